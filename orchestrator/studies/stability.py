"""Stability suite: stiff and extreme cases, each a scenario file under scenarios/stability/.

Each case runs with the regime-aware master and with the fixed-step masters at the case's
macro step.  A run is *stable* when it completed, every recorded value is finite, its
energy residual is within ``ENERGY_LIMIT`` and, where the scene has a reference, its
error against it is within the bound the case states (``[report] error_bound``).  A run
that stops with a diagnosis (status "failed" and a message naming what diverged, when
and in which FMU) is not stable, but it is not silent either; the table says which.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from orchestrator.accuracy import compare
from orchestrator.run import reference_of
from orchestrator.scenario import load_scene
from orchestrator.studies.jobs import Job, JobResult, run_jobs

SUITE_DIR = Path(__file__).resolve().parents[2] / "scenarios" / "stability"
ENERGY_LIMIT = 0.05  # relative energy residual above which a run is called unstable
STABILITY_MASTERS = ("regime-aware", "jacobi", "gauss-seidel")


@dataclass
class CaseRow:
    case: str
    master: str
    status: str
    stable: bool
    error: float
    energy_residual: float
    wall_time: float
    diagnosis: str

    def as_dict(self) -> dict[str, Any]:
        return dict(self.__dict__)


def case_files(suite_dir: Path = SUITE_DIR) -> list[Path]:
    return sorted(suite_dir.glob("*.toml"))


def run_suite(
    suite_dir: Path = SUITE_DIR,
    out_dir: Path = Path("runs") / "stability",
    workers: int | None = None,
    dask_address: str | None = None,
    masters: tuple[str, ...] = STABILITY_MASTERS,
    cases: tuple[str, ...] | None = None,
    overrides: dict[str, object] | None = None,
) -> list[CaseRow]:
    """Run every case (or those named in ``cases``) under each master, with ``overrides``
    of every case's settings (e.g. the regime-aware master's ``master.input_hold``); write
    the table."""
    out_dir.mkdir(parents=True, exist_ok=True)
    files = [f for f in case_files(suite_dir) if cases is None or f.stem in cases]
    jobs = [
        Job(
            str(f),
            {"master.algorithm": m, **(overrides or {})},
            str(out_dir / f.stem / m),
            f"{f.stem}|{m}",
            compare_reference=False,
        )
        for f in files
        for m in masters
    ]
    results = run_jobs(jobs, workers=workers, dask_address=dask_address)
    references = {}
    rows = []
    for job, res in zip(jobs, results, strict=True):
        case, master = job.label.split("|")
        scene = load_scene(job.scene, job.overrides)
        error = math.nan
        if scene.reference and res.status == "completed":
            if case not in references:
                references[case] = reference_of(scene)
            acc = compare(res.header, res.data, res.events, res.headline, references[case])
            # The trajectory (continuous signals), not headline maxima: a jammed mechanism's
            # static contact forces, for one, are not determined by the physics.
            error = acc.get("trajectory_error", math.nan)
        rows.append(_row(case, master, res, error, scene.error_bound))
    _write(rows, out_dir)
    return rows


def _row(case: str, master: str, res: JobResult, error: float, limit: float) -> CaseRow:
    energy = res.headline.get("energy_residual", {}).get("value", math.nan)
    finite = bool(np.all(np.isfinite(res.data))) if res.data.size else False
    stable = (
        res.status == "completed" and finite and not (energy > ENERGY_LIMIT) and not (error > limit)
    )
    diagnosis = (
        res.message if res.status != "completed" else ("" if finite else "non-finite values")
    )
    if res.status == "completed" and not stable and not diagnosis:
        diagnosis = f"error {error:.3g} > {limit:.3g}" if error > limit else f"energy {energy:.3g}"
    return CaseRow(
        case,
        master,
        res.status,
        stable,
        error,
        energy,
        res.stats.get("wall_time", math.nan),
        diagnosis,
    )


def _write(rows: list[CaseRow], out_dir: Path) -> None:
    with open(out_dir / "stability.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(CaseRow.__dataclass_fields__))
        writer.writeheader()
        for r in rows:
            writer.writerow(r.as_dict())
    lines = [
        "| case | master | stable? | error | energy residual | wall time [s] | diagnosis |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r.case} | {r.master} | {'yes' if r.stable else 'no'} | {r.error:.3g} "
            f"| {r.energy_residual:.3g} | {r.wall_time:.3g} | {r.diagnosis} |"
        )
    (out_dir / "stability.md").write_text("\n".join(lines) + "\n")
