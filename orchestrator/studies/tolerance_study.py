"""Tolerance studies: a scene run once per sample of its ``[study]`` inputs, all varied at
once, and the distribution of its headline quantities.

Sample k's inputs depend only on the seed, the sampling method and k (``sampling``), so a
study gives the same ``samples.csv`` on any number of workers, on a process pool or a Dask
cluster, and after an interruption.  Each sample is appended to ``samples.csv`` as it
finishes (flushed to disk), so ``--resume`` runs only the samples missing; when the study
ends the file is rewritten in sample order.  A sample that fails, stalls or does not arm is
a row like any other, with its status and reason.

Written under ``runs/<scene>/study`` by default: ``samples.csv``, ``study.md`` (statistics,
limits, sensitivity, convergence), ``study.png`` and ``samples/<k>/`` (each run's summary;
the time series are kept only for samples that did not give every quantity).
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import time
from pathlib import Path
from typing import Any

import numpy as np

from orchestrator.errors import ScenarioError
from orchestrator.interrupt import catching_signals
from orchestrator.progress import ProgressBar
from orchestrator.provenance import source_changed, source_commit
from orchestrator.scenario import load_scene
from orchestrator.setting_limits import check_samples, check_workers
from orchestrator.studies.jobs import Job, JobResult, iter_jobs
from orchestrator.studies.sampling import draw
from orchestrator.studies.study_report import write_markdown, write_plot
from orchestrator.studies.study_result import FAILED, NO_VALUE, NOT_ARMED, OK, Sample, StudyResult
from orchestrator.studies.study_table import MAX_SAMPLES, StudySpec


def csv_header(spec: StudySpec) -> list[str]:
    inputs = [f"{i.name} [{i.unit}]" for i in spec.inputs]
    return ["sample", *inputs, "status", *spec.quantities, "reason"]


def _number(x: float) -> str:
    return repr(float(x))  # shortest text that reads back to the same double


def _csv_line(sample: Sample, spec: StudySpec) -> str:
    cells = [str(sample.index), *(_number(v) for v in sample.inputs), sample.status]
    cells += [_number(sample.values.get(q, math.nan)) for q in spec.quantities]
    cells.append(sample.reason)
    buffer = io.StringIO()
    csv.writer(buffer, lineterminator="\n").writerow(cells)
    return buffer.getvalue()


def _job_value(spec_input: Any, value: float) -> Any:
    if spec_input.distribution == "discrete" and float(value).is_integer():
        return int(value)  # an Integer parameter takes only an int
    return float(value)


def run_study(
    scene_path: str | Path,
    samples: int | None = None,
    workers: int | None = None,
    dask_address: str | None = None,
    resume: bool = False,
    overrides: dict[str, Any] | None = None,
    output_dir: Path | None = None,
    show_progress: bool = True,
    keep_going: bool = False,
) -> StudyResult:
    """Run the scene's study (the missing samples only with ``resume``) and write its files.

    When the first ``EARLY_FAILURES`` samples run all fail with one same error (a worker
    that cannot import the project, an FMU that cannot load), the study stops there and
    says so, unless ``keep_going``."""
    scene_path = Path(scene_path).resolve()
    scene = load_scene(scene_path, overrides)  # builds the FMUs once, before the workers start
    spec: StudySpec | None = scene.study
    if spec is None:
        raise ScenarioError(scene_path, "study", "missing; the scene has no [study] table")
    n = spec.samples if samples is None else samples
    check_samples(n)
    if n > MAX_SAMPLES:
        raise ScenarioError(
            "--samples", "", f"{n} is more than {MAX_SAMPLES} (the limit of [study] samples)"
        )
    check_workers(workers)
    out_dir = Path(output_dir or scene.output_dir / "study").resolve()
    out_dir.mkdir(parents=True, exist_ok=True)
    csv_path = out_dir / "samples.csv"
    points = draw(spec, n)
    done = _read_samples(csv_path, spec, points) if resume and csv_path.exists() else {}
    if not done:
        csv_path.write_text(",".join(csv_header(spec)) + "\n")
    else:  # drop a half-written last line and samples beyond n, keep the rest in order
        _rewrite(csv_path, spec, done)
    todo = [k for k in range(n) if k not in done]
    notes: list[str] = []
    if workers is not None and workers > max(1, len(todo)) and not dask_address:
        notes.append(
            f"--workers {workers} capped at {max(1, len(todo))}: "
            "no more workers than samples to run"
        )
        workers = max(1, len(todo))
    jobs = [
        Job(
            str(scene_path),
            {
                **(overrides or {}),
                **{
                    key: _job_value(inp, points[k, j])
                    for j, inp in enumerate(spec.inputs)
                    for key in inp.keys
                },
            },
            str(out_dir / "samples" / f"{k:05d}"),
            str(k),
            compare_reference=False,
            plots=False,
        )
        for k in todo
    ]
    if dask_address:
        where = f"Dask at {dask_address}"
    elif workers == 1:
        where = "1 worker, in process"
    else:
        where = f"{workers} workers" if workers else "one worker per core"
    units: dict[str, str] = {}
    start = time.perf_counter()
    commit = _source_description()
    interrupted: int | None = None
    bar = ProgressBar(
        total=n, initial=len(done), unit="sample", disable=not show_progress, desc=scene.name
    )
    early = _EarlyFailures(keep_going or len(todo) <= EARLY_FAILURES)
    with catching_signals() as guard, open(csv_path, "a", newline="") as f:
        stop = lambda: guard.signum is not None or early.stopped is not None  # noqa: E731
        for j, outcome in iter_jobs(jobs, workers, dask_address, stop):
            k = todo[j]
            sample = _sample(k, points[k], outcome, spec)
            if isinstance(outcome, JobResult):
                for q in spec.quantities:
                    if q in outcome.headline:
                        units.setdefault(q, outcome.headline[q].get("unit", ""))
            if sample is None:  # interrupted: not a result; --resume runs it again
                continue
            early.add(sample)
            if sample.status == OK:
                _drop_series(Path(jobs[j].output_dir))
            f.write(_csv_line(sample, spec))
            f.flush()
            os.fsync(f.fileno())
            done[k] = sample
            bar.update(1)
        interrupted = guard.signum
    bar.close()
    wall = time.perf_counter() - start
    _rewrite(csv_path, spec, done)
    invocations = _log_invocation(out_dir, resume, len(done) - (n - len(todo)), wall, where, commit)
    result = StudyResult(
        scene,
        spec,
        n,
        [done[k] for k in sorted(done)],
        out_dir,
        wall,
        len(done) - (n - len(todo)),
        where,
        interrupted,
        {**_saved_units(out_dir, done, spec), **units},
        invocations,
        notes,
        early.stopped,
    )
    write_markdown(result, out_dir / "study.md")
    write_plot(result, out_dir / "study.png")
    return result


EARLY_FAILURES = 4  # first samples that, failing alike, stop a study


class _EarlyFailures:
    """Watches the first samples of a study: all failed, with one same reason, stops it."""

    def __init__(self, off: bool) -> None:
        self.off = off
        self.first: list[Sample] = []
        self.stopped: str | None = None

    def add(self, sample: Sample) -> None:
        if self.off or len(self.first) >= EARLY_FAILURES:
            return
        self.first.append(sample)
        if len(self.first) < EARLY_FAILURES:
            return
        reasons = {s.reason for s in self.first if s.status == FAILED}
        if all(s.status == FAILED for s in self.first) and len(reasons) == 1:
            self.stopped = (
                f"the first {EARLY_FAILURES} samples all failed with the same error "
                f"({reasons.pop()}): stopped; give --keep-going to run every sample"
            )


def _sample(k: int, inputs: np.ndarray, outcome: Any, spec: StudySpec) -> Sample | None:
    """What one run says about sample k; None for a run that was interrupted."""
    values = {q: math.nan for q in spec.quantities}
    row = [float(v) for v in inputs]
    if isinstance(outcome, BaseException):
        text = str(outcome).strip().splitlines()[0] if str(outcome).strip() else ""
        return Sample(k, row, FAILED, values, f"{type(outcome).__name__}: {text}".rstrip(": "))
    if outcome.status == "interrupted":
        return None
    if outcome.status != "completed":
        message = outcome.message.strip().splitlines()[0] if outcome.message.strip() else ""
        return Sample(k, row, FAILED, values, message or outcome.status)
    for q in spec.quantities:
        v = outcome.headline.get(q, {}).get("value")
        if isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v):
            values[q] = float(v)
    armed = outcome.headline.get("armed", {}).get("value")
    if armed == 0.0:
        why = outcome.headline.get("not_armed_reason", {}).get("value", "did not arm")
        return Sample(k, row, NOT_ARMED, values, str(why))
    missing = [q for q in spec.quantities if not math.isfinite(values[q])]
    if missing:
        notes = [*outcome.notes, *outcome.stats.get("warnings", [])]
        why = f"no value of {', '.join(missing)}" + (f" ({notes[0]})" if notes else "")
        return Sample(k, row, NO_VALUE, values, why)
    return Sample(k, row, OK, values)


def _source_description() -> str | None:
    """The commit the study runs from (taken at its start), marked if the tree differs."""
    commit = source_commit()
    if commit and source_changed():
        commit += " with uncommitted changes"
    return commit


def _log_invocation(
    out_dir: Path, resume: bool, ran: int, wall: float, where: str, commit: str | None
) -> list[dict[str, Any]]:
    """Append this invocation to ``runs.json`` (started afresh unless resuming): the
    study's run time, which samples.csv leaves out to stay the same wherever it ran."""
    path = out_dir / "runs.json"
    log: list[dict[str, Any]] = []
    if resume:
        try:
            log = json.loads(path.read_text())
        except (OSError, ValueError):
            log = []
    log.append({"samples_run": ran, "wall_time": round(wall, 3), "where": where, "commit": commit})
    path.write_text(json.dumps(log, indent=1) + "\n")
    return log


def _drop_series(run_dir: Path) -> None:
    """A sample that gave every quantity keeps only its summary (disk: a study may be long)."""
    for name in ("timeseries.csv", "events.csv"):
        (run_dir / name).unlink(missing_ok=True)


def _read_samples(path: Path, spec: StudySpec, points: np.ndarray) -> dict[int, Sample]:
    """Samples already recorded, checked against the study as it is drawn now."""
    try:
        text = path.read_bytes().decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ScenarioError(
            path, "", f"not a text file (byte {exc.start}); run without --resume to start again"
        ) from None
    if "\0" in text:
        line = text.count("\n", 0, text.index("\0")) + 1
        raise ScenarioError(path, f"line {line}", "binary content (a NUL byte)")
    lines = text.splitlines(keepends=True)
    if lines and not lines[-1].endswith("\n"):
        lines = lines[:-1]  # cut short by a kill: run that sample again
    try:
        rows = list(csv.reader(lines))
    except csv.Error as exc:
        raise ScenarioError(path, "", f"not a samples file: {exc}") from None
    header = csv_header(spec)
    if not rows or rows[0] != header:
        raise ScenarioError(
            path, "", "made by a different [study] (its columns differ); run without --resume"
        )
    done: dict[int, Sample] = {}
    d, nq = len(spec.inputs), len(spec.quantities)
    for line, cells in enumerate(rows[1:], start=2):
        if len(cells) != len(header) or not cells[0].isdigit():
            raise ScenarioError(path, f"line {line}", f"expected {len(header)} fields")
        k = int(cells[0])
        if k >= MAX_SAMPLES:
            raise ScenarioError(
                path,
                f"line {line}",
                f"sample index {k} is beyond any study ({MAX_SAMPLES} samples)",
            )
        if k >= len(points):  # recorded by a larger study: kept, checked against its draw
            points = draw(spec, k + 1)
        numbers = [*cells[1 : 1 + d], *cells[2 + d : 2 + d + nq]]
        names = [*header[1 : 1 + d], *header[2 + d : 2 + d + nq]]
        for name, cell in zip(names, numbers, strict=True):
            try:
                float(cell)
            except ValueError:
                raise ScenarioError(
                    path, f"line {line}", f"{name} is {cell!r}, not a number"
                ) from None
        inputs = [float(c) for c in cells[1 : 1 + d]]
        if inputs != [float(v) for v in points[k]]:
            raise ScenarioError(
                path,
                f"line {line}",
                f"sample {k}'s inputs differ from the study's (another seed, sampling or "
                "inputs?); run without --resume to start again",
            )
        values = {
            q: float(c) for q, c in zip(spec.quantities, cells[2 + d : 2 + d + nq], strict=True)
        }
        done[k] = Sample(k, inputs, cells[1 + d], values, cells[-1])
    return done


def _rewrite(path: Path, spec: StudySpec, done: dict[int, Sample]) -> None:
    """The file in sample order (written beside and renamed: never half a file)."""
    tmp = path.with_suffix(".csv.tmp")
    with open(tmp, "w", newline="") as f:
        f.write(",".join(csv_header(spec)) + "\n")
        for k in sorted(done):
            f.write(_csv_line(done[k], spec))
        f.flush()
        os.fsync(f.fileno())
    os.replace(tmp, path)


def _saved_units(out_dir: Path, done: dict[int, Sample], spec: StudySpec) -> dict[str, str]:
    """Units of the quantities from a recorded sample's summary (for a resumed study)."""
    for k, sample in sorted(done.items()):
        if sample.status != OK:
            continue
        summary = out_dir / "samples" / f"{k:05d}" / "summary.json"
        try:
            headline = json.loads(summary.read_text()).get("headline", {})
        except (OSError, ValueError):
            continue
        return {q: headline.get(q, {}).get("unit", "") for q in spec.quantities}
    return {}
