"""Work–precision report: error against wall time for every master setting of a scene.

One command runs the scene's reference once, then sweeps the masters (fixed-step Jacobi and
Gauss–Seidel over macro steps; tolerance-driven masters over tolerances) on a process pool
or a Dask cluster, and writes ``work_precision.csv``, ``work_precision.png`` and
``work_precision.md`` with the observed convergence order of each master.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from orchestrator.accuracy import compare
from orchestrator.errors import ScenarioError
from orchestrator.masters import TOLERANCE_MASTERS
from orchestrator.run import reference_of
from orchestrator.scenario import Scene, load_scene
from orchestrator.studies.jobs import Job, JobResult, run_jobs

STEP_FACTORS = (8.0, 4.0, 2.0, 1.0, 0.5, 0.25)
TOLERANCES = (1e-2, 3e-3, 1e-3, 3e-4, 1e-4)
COUNTERS = ("steps", "do_steps", "rollbacks", "rejections", "iterations", "events")
COLUMNS = [
    "master",
    "setting",
    "value",
    "status",
    "wall_time",
    "headline_error",
    "trajectory_error",
    "event_time_error",
    "energy_residual",
    *COUNTERS,
]


@dataclass
class Row:
    master: str
    setting: str  # "step" or "tolerance"
    value: float
    result: JobResult
    accuracy: dict[str, float]

    def as_dict(self) -> dict[str, Any]:
        stats = self.result.stats
        energy = self.result.headline.get("energy_residual", {}).get("value", math.nan)
        return {
            "master": self.master,
            "setting": self.setting,
            "value": self.value,
            "status": self.result.status,
            "wall_time": stats.get("wall_time", math.nan),
            "headline_error": self.accuracy.get("headline_error", math.nan),
            "trajectory_error": self.accuracy.get("trajectory_error", math.nan),
            "event_time_error": self.accuracy.get("event_time_error", math.nan),
            "energy_residual": energy,
            **{k: stats.get(k, 0) for k in COUNTERS},
        }


#: Label of the regime-aware master with inputs held at the step start (the baseline that
#: the default midpoint hold is measured against).
START_HOLD = "regime-aware/start"


def sweep_jobs(
    scene_path: Path,
    scene: Scene,
    out_dir: Path,
    step_factors,
    tolerances,
    start_hold_tolerances=(),
) -> list[Job]:
    def job(overrides: dict, directory: str, label: str) -> Job:
        # The study compares every run with one reference it computes itself, and draws
        # one diagram of them all (a plot per run would cost more than most runs).
        return Job(
            str(scene_path),
            overrides,
            str(out_dir / directory),
            label,
            compare_reference=False,
            plots=False,
        )

    jobs = []
    for master in ("jacobi", "gauss-seidel"):
        for f in step_factors:
            h = scene.master.step * f
            if h <= scene.stop - scene.start:
                overrides = {"master.algorithm": master, "master.step": h}
                jobs.append(job(overrides, f"{master}_h{h:.3e}", master))
    for master in TOLERANCE_MASTERS:
        for tol in tolerances:
            overrides = {"master.algorithm": master, "master.tolerance": tol}
            jobs.append(job(overrides, f"{master}_tol{tol:.0e}", master))
    for tol in start_hold_tolerances:
        overrides = {
            "master.algorithm": "regime-aware",
            "master.tolerance": tol,
            "master.input_hold": "start",
        }
        jobs.append(job(overrides, f"regime-aware-start_tol{tol:.0e}", START_HOLD))
    return jobs


def work_precision(
    scene_path: Path,
    out_dir: Path | None = None,
    step_factors=STEP_FACTORS,
    tolerances=TOLERANCES,
    workers: int | None = None,
    dask_address: str | None = None,
    start_hold_tolerances=(),
) -> list[Row]:
    scene = load_scene(scene_path)
    if not scene.reference:
        raise ScenarioError(scene_path, "report.reference", "missing; the report needs a reference")
    out_dir = Path(out_dir or Path("runs") / f"{scene.name}_work_precision")
    out_dir.mkdir(parents=True, exist_ok=True)
    reference = reference_of(scene)
    jobs = sweep_jobs(scene_path, scene, out_dir, step_factors, tolerances, start_hold_tolerances)
    results = run_jobs(jobs, workers=workers, dask_address=dask_address)
    rows = []
    for job, res in zip(jobs, results, strict=True):
        accuracy = {}
        if res.status == "completed":
            accuracy = compare(res.header, res.data, res.events, res.headline, reference)
        setting, value = (
            ("tolerance", job.overrides["master.tolerance"])
            if "master.tolerance" in job.overrides
            else ("step", job.overrides["master.step"])
        )
        rows.append(Row(job.label, setting, value, res, accuracy))
    _write_csv(rows, out_dir / "work_precision.csv")
    plot_records(
        [r.as_dict() for r in rows], reference.wall_time, scene.name, out_dir / "work_precision.png"
    )
    _write_summary(rows, scene, reference.wall_time, out_dir / "work_precision.md")
    return rows


def observed_order(rows: list[Row], master: str, error: str = "trajectory_error") -> float:
    """Least-squares slope of log(error) against log(setting) for one master."""
    pts = [
        (r.value, r.accuracy.get(error, math.nan))
        for r in rows
        if r.master == master and r.result.status == "completed"
    ]
    pts = [(x, y) for x, y in pts if y > 0 and math.isfinite(y)]
    if len(pts) < 2:
        return math.nan
    x, y = np.log([p[0] for p in pts]), np.log([p[1] for p in pts])
    return float(np.polyfit(x, y, 1)[0])


def _write_csv(rows: list[Row], path: Path) -> None:
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=COLUMNS)
        writer.writeheader()
        for r in rows:
            writer.writerow(r.as_dict())


def plot_records(records: list[dict[str, Any]], reference_time: float, name: str, path: Path):
    """The diagram from table rows (``Row.as_dict`` or the CSV read back with float values)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    for ax, error in zip(axes, ("trajectory_error", "headline_error"), strict=True):
        for master in dict.fromkeys(r["master"] for r in records):
            pts = [
                (float(r["wall_time"]), float(r[error]))
                for r in records
                if r["master"] == master and r["status"] == "completed"
            ]
            pts = sorted((x, y) for x, y in pts if y > 0 and math.isfinite(y))
            if pts:
                ax.loglog(*zip(*pts, strict=True), "o-", label=master)
        if reference_time > 0:
            ax.axvline(reference_time, color="grey", ls=":", label="reference run time")
        ax.xaxis.set_minor_formatter(NullFormatter())  # minor labels collide on short spans
        ax.set_xlabel("wall time [s]")
        ax.set_ylabel(error.replace("_", " ") + " (relative)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    fig.suptitle(f"{name}: work–precision")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _write_summary(rows: list[Row], scene: Scene, reference_time: float, path: Path) -> None:
    lines = [
        f"# Work–precision: {scene.name}",
        "",
        f"Reference: `{scene.reference}` ({reference_time:.3g} s). "
        f"{len(rows)} runs; errors are relative to the reference.",
        "",
        "| master | setting | value | status | wall time [s] | headline error | trajectory error "
        "| event-time error [s] | energy residual | doSteps | rollbacks |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        d = r.as_dict()
        lines.append(
            f"| {d['master']} | {d['setting']} | {d['value']:.3g} | {d['status']} "
            f"| {d['wall_time']:.3g} | {d['headline_error']:.3g} | {d['trajectory_error']:.3g} "
            f"| {d['event_time_error']:.3g} | {d['energy_residual']:.3g} | {d['do_steps']} "
            f"| {d['rollbacks']} |"
        )
    lines += ["", "Observed order (slope of log trajectory error against log setting):", ""]
    for master in dict.fromkeys(r.master for r in rows):
        setting = next(r.setting for r in rows if r.master == master)
        lines.append(f"- {master}: {observed_order(rows, master):.2f} (per {setting})")
    path.write_text("\n".join(lines) + "\n")
