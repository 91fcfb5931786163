"""Run one scene: build/load its FMUs, run the master, record, report.

A failure anywhere after loading (an FMU step that fails, a diverging master) ends the
run with status "failed" and a message naming the FMU and time; everything recorded up
to then is kept on disk and in the result.
"""

from __future__ import annotations

import platform
import time
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

from fmus.build import build_fmu, default_cache_dir
from fmus.disk_memo import installed_version
from orchestrator.accuracy import compare
from orchestrator.analyses import energy_residual, headline, missing_column
from orchestrator.errors import RunError
from orchestrator.execution import StopRule, execute
from orchestrator.file_hash import file_sha256
from orchestrator.flight import announce_run, summary_written
from orchestrator.fmu_instance import FmuTerminated
from orchestrator.fmu_log import FmuLog
from orchestrator.interrupt import Interrupted, SignalGuard, catching_signals, signal_name
from orchestrator.last_success import record_last_success
from orchestrator.master_settings import as_record
from orchestrator.masters.macro_step import Master
from orchestrator.masters.registry import algorithm
from orchestrator.observers import EnergyBalance, RegimeLog, StepCounter, TimeSeries
from orchestrator.output_lock import OutputLock
from orchestrator.plot_cache import cached_plot
from orchestrator.plotting import pyplot
from orchestrator.progress import ProgressBar
from orchestrator.provenance import source_commit
from orchestrator.recorder import Recorder, StepStats
from orchestrator.reference_cache import cached_reference
from orchestrator.scene_model import Scene
from orchestrator.scenes import ANALYSES, PLOTS, REFERENCES
from orchestrator.scenes.family import Reference
from orchestrator.signals import scene_signals
from orchestrator.stop_condition import keep_comparable, refuse_if_met_at_start
from orchestrator.summary_file import not_started_summary, write_summary
from orchestrator.system import CoupledSystem


@dataclass(kw_only=True)
class RunResult:
    scene: Scene
    status: str  # "completed", "failed" or "interrupted"
    message: str
    header: list[str]
    data: np.ndarray
    events: list[tuple[float, str, str, str]]
    stats: StepStats
    headline: dict[str, dict[str, Any]]
    output_dir: Path
    accuracy: dict[str, float] = field(default_factory=dict)
    metadata: dict[str, Any] = field(default_factory=dict)
    time_reached: float | None = None  # simulated time the run got to
    notes: list[str] = field(default_factory=list)  # what could not be computed, and why
    interrupted_by: int | None = None  # the signal that interrupted the run
    reference: Reference | None = None  # the reference the run was compared with, if any
    #: wall time [s] of each phase of the run, in the order run (``--debug`` prints them)
    phases: dict[str, float] = field(default_factory=dict)

    def signal(self, name: str) -> np.ndarray:
        """Recorded column by name ('time' or '<instance>.<variable>')."""
        return self.data[:, self.header.index(name)]

    def value(self, quantity: str) -> float:
        return self.headline[quantity]["value"]


def run_scene(
    scene: Scene,
    output_dir: Path | None = None,
    cache_dir: Path | None = None,
    show_progress: bool = True,
    compare_reference: bool = True,
    plots: bool = True,
    reference_cache: bool = True,
) -> RunResult:
    """Run ``scene`` and write its results under ``output_dir`` (default: the scene's).

    The directory is locked for the run (``OutputInUseError`` if another run holds it).
    SIGINT/SIGTERM stop the run at the next step boundary with status "interrupted".
    ``reference_cache``: read the reference and the plot from, and keep them in, the FMU
    cache directory (``orchestrator.reference_cache``, ``orchestrator.plot_cache``).
    """
    out = Path(output_dir) if output_dir else scene.output_dir
    options = _Options(compare_reference, plots, cache_dir, reference_cache, Phases())
    about = {"scene": scene.name, "scene_file": str(scene.path), "stop": scene.stop}
    with catching_signals() as guard, OutputLock(out, about):
        announce_run(scene, out)  # for a supervisor, should this process crash
        return _run_locked(scene, out, cache_dir, show_progress, options, guard)


class Phases(dict):
    """Wall time [s] by phase name, in the order the phases ran."""

    @contextmanager
    def timed(self, name: str) -> Iterator[None]:
        start = time.perf_counter()
        try:
            yield
        finally:
            self[name] = self.get(name, 0.0) + time.perf_counter() - start


@dataclass
class _Options:
    compare_reference: bool
    plots: bool
    cache_dir: Path | None
    reference_cache: bool
    phases: Phases


def _run_locked(
    scene: Scene,
    out: Path,
    cache_dir: Path | None,
    show_progress: bool,
    options: _Options,
    guard: SignalGuard,
) -> RunResult:
    phases = options.phases
    with phases.timed("FMUs: build/find, extract, instantiate"):
        fmu_paths = fmu_files(scene, cache_dir)
        try:
            system = CoupledSystem(scene, fmu_paths)
        except RunError as exc:  # an FMU that cannot be instantiated: say so in the results
            write_summary(out, not_started_summary(scene, str(exc)))
            raise
    try:
        recorder = Recorder(out, system.record_header)
    except OSError as exc:
        system.close()
        raise RunError(f"cannot write results in {out}: {exc.strerror or exc}") from None
    # The master says what it needs of the FMUs before they are initialized.
    master = algorithm(scene.master.algorithm).make(scene.master.settings, system)
    master.setup()
    energy = EnergyBalance(system, recorder.header)
    with phases.timed("metadata (FMU hashes, versions, commit)"):
        meta = _metadata(scene, fmu_paths)
    bar = ProgressBar(
        total=scene.stop - scene.start,
        unit="s(sim)",
        delay=1.0,  # only runs longer than a moment show a bar
        disable=not show_progress,
        leave=False,
        bar_format="{l_bar}{bar}| {n:.4g}/{total:.4g} s [{elapsed}<{remaining}]",
    )
    last = [scene.start, time.perf_counter()]
    reached = [scene.start]

    def progress(t: float) -> None:
        reached[0] = t
        guard.check()  # between macro steps: no FMU call is under way
        now = time.perf_counter()
        if now - last[1] > 0.2:  # keep the bar off the hot path
            bar.update(t - last[0])
            last[0], last[1] = t, now

    start = time.perf_counter()
    try:
        return _stepped(scene, out, master, recorder, energy, meta, guard, progress,
                        reached, bar, start, options)  # fmt: skip
    finally:
        # Last: an FMU that crashes as it is terminated or freed (README, "A crashing FMU")
        # then finds the run's summary written, headline and all.
        with phases.timed("close FMUs"):
            system.close()


def _stepped(
    scene: Scene,
    out: Path,
    master: Master,
    recorder: Recorder,
    energy: EnergyBalance,
    meta: dict[str, Any],
    guard: SignalGuard,
    progress: Any,
    reached: list[float],
    bar: ProgressBar,
    start: float,
    options: _Options,
) -> RunResult:
    """Step ``system`` to the end, then analyse, summarize and return the run (the FMUs
    stay alive: the caller closes them)."""
    status, message = "completed", ""
    # a signal file read in FMPy's format, without units: said where the run is reported
    signals = meta.get("signals", {})
    notes = [f"signal {k}: {v['units']}" for k, v in signals.items() if "units" in v]
    phases = options.phases
    system, stats = master.system, master.stats
    observers = [
        RegimeLog(recorder),
        StepCounter(stats),
        TimeSeries(system, recorder, scene.record_every),
        energy,
    ]
    cosim = phases.timed("co-simulation (initialize, step)")
    cosim.__enter__()
    try:
        guard.check()
        system.initialize()
        refuse_if_met_at_start(system, scene)
        master.start(scene.start, scene.stop)
        guard.check()
        execute(master, StopRule(scene.start, scene.stop, system), observers, progress)
    except FmuTerminated as exc:  # as FMPy does: the run ends there, with what it has
        message = str(exc)
        notes.append(message)
        reached[0], unrecorded = record_last_success(system, recorder, exc)
        notes.extend([unrecorded] if unrecorded else [])
    except RunError as exc:
        status, message = "failed", str(exc)
        if exc.time is not None:
            reached[0] = exc.time
    except Interrupted as exc:
        status = "interrupted"  # the loop kept the values at the step boundary reached
        message = (
            f"{exc}: stopped at t = {reached[0]:.9g} s (simulated); everything up to there is kept"
        )
    finally:
        stats.wall_time = time.perf_counter() - start
        bar.close()
        cosim.__exit__(None, None, None)
    warned = fmu_warnings(system)
    for fmu, log in warned.items():
        notes.extend(log.notes(fmu))
    recorder.flush()
    data = recorder.array()
    quantities: dict[str, dict[str, Any]] = {}
    accuracy: dict[str, float] = {}
    ref: Reference | None = None
    try:
        # No FMU is called any more: a signal may now stop the analyses where it lands.
        with guard.raise_at_once(), _without_numeric_warnings():
            quantities, accuracy, ref = _analyse(
                scene, out, recorder, data, energy, status, options, notes
            )
            if ref is not None:
                keep_comparable(scene, stats, ref, accuracy, notes, reached[0])
    except Interrupted as exc:
        if status == "completed":
            status = "interrupted"
            message = f"{exc} after the run ended (t = {reached[0]:.9g} s): analyses skipped"
    if guard.signum is not None and status == "completed":
        status = "interrupted"
        message = f"interrupted by {signal_name(guard.signum)} after the run ended"
    meta["master_ran"] = master_ran(master)
    summary_phase = phases.timed("summary")
    summary_phase.__enter__()
    recorder.close(
        {
            "scene": scene.name,
            "status": status,
            "message": message,
            "time_reached": reached[0],
            "headline": quantities,
            "accuracy": accuracy,
            "notes": notes,
            "stats": stats.as_dict(),
            "metadata": meta,
            # only where an FMU warned: the summaries of runs without warnings unchanged
            **({"fmu_warnings": {f: log.summary() for f, log in warned.items()}} if warned else {}),
        }
    )
    summary_written()  # for a supervisor, should closing an FMU crash this process
    summary_phase.__exit__(None, None, None)
    return RunResult(
        scene=scene,
        status=status,
        message=message,
        header=recorder.header,
        data=data,
        events=recorder.events,
        stats=stats,
        headline=quantities,
        output_dir=out,
        accuracy=accuracy,
        metadata=meta,
        time_reached=reached[0],
        notes=notes,
        interrupted_by=guard.signum if status == "interrupted" else None,
        reference=ref,
        phases=phases,
    )


def _analyse(
    scene: Scene,
    out: Path,
    recorder: Recorder,
    data: np.ndarray,
    energy: EnergyBalance,
    status: str,
    options: _Options,
    notes: list[str],
) -> tuple[dict[str, dict[str, Any]], dict[str, float], Reference | None]:
    """Headline, energy residual, scene analysis, plot and error against the reference
    (returned with them): each that fails adds a note saying why, and the others still
    count."""
    header = recorder.header
    phases = options.phases
    quantities: dict[str, dict[str, Any]] = {}
    analysis = phases.timed("headline, energy, analysis")
    analysis.__enter__()
    with _noted(notes, "headline quantities", header):
        quantities.update(headline(scene, header, data))
    with _noted(notes, "energy residual", header):
        # Over every step taken (the record may be thinned); a failed run's from what it
        # recorded, the values that failed it included.
        residual = energy.residual() if status != "failed" else energy_residual(header, data)
        if residual is not None and scene_signals(scene):
            notes.append(  # e.g. a torque table into an Inertia: all its energy came in so
                "energy residual not computed: input signals do work on the FMUs, which "
                "they do not report apart from the work through their connections"
            )
        elif residual is not None:
            quantities["energy_residual"] = residual
    if scene.family and status == "completed":
        with _noted(notes, f"analysis {scene.family!r}", header):
            quantities.update(ANALYSES[scene.family](scene, header, data, scene.report_options))
    analysis.__exit__(None, None, None)
    plotted = scene.family in PLOTS and options.plots and len(data) > 1
    if scene.family and status == "completed" and plotted:
        with _noted(notes, f"plot of {scene.family!r}", header):
            png = out / f"{scene.name}.png"

            def draw() -> None:
                with phases.timed("plot: import matplotlib"):
                    pyplot()  # once a process: told apart from the drawing
                with phases.timed("plot: draw and write the PNG"):
                    PLOTS[scene.family](scene, header, data, png)

            if options.reference_cache:
                start = time.perf_counter()
                cache_dir = options.cache_dir or default_cache_dir()
                if cached_plot(scene, header, data, png, draw, cache_dir):
                    phases["plot (from the cache)"] = time.perf_counter() - start
            else:
                draw()
    accuracy: dict[str, float] = {}
    ref = None
    if scene.reference and status == "completed" and options.compare_reference:
        with _noted(notes, f"reference {scene.reference!r}", header):
            hit = False
            with phases.timed("reference"):
                if options.reference_cache:
                    ref, hit = cached_reference(
                        scene, reference_of, options.cache_dir or default_cache_dir()
                    )
                else:
                    ref = reference_of(scene)
            if hit:  # said in the phase list only: the summary stays that of a computed one
                phases["reference (from the cache)"] = phases.pop("reference")
            with phases.timed("accuracy against the reference"):
                accuracy = compare(header, data, recorder.events, quantities, ref, notes)
            accuracy["reference_wall_time"] = ref.wall_time
    return quantities, accuracy, ref


@contextmanager
def _without_numeric_warnings() -> Iterator[None]:
    """Non-finite results are reported as such (NaN, or a note), not as numpy warnings."""
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore", RuntimeWarning)
        yield


@contextmanager
def _noted(notes: list[str], what: str, header: list[str]) -> Iterator[None]:
    """Run a post-run stage; an error becomes a one-line note instead of ending the run."""
    try:
        yield
    except KeyError as exc:
        column = missing_column(exc, header)
        if column is not None:
            notes.append(f"{what} not computed: it needs {column} recorded (output.record)")
        else:
            notes.append(f"{what} not computed: missing {exc.args[0]!r}")
    except Exception as exc:  # noqa: BLE001 - any failure of an analysis is reported, not raised
        text = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
        notes.append(f"{what} not computed: {type(exc).__name__}: {text}".rstrip(": "))


def master_ran(master: Master) -> dict[str, Any]:
    """The algorithm and every setting that ran ("auto" resolved, defaults filled in; the
    Jacobi run instead where the regime-aware master could not roll back)."""
    return {"algorithm": master.name, **as_record(master.settings)}


def fmu_warnings(system: CoupledSystem) -> dict[str, FmuLog]:
    """The logs of the FMU instances that warned, by instance name."""
    return {inst.name: inst.log for inst in system.instances if inst.log.warnings}


def fmu_files(scene: Scene, cache_dir: Path | None = None) -> dict[str, Path]:
    """Instance -> FMU file: the scene's, ours taken from ``cache_dir`` when one is given
    (the same build: the file name is its content hash)."""
    return {
        name: build_fmu(spec.component, cache_dir) if spec.component and cache_dir else spec.path
        for name, spec in scene.fmus.items()
    }


def reference_of(scene: Scene) -> Reference:
    """The scene's reference, timed (wall_time is filled in)."""
    start = time.perf_counter()
    ref = REFERENCES[scene.reference](scene)
    ref.wall_time = time.perf_counter() - start
    return ref


@cache
def _versions() -> dict[str, str | None]:
    """Installed versions (read once a process: a study runs hundreds of scenes in one)."""
    return {p: installed_version(p) for p in ("fmpy", "pythonfmu", "numpy", "scipy", "pint")}


def _metadata(scene: Scene, fmu_paths: dict[str, Path]) -> dict[str, Any]:
    versions = dict(_versions())
    signals = scene_signals(scene)
    own_key, step = scene.master.own_step
    return {
        **({"signals": signals.provenance()} if signals else {}),  # a CSV file's sha256
        "scene_file": str(scene.path),
        "scene_sha256": file_sha256(scene.path),
        "fmus": {
            name: {"file": p.name, "sha256": file_sha256(p), "model": scene.fmus[name].fmu_name}
            for name, p in fmu_paths.items()
        },
        # The parameters as run (SI, --set overrides applied): what rebuilds the design of a
        # run's mechanism from its results alone (``mechcosim animate``).
        "parameters": {name: dict(spec.parameters) for name, spec in scene.fmus.items()},
        "master": {
            "algorithm": scene.master.algorithm,
            own_key: step,
            "order": list(scene.master.order),
            **scene.master.options,
        },
        "start": scene.start,
        "stop": scene.stop,
        "python": platform.python_version(),
        "versions": versions,
        "commit": source_commit(),
        "date": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
    }
