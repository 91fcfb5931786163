"""Work–precision report: error against wall time for every master setting of a scene.

One command runs the scene's reference once, then sweeps the masters (fixed-step Jacobi and
Gauss–Seidel over macro steps; tolerance-driven masters, and the regime-aware master's
single pass, over tolerances) on a process pool or a Dask cluster, and writes
``work_precision.csv``, ``work_precision.png`` and ``work_precision.md`` with the observed
convergence order of each master.

Where the scene's family has a monolithic model and a headline quantity (its ``monolithic``
and ``headline``: the S&As' turns to arm), that model also runs over its own tolerances; its
curve is drawn with the masters on the panel of that quantity's error, and each master
point in the error window 1e-6 .. 1e-3 gets the ratio of its time to the monolithic model's
time at the same accuracy.  Each tolerance-driven point is flagged when its error (that
quantity's, else the largest headline error) exceeds its tolerance.
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
from orchestrator.masters.registry import tolerance_masters
from orchestrator.run import reference_of
from orchestrator.scenario import load_scene
from orchestrator.scene_model import Scene
from orchestrator.scenes.family import Headline
from orchestrator.setting_limits import check_step_factors, check_tolerances, check_workers
from orchestrator.studies.jobs import Job, JobResult, run_jobs
from orchestrator.studies.monolithic_curve import (
    CURVE_TOLERANCES,
    REPEATS,
    TARGET_RATIO,
    TRUTH_TOLERANCE,
    WINDOW,
    MonolithicCurve,
    envelope_time,
    monolithic_curve,
    monolithic_model,
    retime,
    time_in_window,
)

STEP_FACTORS = (8.0, 4.0, 2.0, 1.0, 0.5, 0.25)
TOLERANCES = (1e-1, 1e-2, 1e-3, 1e-4, 1e-5)
COUNTERS = ("steps", "do_steps", "rollbacks", "rejections", "iterations", "events")
#: The error column of a scene whose family has no monolithic model (empty there; named as
#: in the S&A tables, so that every work-precision table has the same columns).
NO_HEADLINE = Headline("", "turns_error", "turns")


def columns(headline: Headline = NO_HEADLINE) -> list[str]:
    """The table's columns; the error of the family's headline quantity is the sixth."""
    return [
        "master",
        "setting",
        "value",
        "status",
        "wall_time",
        headline.error_column,
        "monolithic_time",
        "monolithic_ratio",
        "within_tolerance",
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
    #: relative error of the family's headline quantity against the monolithic truth (NaN:
    #: no monolithic model)
    quantity_error: float = math.nan
    monolithic_time: float = math.nan  # the monolithic model's time for quantity_error
    #: best wall time of the repeats (the result's own when run once)
    wall_time: float = math.nan
    headline: Headline = NO_HEADLINE  # the family's quantity quantity_error is of

    @property
    def monolithic_ratio(self) -> float:
        return self.wall_time / self.monolithic_time if self.monolithic_time > 0 else math.nan

    @property
    def error(self) -> float:
        """The error the tolerance is held against: the headline quantity's, else the
        largest headline error."""
        if math.isfinite(self.quantity_error):
            return self.quantity_error
        return self.accuracy.get("headline_error", math.nan)

    @property
    def within_tolerance(self) -> str:
        """'yes' / 'no' for a tolerance-driven point, '' otherwise (or no error)."""
        if self.setting != "tolerance" or not math.isfinite(self.error):
            return ""
        return "yes" if self.error <= self.value else "no"

    def as_dict(self) -> dict[str, Any]:
        stats = self.result.stats
        energy = self.result.headline.get("energy_residual", {}).get("value", math.nan)
        return {
            "master": self.master,
            "setting": self.setting,
            "value": self.value,
            "status": self.result.status,
            "wall_time": self.wall_time,
            self.headline.error_column: self.quantity_error,
            "monolithic_time": self.monolithic_time,
            "monolithic_ratio": self.monolithic_ratio,
            "within_tolerance": self.within_tolerance,
            "headline_error": self.accuracy.get("headline_error", math.nan),
            "trajectory_error": self.accuracy.get("trajectory_error", math.nan),
            "event_time_error": self.accuracy.get("event_time_error", math.nan),
            "energy_residual": energy,
            **{k: stats.get(k, 0) for k in COUNTERS},
        }


#: Label of the regime-aware master with inputs held at the step start (the baseline that
#: the midpoint hold, labelled "regime-aware", is measured against).
START_HOLD = "regime-aware/start"
#: The fixed-step masters, swept over macro steps.
FIXED_STEP = ("jacobi", "gauss-seidel")
#: Label of the regime-aware master's single pass (``input_hold = "extrapolated"``).
ONE_PASS = "regime-aware/one-pass"


def sweep_jobs(
    scene_path: Path,
    scene: Scene,
    out_dir: Path,
    step_factors,
    tolerances,
    start_hold_tolerances=(),
    base: dict[str, Any] | None = None,
) -> list[Job]:
    """The sweep's runs; ``base`` overrides go into every one (e.g. a shorter stop)."""

    def job(overrides: dict, directory: str, label: str) -> Job:
        # The study compares every run with one reference it computes itself, and draws
        # one diagram of them all (a plot per run would cost more than most runs).
        return Job(
            str(scene_path),
            {**(base or {}), **overrides},
            str(out_dir / directory),
            label,
            compare_reference=False,
            plots=False,
        )

    jobs = []
    for master in FIXED_STEP:
        for f in step_factors:
            h = scene.master.step * f
            if h <= scene.stop - scene.start:
                overrides = {"master.algorithm": master, "master.step": h}
                jobs.append(job(overrides, f"{master}_h{h:.3e}", master))
    for master in tolerance_masters():
        for tol in tolerances:
            # The midpoint hold: the single pass ("auto" picks it where a copy judges the
            # coupling) has a line of its own.
            overrides = {
                "master.algorithm": master,
                "master.tolerance": tol,
                "master.input_hold": "midpoint",
            }
            jobs.append(job(overrides, f"{master}_tol{tol:.0e}", master))
    # The regime-aware master's other schemes, each a line of its own.
    for hold, label, tols in (
        ("extrapolated", ONE_PASS, tolerances),
        ("start", START_HOLD, start_hold_tolerances),
    ):
        for tol in tols:
            overrides = {
                "master.algorithm": "regime-aware",
                "master.tolerance": tol,
                "master.input_hold": hold,
            }
            jobs.append(job(overrides, f"{label.replace('/', '-')}_tol{tol:.0e}", label))
    return jobs


def work_precision(
    scene_path: Path,
    out_dir: Path | None = None,
    step_factors=STEP_FACTORS,
    tolerances=TOLERANCES,
    workers: int | None = None,
    dask_address: str | None = None,
    start_hold_tolerances=(),
    overrides: dict[str, Any] | None = None,
    repeats: int = 1,
    monolithic_tolerances=CURVE_TOLERANCES,
    monolithic_repeats: int = REPEATS,
) -> list[Row]:
    """Sweep the masters (each run ``repeats`` times, its least wall time kept) and, where
    the scene has a monolithic model, that model over ``monolithic_tolerances`` (each
    timed ``monolithic_repeats`` times, in this process).  The runs go in rounds, each
    round the monolithic curve once and then every master setting once, so that the two
    sides of each ratio sample the same spells of a shared machine."""
    check_tolerances(tolerances, "--tolerances")
    check_tolerances(start_hold_tolerances, "--start-hold-tolerances")
    check_tolerances(monolithic_tolerances, "--monolithic-tolerances")
    check_workers(workers)
    scene = load_scene(scene_path, overrides)
    if not scene.reference:
        raise ScenarioError(scene_path, "report.reference", "missing; the report needs a reference")
    check_step_factors(step_factors, scene.master.step, scene.stop - scene.start)
    out_dir = Path(out_dir or Path("runs") / f"{scene.name}_work_precision")
    out_dir.mkdir(parents=True, exist_ok=True)
    reference = reference_of(scene)
    monolithic = monolithic_model(scene)
    headline, model = monolithic if monolithic else (NO_HEADLINE, None)
    curve, notes = None, []
    if model is not None:
        curve = monolithic_curve(model, monolithic_tolerances)
        if isinstance(curve, str):
            curve, notes = None, [f"The monolithic model {curve}."]
    jobs = sweep_jobs(
        scene_path, scene, out_dir, step_factors, tolerances, start_hold_tolerances, overrides
    )
    results = run_jobs(jobs, workers=workers, dask_address=dask_address)
    walls = [r.stats.get("wall_time", math.nan) for r in results]
    for round_ in range(1, max(repeats, monolithic_repeats)):
        if curve is not None and round_ < monolithic_repeats:
            curve = retime(curve, model)
        if round_ < repeats:  # after the first round, so that no two write one directory
            again = run_jobs(jobs, workers=workers, dask_address=dask_address)
            again_walls = [r.stats.get("wall_time", math.nan) for r in again]
            walls = [min(a, b) for a, b in zip(walls, again_walls, strict=True)]
    rows = []
    for job, res, wall in zip(jobs, results, walls, strict=True):
        accuracy = {}
        if res.status == "completed":
            accuracy = compare(res.header, res.data, res.events, res.headline, reference)
        # By the master, not by the keys: --set may put either key into every job.
        setting = "step" if job.label in FIXED_STEP else "tolerance"
        value = job.overrides[f"master.{setting}"]
        row = Row(job.label, setting, value, res, accuracy, wall_time=wall, headline=headline)
        quantity = headline.quantity
        if curve is not None and res.status == "completed" and quantity in res.headline:
            row.quantity_error = curve.relative_error(float(res.headline[quantity]["value"]))
            row.monolithic_time = time_in_window(curve, row.quantity_error)
        rows.append(row)
    records = [r.as_dict() for r in rows] + monolithic_records(curve, headline)
    _write_csv(records, out_dir / "work_precision.csv", headline)
    png = out_dir / "work_precision.png"
    plot_records(records, reference.wall_time, scene.name, png, headline)
    text = summary(
        rows, curve, scene, reference.wall_time, repeats, monolithic_repeats, notes, headline
    )
    (out_dir / "work_precision.md").write_text(text)
    return rows


#: The label of the monolithic model's rows in the CSV and its line in the diagram.
MONOLITHIC = "monolithic"


def monolithic_records(
    curve: MonolithicCurve | None, headline: Headline = NO_HEADLINE
) -> list[dict[str, Any]]:
    """The monolithic curve as table rows (the columns the masters' rows have)."""
    if curve is None:
        return []
    out = []
    for p in curve.points:
        record: dict[str, Any] = dict.fromkeys(columns(headline), math.nan)
        record.update(
            master=MONOLITHIC,
            setting="tolerance",
            value=p.tolerance,
            status="completed" if math.isfinite(p.error) else "not armed",
            wall_time=p.wall_time,
            within_tolerance="",
            **dict.fromkeys(COUNTERS, ""),
        )
        record[headline.error_column] = p.error
        out.append(record)
    return out


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


def _write_csv(records: list[dict[str, Any]], path: Path, headline: Headline) -> None:
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=columns(headline))
        writer.writeheader()
        writer.writerows(records)


def _float(value: Any) -> float:
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan


def plot_records(
    records: list[dict[str, Any]],
    reference_time: float,
    name: str,
    path: Path,
    headline: Headline = NO_HEADLINE,
):
    """The diagram from table rows (``Row.as_dict`` and ``monolithic_records``, or the CSV
    read back).  The right panel is the headline quantity's error when the rows have one
    (the monolithic curve on the same axes), else the largest headline error."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import NullFormatter

    own = headline.error_column
    has_own = any(math.isfinite(_float(r.get(own))) for r in records)
    fig, axes = plt.subplots(1, 2, figsize=(14 if has_own else 11, 4.5))
    panels = ("trajectory_error", own if has_own else "headline_error")
    for ax, error in zip(axes, panels, strict=True):
        for master in dict.fromkeys(r["master"] for r in records):
            pts = [
                (_float(r["wall_time"]), _float(r[error]))
                for r in records
                if r["master"] == master and r["status"] == "completed"
            ]
            pts = sorted((x, y) for x, y in pts if y > 0 and math.isfinite(y))
            if pts and master == MONOLITHIC:
                _draw_monolithic(ax, pts)
            elif pts:
                ax.loglog(*zip(*pts, strict=True), "o-", label=master)
        if reference_time > 0:
            ax.axvline(reference_time, color="grey", ls=":", label="reference run time")
        if error == own:
            for level in WINDOW:  # the accuracies compared with the monolithic model
                ax.axhline(level, color="grey", lw=0.8, ls="-.")
        ax.xaxis.set_minor_formatter(NullFormatter())  # minor labels collide on short spans
        ax.set_xlabel("wall time [s]")
        label = {
            own: f"{headline.word} error (relative, vs monolithic at {TRUTH_TOLERANCE:g})",
            "headline_error": "largest headline error (relative)",
        }.get(error, error.replace("_", " ") + " (relative)")
        ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3)
        if error == own:  # beside the axes: the monolithic curve spans them
            ax.legend(fontsize="small", loc="upper left", bbox_to_anchor=(1.02, 1.0))
        else:
            ax.legend(fontsize="small")
    fig.suptitle(f"{name}: work–precision")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _draw_monolithic(ax: Any, pts: list[tuple[float, float]]) -> None:
    """The monolithic runs as points, and the envelope the ratios are read off: for each
    error, the least time of a run at least that accurate (a staircase)."""
    ax.loglog(*zip(*pts, strict=True), "ks", label=MONOLITHIC)
    errors = np.logspace(np.log10(min(e for _, e in pts)), np.log10(max(e for _, e in pts)), 400)
    times = [envelope_time([(e, t) for t, e in pts], x) for x in errors]
    ax.loglog(times, errors, "k-", lw=1.2, label=f"{MONOLITHIC}: least time for an error")
    ax.loglog(
        [TARGET_RATIO * t for t in times], errors, "k:", lw=1.2, label=f"{TARGET_RATIO:g}x that"
    )


def _g(x: float) -> str:
    return "–" if not math.isfinite(x) else f"{x:.3g}"


def summary(
    rows: list[Row],
    curve: MonolithicCurve | None,
    scene: Scene,
    reference_time: float,
    repeats: int = 1,
    monolithic_repeats: int = REPEATS,
    notes: list[str] | None = None,
    headline: Headline = NO_HEADLINE,
) -> str:
    """The Markdown report: every run, the monolithic curve, and the two verdicts (time
    against the monolithic model in the error window of the family's headline quantity;
    error against tolerance)."""
    word = headline.word
    timing = "one run each" if repeats == 1 else f"the least of {repeats} runs"
    lines = [
        f"# Work–precision: {scene.name}",
        "",
        f"Reference: `{scene.reference}` ({reference_time:.3g} s). {len(rows)} runs; master "
        f"wall times: {timing}. Headline error: the largest relative error of the headline "
        "quantities against the reference; trajectory error: relative, against the reference.",
        *(["", *notes] if notes else []),
    ]
    if curve is not None:
        lines += [
            "",
            f"{word.capitalize()} error: |{word} - truth| / truth for the master runs and the "
            f"monolithic runs alike, truth = the monolithic model at tolerance "
            f"{TRUTH_TOLERANCE:g} ({curve.truth:.9g} {word}, {curve.truth_wall_time:.3g} s).",
            "",
            "x monolithic: the run's wall time / the least time of a monolithic run whose "
            f"{word} error is at most the run's (only for {word} errors {WINDOW[0]:g} .. "
            f"{WINDOW[1]:g}; monolithic times: the least of {monolithic_repeats} runs, one in "
            "each round of the sweep, before its master runs).",
        ]
    error_name = f"{word} error" if curve is not None else "largest headline error"
    head = "| master | setting | value | status | wall time [s] |"
    rule = "|---|---|---|---|---|"
    if curve is not None:
        head += f" {word} error | monolithic time [s] | x monolithic |"
        rule += "---|---|---|"
    head += (
        f" {error_name} <= tolerance | headline error | trajectory error | event-time error [s] "
        "| energy residual | doSteps | rollbacks |"
    )
    rule += "---|---|---|---|---|---|---|"
    lines += ["", head, rule]
    for r in rows:
        d = r.as_dict()
        cells = [
            d["master"],
            d["setting"],
            f"{d['value']:.3g}",
            d["status"],
            _g(d["wall_time"]),
        ]
        if curve is not None:
            cells += [_g(r.quantity_error), _g(r.monolithic_time), _g(r.monolithic_ratio)]
        flag = {"yes": "yes", "no": "**NO**"}.get(r.within_tolerance, "")
        cells += [
            flag,
            _g(d["headline_error"]),
            _g(d["trajectory_error"]),
            _g(d["event_time_error"]),
            _g(d["energy_residual"]),
            str(d["do_steps"]),
            str(d["rollbacks"]),
        ]
        lines.append("| " + " | ".join(cells) + " |")
    if curve is not None:
        lines += _monolithic_lines(rows, curve, monolithic_repeats, word)
    lines += ["", f"The tolerance means accuracy ({error_name} <= tolerance):", ""]
    for master in dict.fromkeys(r.master for r in rows if r.setting == "tolerance"):
        points = [r for r in rows if r.master == master and r.within_tolerance]
        over = [r for r in points if r.within_tolerance == "no"]
        if not points:
            lines.append(f"- {master}: no completed run with an error")
        elif not over:
            lines.append(f"- {master}: yes at all {len(points)} tolerances")
        else:
            worst = ", ".join(f"{_g(r.error)} at {r.value:g}" for r in over)
            lines.append(f"- {master}: NO at {len(over)} of {len(points)} ({worst})")
    lines += ["", "Observed order (slope of log trajectory error against log setting):", ""]
    for master in dict.fromkeys(r.master for r in rows):
        setting = next(r.setting for r in rows if r.master == master)
        lines.append(f"- {master}: {observed_order(rows, master):.2f} (per {setting})")
    return "\n".join(lines) + "\n"


def _monolithic_lines(
    rows: list[Row], curve: MonolithicCurve, repeats: int, word: str
) -> list[str]:
    lines = [
        "",
        f"Monolithic model over its tolerances (wall time: the least of {repeats} runs):",
        "",
        f"| tolerance | wall time [s] | {word} error |",
        "|---|---|---|",
    ]
    lines += [f"| {p.tolerance:g} | {p.wall_time:.3g} | {_g(p.error)} |" for p in curve.points]
    lo, hi = WINDOW
    lines += [
        "",
        f"Against the monolithic curve ({word} error {lo:g} .. {hi:g}, target <= "
        f"{TARGET_RATIO:g}x the monolithic time at the same accuracy):",
        "",
    ]
    for master in dict.fromkeys(r.master for r in rows):
        ratios = [
            (r.value, r.monolithic_ratio)
            for r in rows
            if r.master == master and lo <= r.quantity_error <= hi
        ]
        if not ratios:
            lines.append(f"- {master}: no point in the window")
            continue
        values = [x for _, x in ratios]
        verdict = (
            "every point within"
            if all(x <= TARGET_RATIO for x in values)
            else "NOT every point within"
        )
        listed = ", ".join(f"{_g(x)} at {v:g}" for v, x in ratios)
        lines.append(f"- {master}: {verdict} {TARGET_RATIO:g}x ({listed})")
    return lines
