"""Parameter sweeps: a scene run once per value of one setting, optionally per series.

A scene's ``[sweep]`` table names the dotted key to vary, its values and, optionally, series
(sets of overrides, one line each in the plot: Table I units, meshes, ...).  The runs go to
the same process pool or Dask cluster as every other sweep (``orchestrator.studies.jobs``); the
results are ``sweep.csv`` (one row per run), ``sweep.png`` (each quantity against the swept
value, a line per series) and ``sweep.md``, under ``runs/<scene>/sweep`` by default.
"""

from __future__ import annotations

import csv
import math
import re
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from orchestrator.errors import ScenarioError
from orchestrator.scenario import load_scene
from orchestrator.scene_model import Scene, SweepSeries
from orchestrator.studies.jobs import Job, JobResult, run_jobs

_BASE = SweepSeries("", {})


@dataclass
class SweepResult:
    scene: Scene
    rows: list[dict[str, Any]]  # series, value (SI), status, message, wall_time, quantities
    quantities: list[str]
    units: dict[str, str]
    output_dir: Path

    def column(self, quantity: str, series: str = "") -> tuple[list[float], list[float]]:
        """(swept values, quantity) of the completed runs of one series."""
        pts = [
            (r["value"], r[quantity])
            for r in self.rows
            if r["series"] == series and r["status"] == "completed"
        ]
        return [p[0] for p in pts], [p[1] for p in pts]


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9]+", "_", text).strip("_") or "base"


def sweep_jobs(scene_path: Path, scene: Scene, out_dir: Path, run_plots: bool = False) -> list[Job]:
    """One job per (series, value), in series-major order.  Each run writes its time series
    and summary; its plot only with ``run_plots`` (drawing it can cost more than the run)."""
    spec = scene.sweep
    assert spec is not None
    jobs = []
    for series in spec.series or (_BASE,):
        for k, value in enumerate(spec.values):
            overrides = {**series.overrides, spec.parameter: value}
            run_dir = out_dir / f"{_slug(series.label)}_{k:03d}"
            jobs.append(
                Job(str(scene_path), overrides, str(run_dir), series.label, plots=run_plots)
            )
    return jobs


def run_sweep(
    scene_path: str | Path,
    output_dir: Path | None = None,
    workers: int | None = None,
    dask_address: str | None = None,
    overrides: dict[str, Any] | None = None,
    run_plots: bool = False,
) -> SweepResult:
    """Run the scene's sweep and write the CSV, PNG and Markdown tables."""
    scene_path = Path(scene_path)
    scene = load_scene(scene_path, overrides)
    if scene.sweep is None:
        raise ScenarioError(scene_path, "sweep", "missing; the scene has no [sweep] table")
    out_dir = Path(output_dir or scene.output_dir / "sweep")
    out_dir.mkdir(parents=True, exist_ok=True)
    jobs = sweep_jobs(scene_path, scene, out_dir, run_plots)
    if overrides:
        jobs = [replace(j, overrides={**overrides, **j.overrides}) for j in jobs]
    results = run_jobs(jobs, workers=workers, dask_address=dask_address)
    quantities, units = _quantities(scene, results)
    si_values = scene.sweep.si_values * max(1, len(scene.sweep.series))
    rows = [_row(res, value, quantities) for res, value in zip(results, si_values, strict=True)]
    result = SweepResult(scene, rows, quantities, units, out_dir)
    _write_csv(result, out_dir / "sweep.csv")
    _plot(result, out_dir / "sweep.png")
    _write_markdown(result, out_dir / "sweep.md")
    return result


def _quantities(scene: Scene, results: list[JobResult]) -> tuple[list[str], dict[str, str]]:
    """The quantities to tabulate (the scene's list, else every numeric headline value)."""
    units: dict[str, str] = {}
    for res in results:
        for name, q in res.headline.items():
            if isinstance(q.get("value"), int | float):
                units.setdefault(name, q.get("unit", ""))
    wanted = list(scene.sweep.quantities) or sorted(units)
    done = [r for r in results if r.status == "completed"]
    missing = [q for q in wanted if q not in units]
    if done and missing:
        raise ScenarioError(
            scene.path,
            "sweep.quantities",
            f"{missing[0]!r} is not a headline quantity of the runs; expected one of "
            f"{sorted(units)}",
        )
    return wanted, {q: units.get(q, "") for q in wanted}


def _row(res: JobResult, value: float, quantities: list[str]) -> dict[str, Any]:
    row: dict[str, Any] = {
        "series": res.job.label,
        "value": value,
        "status": res.status,
        "message": res.message,
        "wall_time": res.stats.get("wall_time", math.nan),
    }
    for q in quantities:
        v = res.headline.get(q, {}).get("value", math.nan)
        row[q] = float(v) if isinstance(v, int | float) else math.nan
    return row


def _write_csv(result: SweepResult, path: Path) -> None:
    fields = ["series", "value", "status", "wall_time", *result.quantities, "message"]
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        writer.writeheader()
        writer.writerows(result.rows)


def _plot(result: SweepResult, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    spec = result.scene.sweep
    n = max(1, len(result.quantities))
    fig, axes = plt.subplots(n, 1, figsize=(7.5, 2.8 * n + 0.6), sharex=True, squeeze=False)
    for ax, q in zip(axes[:, 0], result.quantities, strict=False):
        for series in dict.fromkeys(r["series"] for r in result.rows):
            x, y = result.column(q, series)
            if x:
                ax.plot(x, y, "o-", label=series or None)
        ax.set_ylabel(f"{q} [{result.units.get(q) or '1'}]")
        ax.grid(True, alpha=0.3)
        if any(r["series"] for r in result.rows):
            ax.legend(fontsize="x-small", ncol=2)
    axes[-1, 0].set_xlabel(f"{spec.label} [{spec.unit}]")
    fig.suptitle(f"{result.scene.name}: sweep of {spec.label}")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _write_markdown(result: SweepResult, path: Path) -> None:
    spec = result.scene.sweep
    head = ["series", f"{spec.label} [{spec.unit}]", "status", "wall time [s]"]
    head += [f"{q} [{result.units.get(q) or '1'}]" for q in result.quantities]
    lines = [
        f"# Sweep: {result.scene.name}",
        "",
        f"`{spec.parameter}` over {len(spec.values)} values"
        + (f", {len(spec.series)} series" if spec.series else "")
        + f"; {len(result.rows)} runs.",
        "",
        "| " + " | ".join(head) + " |",
        "|" + "---|" * len(head),
    ]
    for r in result.rows:
        cells = [r["series"] or "-", f"{r['value']:.6g}", r["status"], f"{r['wall_time']:.3g}"]
        cells += [f"{r[q]:.6g}" for q in result.quantities]
        lines.append("| " + " | ".join(cells) + " |")
    failed = [r for r in result.rows if r["status"] != "completed"]
    for r in failed:
        lines.append(f"\n- {r['series'] or 'run'} at {r['value']:.6g}: {r['message']}")
    path.write_text("\n".join(lines) + "\n")
