"""Work–precision against the monolithic curve: the envelope read-off, the ratio per point,
the error-against-tolerance flag, and a short clock-train run that writes them."""

from __future__ import annotations

import csv
import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from orchestrator.run import reference_of
from orchestrator.scenario import load_scene
from orchestrator.scenes.family import Outcome
from orchestrator.scenes.m739 import TURNS
from orchestrator.scenes.m739.monolithic import REFERENCE_TOLERANCE
from orchestrator.studies.jobs import Job, JobResult
from orchestrator.studies.monolithic_curve import (
    MonolithicCurve,
    MonolithicPoint,
    envelope_time,
    monolithic_curve,
    monolithic_model,
    retime,
    time_in_window,
)
from orchestrator.studies.work_precision import MONOLITHIC, ONE_PASS, Row, summary, work_precision

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
#: The clock-train S&A armed at 5 deg of rotor instead of 46.4 deg (about 3 of 24 turns).
SHORT_CLOCK = {"scene.stop_when": {"signal": "train.rotor_angle", "above": "-115 deg"}}

# A monolithic curve as measured on M739: wrong path at loose tolerances (error 0.1), then
# not monotone in time (the 1e-8 run slower than the 1e-6 one) and a run that did not arm.
POINTS = [(1e-1, 0.29), (2e-4, 0.30), (3e-5, 0.40), (2e-6, 0.35), (1e-8, 0.90), (math.nan, 0.1)]


def test_envelope_is_the_least_time_of_the_runs_at_least_as_accurate() -> None:
    assert envelope_time(POINTS, 1e-3) == 0.30
    assert envelope_time(POINTS, 2e-4) == 0.30  # the point itself counts
    assert envelope_time(POINTS, 1e-4) == 0.35  # 3e-5 took longer than 2e-6
    assert envelope_time(POINTS, 1e-6) == 0.90
    assert envelope_time(POINTS, 0.5) == 0.29
    assert math.isnan(envelope_time(POINTS, 1e-9))  # more accurate than any run
    assert math.isnan(envelope_time(POINTS, math.nan))
    # Never increasing with the error asked for, and the run that did not arm never counts.
    errors = np.logspace(-8, 0, 50)
    times = [envelope_time(POINTS, e) for e in errors]
    assert all(a >= b for a, b in zip(times, times[1:], strict=False))
    assert min(times) == 0.29


def test_time_in_window_and_the_ratio_of_a_point() -> None:
    curve = MonolithicCurve(25.0, 1.0, [MonolithicPoint(1e-5, t, e) for e, t in POINTS])
    assert time_in_window(curve, 5e-5) == 0.35
    assert math.isnan(time_in_window(curve, 5e-3))  # outside 1e-6 .. 1e-3
    assert math.isnan(time_in_window(curve, 5e-7))
    assert math.isnan(time_in_window(None, 5e-5))
    assert curve.relative_error(25.0 * (1 + 3e-5)) == pytest.approx(3e-5, rel=1e-9)
    row = _row("regime-aware", 1e-3, wall=0.63, quantity_error=5e-5, mono=0.35)
    assert row.monolithic_ratio == pytest.approx(1.8)


def test_monolithic_curve_times_each_tolerance_against_the_truth() -> None:
    truth = 25.9
    calls = []

    def model(tolerance: float):
        calls.append(tolerance)
        if tolerance == 1e-2:
            return Outcome(math.nan, "stalled")
        return Outcome(truth * (1 + 10 * tolerance), "armed")

    curve = monolithic_curve(model, (1e-2, 1e-4, 1e-6))
    assert calls == [1e-12, 1e-2, 1e-4, 1e-6]  # each once: retime times them again
    assert curve.truth == pytest.approx(truth * (1 + 1e-11))
    assert math.isnan(curve.points[0].error)
    assert [p.error for p in curve.points[1:]] == pytest.approx([1e-3, 1e-5], rel=1e-6)
    assert all(p.wall_time > 0 for p in curve.points)
    # A truth that does not arm (a stop before arming) gives the reason, not a curve.
    never = monolithic_curve(lambda tolerance: Outcome(math.nan, "stop"), (1e-3,))
    assert never == "gave no value at tolerance 1e-12 (stop): no error"


def test_retime_runs_each_tolerance_again_and_keeps_the_least_time() -> None:
    calls = []

    def model(tolerance: float):
        calls.append(tolerance)
        return Outcome(1.0, "armed")

    slow = MonolithicCurve(
        1.0, 5.0, [MonolithicPoint(1e-3, 1e9, 2e-4), MonolithicPoint(1e-5, 1e9, 3e-6)]
    )
    again = retime(slow, model)
    assert calls == [1e-3, 1e-5]
    assert [(p.tolerance, p.error) for p in again.points] == [(1e-3, 2e-4), (1e-5, 3e-6)]
    assert all(0 < p.wall_time < 1e9 for p in again.points)  # the new, shorter time
    assert (again.truth, again.truth_wall_time) == (1.0, 5.0)
    fast = MonolithicCurve(1.0, 5.0, [MonolithicPoint(1e-3, 0.0, 2e-4)])
    assert retime(fast, model).points[0].wall_time == 0.0  # the earlier, shorter time


def test_the_report_times_the_curve_and_the_masters_in_alternate_rounds(
    tmp_path: Path, monkeypatch
) -> None:
    """Each round times the monolithic curve once and then runs every master setting once:
    a slow spell of a shared machine falls on both sides of the ratios."""
    import orchestrator.studies.work_precision as wp

    order = []
    curve = MonolithicCurve(1.0, 1.0, [MonolithicPoint(1e-3, 1.0, 1e-4)])
    monkeypatch.setattr(wp, "reference_of", lambda scene: SimpleNamespace(wall_time=1.0))
    monkeypatch.setattr(wp, "monolithic_model", lambda scene: (TURNS, lambda tol: None))
    monkeypatch.setattr(wp, "monolithic_curve", lambda *a: order.append("curve") or curve)
    monkeypatch.setattr(wp, "retime", lambda c, m: order.append("retime") or c)
    monkeypatch.setattr(wp, "run_jobs", lambda jobs, **k: order.append("masters") or [])
    monkeypatch.setattr(wp, "sweep_jobs", lambda *a: [])
    monkeypatch.setattr(wp, "plot_records", lambda *a: None)
    scene = SCENARIOS / "clock_train_sa.toml"
    wp.work_precision(scene, tmp_path / "a", repeats=3, monolithic_repeats=3)
    assert order == ["curve", "masters", "retime", "masters", "retime", "masters"]
    order.clear()
    wp.work_precision(scene, tmp_path / "b", repeats=1, monolithic_repeats=3)
    assert order == ["curve", "masters", "retime", "retime"]
    order.clear()
    wp.work_precision(scene, tmp_path / "c", repeats=2, monolithic_repeats=1)
    assert order == ["curve", "masters", "masters"]


def _row(master, tol, wall, quantity_error, mono=math.nan, setting="tolerance") -> Row:
    job = Job("scene.toml", {}, "out", master)
    result = JobResult(job, "completed", "", {}, {"do_steps": 10}, [], np.empty((0, 1)), [])
    return Row(master, setting, tol, result, {}, quantity_error, mono, wall)


def test_summary_flags_errors_over_the_tolerance_and_ratios_over_2x() -> None:
    curve = MonolithicCurve(25.0, 1.0, [MonolithicPoint(1e-5, 0.5, 2e-6)])
    rows = [
        _row("regime-aware", 1e-2, 0.9, 6e-4, 0.5),  # 1.8x, within tolerance
        _row("regime-aware", 1e-4, 1.5, 3e-4, 0.5),  # 3x, error over the tolerance
        _row(ONE_PASS, 1e-3, 0.8, 2e-4, 0.5),  # 1.6x
        _row(ONE_PASS, 1e-1, 0.6, 4e-3),  # outside the window: no ratio
        _row("jacobi", 1e-6, 2.0, 1e-2, setting="step"),
    ]
    scene = SimpleNamespace(name="m739", reference="m739")
    text = summary(rows, curve, scene, 1.0, headline=TURNS)
    assert (
        "| regime-aware | tolerance | 0.0001 | completed | 1.5 | 0.0003 | 0.5 | 3 | **NO** |"
        in (text)
    )
    assert "- regime-aware: NOT every point within 2x (1.8 at 0.01, 3 at 0.0001)" in text
    assert "- regime-aware/one-pass: every point within 2x (1.6 at 0.001)" in text
    assert "- jacobi: no point in the window" in text
    assert "- regime-aware: NO at 1 of 2 (0.0003 at 0.0001)" in text
    assert "- regime-aware/one-pass: yes at all 2 tolerances" in text
    assert "truth = the monolithic model at tolerance 1e-12" in text


@pytest.mark.parametrize(
    ("scene_file", "overrides"),
    [("m739.toml", {"scene.stop": "5 ms"}), ("clock_train_sa.toml", SHORT_CLOCK)],
)
def test_the_monolithic_model_is_the_references(scene_file, overrides, fmu_cache) -> None:
    """The family's model runs the reference's physics: at the reference's tolerance it
    gives the reference's turns to arm exactly (M739 cut at 5 ms: neither arms)."""
    scene = load_scene(SCENARIOS / scene_file, overrides, cache_dir=fmu_cache)
    found = monolithic_model(scene)
    assert found is not None and found[0] == TURNS
    outcome, headline = found[1](REFERENCE_TOLERANCE), reference_of(scene).headline
    if "clock" in scene_file:
        assert outcome == Outcome(headline["turns_to_arm"], "armed")
    else:
        assert math.isnan(outcome.value) and outcome.reason == "stop time reached"
        assert "turns_to_arm" not in headline


def test_no_monolithic_model_without_a_family_model() -> None:
    for reference in ("press_feed", "two_inertias", None):
        assert monolithic_model(SimpleNamespace(reference=reference)) is None


@pytest.mark.slow  # in the slow suite (CI runs it): the default stays under 2 minutes
def test_precision_run_on_a_short_clock_train_writes_the_monolithic_columns(
    tmp_path: Path, fmu_cache, monkeypatch
) -> None:
    monkeypatch.setenv("MECHCOSIM_FMU_CACHE", str(fmu_cache))
    out = tmp_path / "wp"
    rows = work_precision(
        SCENARIOS / "clock_train_sa.toml",
        out,
        step_factors=(),
        tolerances=(1e-2,),
        workers=2,
        overrides=SHORT_CLOCK,
        monolithic_tolerances=(1e-3, 1e-5),
        monolithic_repeats=1,
    )
    assert [r.master for r in rows] == ["regime-aware", ONE_PASS]
    assert all(r.result.status == "completed" for r in rows)
    with open(out / "work_precision.csv") as f:
        records = list(csv.DictReader(f))
    mono = [r for r in records if r["master"] == MONOLITHIC]
    assert [float(r["value"]) for r in mono] == [1e-3, 1e-5]
    # The clock train's monolithic turns error at 1e-5 (full run: 4.5e-6, against 1e-12).
    assert 1e-7 < float(mono[1]["turns_error"]) < 1e-4
    curve_points = [(float(r["turns_error"]), float(r["wall_time"])) for r in mono]
    ra = rows[0]
    # The master's turns error against the same truth as the curve's, in the window (2.7e-5
    # measured), and its ratio read off the curve written beside it.
    scene = load_scene(SCENARIOS / "clock_train_sa.toml", SHORT_CLOCK, cache_dir=fmu_cache)
    truth = monolithic_model(scene)[1](1e-12).value
    turns = ra.result.headline["turns_to_arm"]["value"]
    assert ra.quantity_error == pytest.approx(abs(turns - truth) / truth, rel=1e-12)
    assert 1e-6 < ra.quantity_error < 1e-3
    assert ra.within_tolerance == "yes"  # 2.7e-5 at tolerance 1e-2
    assert ra.monolithic_time == envelope_time(curve_points, ra.quantity_error)
    assert ra.monolithic_ratio == pytest.approx(ra.wall_time / ra.monolithic_time)
    record = next(r for r in records if r["master"] == "regime-aware")
    assert float(record["monolithic_ratio"]) == pytest.approx(ra.monolithic_ratio)
    assert record["within_tolerance"] == "yes"
    text = (out / "work_precision.md").read_text()
    assert "x monolithic" in text and "Against the monolithic curve" in text
    assert (out / "work_precision.png").stat().st_size > 0
