"""Press-feed scenes under fixed-step Gauss-Seidel against the monolithic reference.

Runs 1-3 of Xu (1993) Part I and the Part II sprag-clutch decay experiment at 72 and
197 rpm, each a scene in scenarios/.  Here every scene runs with fixed-step Gauss-Seidel,
clutch first, at 0.1 ms (0.05 ms for the decay scenes) — Run 2's own default is the
regime-aware master, tested in test_press_feed_regime_aware.py.  The errors are measured
against ``orchestrator.scenes.press_feed.report:reference`` (same parameters, exact events).

Stated tolerances at each scene's default step (measured values in brackets, worst scene):
feed length per cycle 1e-3 relative [7.3e-4, Run 2], windup history 3e-2 of the peak
windup [2.2e-2, Run 2], energy residual 2.5e-3 of the crank work [1.6e-3, Run 2],
switching crank angles within two macro steps of crank rotation, decay ratio 3 % [1.5 %].
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from components.press_feed_data import ROLLER_RADIUS
from orchestrator.cli import main as cli_main
from orchestrator.run import RunResult, reference_of, run_scene
from orchestrator.scenario import load_scene
from orchestrator.scenes.press_feed.report import (
    FEED,
    OVERRUN,
    UNWIND,
    WINDUP,
    feed_scene,
    run_regime_sequences,
    sampled_events,
)

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
SCENES = sorted(p.name for p in SCENARIOS.glob("press_feed_*.toml")) + sorted(
    p.name for p in SCENARIOS.glob("sprag_decay_*.toml")
)
DECAY_SCENES = [s for s in SCENES if s.startswith("sprag_decay")]
# Run 1 and the 72 rpm decay in the default suite; the other operating points validate
# the same code paths at other speeds and loads, in the slow suite.
OTHER_POINTS = {"press_feed_run2.toml", "press_feed_run3.toml", "sprag_decay_197rpm.toml"}
SCENE_CASES = [pytest.param(s, marks=pytest.mark.slow) if s in OTHER_POINTS else s for s in SCENES]
DECAY_CASES = [c for c, s in zip(SCENE_CASES, SCENES, strict=True) if s in DECAY_SCENES]

SHAFT_STOP = ("load", "slip-forward", "stick")
# Scenes whose own master is not fixed-step: the settings this file tests them with.
FIXED_STEP = {"press_feed_run2.toml": {"master.algorithm": "gauss-seidel", "master.step": "0.1 ms"}}
FEED_TOL = 1e-3
WINDUP_TOL = 3e-2
ENERGY_TOL = 2.5e-3
DECAY_TOL = 0.03
HEADLINE = (
    "feed_length_mean",
    "feed_length_last",
    "peak_windup",
    "mean_windup_feed",
    "feed_start_angle",
    "unwind_start_angle",
    "overrun_start_angle",
    "engage_angle",
    "windup_fraction",
    "feed_fraction",
    "unwind_fraction",
    "overrun_fraction",
    "disengagements",
)


def _windup_error(scene, run: RunResult, ref) -> float:
    """max |w_run - w_ref| / max |w_ref| over the run."""
    name = f"{feed_scene(scene).clutch}.windup"
    w_ref = ref.signals(run.signal("time"))[name]
    return float(np.max(np.abs(run.signal(name) - w_ref)) / np.max(np.abs(w_ref)))


@pytest.fixture(scope="module")
def runs(scene_runs):
    """Each scene run once under fixed-step Gauss-Seidel (with the reference and its plot),
    on demand."""
    return lambda name: scene_runs(name, FIXED_STEP.get(name), plots=True)


@pytest.fixture(scope="module")
def references(runs):
    """Each scene's monolithic reference: the one its run was compared with."""

    def get(name: str):
        ref = runs(name).reference
        assert ref is not None, runs(name).notes
        return ref

    return get


def test_every_scene_is_there():
    assert len(SCENES) == 5 and len(DECAY_SCENES) == 2


def test_scenes_check():
    assert cli_main(["check", *(str(SCENARIOS / s) for s in SCENES)]) == 0


@pytest.mark.parametrize("name", SCENE_CASES)
def test_scene_loads_only_its_three_fmus(name):
    scene = load_scene(SCENARIOS / name, FIXED_STEP.get(name))
    assert sorted(spec.fmu_name for spec in scene.fmus.values()) == [
        "BrakeLoad",
        "CrankCouplerDrive",
        "SpragClutch",
    ]
    assert scene.family == "press_feed" and scene.reference == "press_feed"
    assert scene.master.algorithm == "gauss-seidel"
    # ports joined every role: angle and speed of both races in, torque out to both sides
    assert len(scene.connections) == 6


@pytest.mark.parametrize("name", SCENE_CASES)
def test_scene_runs_and_reports(name, runs):
    r = runs(name)
    assert r.status == "completed", r.message
    for key in HEADLINE:
        assert key in r.headline, key
        assert math.isfinite(r.value(key))
    if not feed_scene(r.scene).rigid:
        assert r.value("peak_strain") > 0 and r.value("peak_deflection") > 0
    png = r.output_dir / f"{r.scene.name}.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 10_000
    assert (r.output_dir / "summary.json").exists()


@pytest.mark.parametrize("name", SCENE_CASES)
def test_against_the_monolithic_reference(name, runs):
    r = runs(name)
    acc = r.accuracy
    assert acc["headline_error.feed_length_mean"] < FEED_TOL
    assert acc["headline_error.feed_length_last"] < FEED_TOL
    assert acc["trajectory_error"] < WINDUP_TOL  # windup, rocker and roller angles


@pytest.mark.parametrize("name", SCENE_CASES)
def test_windup_history_against_the_reference(name, runs, references):
    r = runs(name)
    assert _windup_error(r.scene, r, references(name)) < WINDUP_TOL


@pytest.mark.parametrize("name", SCENE_CASES)
def test_energy_balance(name, runs):
    r = runs(name)
    assert r.value("energy_residual") < ENERGY_TOL
    assert r.value("crank_work_per_cycle") > 0.0


@pytest.mark.parametrize("name", SCENE_CASES)
def test_four_regimes_in_every_cycle(name, runs):
    r = runs(name)
    seqs = run_regime_sequences(r.scene, r.header, r.data)
    period = feed_scene(r.scene).period
    assert len(seqs) == math.floor((r.scene.stop - r.scene.start) / period + 1e-9)
    for seq in seqs:
        assert set(seq) == {WINDUP, FEED, UNWIND, OVERRUN}, seq
        first = [seq.index(k) for k in (WINDUP, FEED, UNWIND, OVERRUN)]
        assert first == sorted(first), seq
        assert seq[-1] == OVERRUN


# Run 2: the clutch unloads mid-feed for about 1 ms per cycle (found by the monolithic
# reference; the thesis assumes it never does, eq. 65); the windup
# only grazes zero there, and fixed-step coupling at 0.1 ms keeps it just above zero, so
# those disengagements are missed.  A master that locates the switches must pass this.
MISSES_GRAZING = pytest.mark.xfail(
    reason="fixed-step Gauss-Seidel misses Run 2's mid-feed disengagements", strict=True
)
LOCATED = [
    pytest.param(s, marks=[MISSES_GRAZING, pytest.mark.slow])
    if s == "press_feed_run2.toml"
    else pytest.param(s, marks=pytest.mark.slow)
    if s in OTHER_POINTS
    else s
    for s in SCENES
]


@pytest.mark.parametrize("name", SCENE_CASES)
def test_switching_angles_against_the_reference(name, runs, references):
    r = runs(name)
    ref = references(name).headline
    fs = feed_scene(r.scene)
    tol = 2.0 * fs.omega * r.scene.master.step  # two macro steps of crank rotation
    # Engagement (rocker reversal), break-away and disengagement; the entry into unwinding
    # is a shaft stop in some scenes, see test_shaft_stop_time_converges.
    for key in ("feed_start_angle", "overrun_start_angle", "engage_angle"):
        assert abs(r.value(key) - ref[key]) < tol, key
    for key in ("windup_fraction", "feed_fraction", "unwind_fraction", "overrun_fraction"):
        assert abs(r.value(key) - ref[key]) < 4.0 * r.scene.master.step / fs.period, key


@pytest.mark.parametrize("name", LOCATED)
def test_regime_events_match_the_reference(name, runs, references):
    r = runs(name)
    ref_events = references(name).events
    run_events = sampled_events(r.scene, r.header, r.data)
    assert ref_events, "the reference locates the regime switches"
    groups: dict[tuple, list[float]] = {}
    for t, *key in ref_events:
        groups.setdefault(tuple(key), []).append(t)
    seen: dict[tuple, list[float]] = {}
    for t, *key in run_events:
        seen.setdefault(tuple(key), []).append(t)
    assert sorted(groups) == sorted(seen)
    for key, times in groups.items():
        assert len(seen[key]) == len(times), key
        if key == SHAFT_STOP:
            continue  # test_shaft_stop_time_converges
        err = max(abs(a - b) for a, b in zip(seen[key], times, strict=True))
        assert err < 2.0 * r.scene.master.step, key


def _stop_time_error(name: str, h: str, cache: Path, tmp: Path) -> float:
    scene = load_scene(SCENARIOS / name, {"master.step": h})
    r = run_scene(scene, tmp / h.replace(" ", ""), cache, False, compare_reference=False)
    run = [t for t, *key in sampled_events(scene, r.header, r.data) if tuple(key) == SHAFT_STOP]
    ref = [t for t, *key in reference_of(scene).events if tuple(key) == SHAFT_STOP]
    assert len(run) == len(ref) > 0
    return max(abs(a - b) for a, b in zip(run, ref, strict=True))


@pytest.mark.slow  # a convergence study: several runs
def test_shaft_stop_time_converges(fmu_cache, tmp_path):
    # The roller stops when its speed reaches zero: the stop time carries the roller speed
    # error divided by the deceleration, about 3 macro steps early at every step here
    # (197 rpm), so it is held to first-order convergence rather than to two steps.
    errs = [
        _stop_time_error("sprag_decay_197rpm.toml", h, fmu_cache, tmp_path)
        for h in ("0.2 ms", "0.1 ms", "0.05 ms")
    ]
    for coarse, fine in zip(errs, errs[1:], strict=False):
        assert fine < coarse / 1.5, errs


# Run 2's reference: another operating point, long validation
@pytest.mark.slow
def test_run2_reference_clutch_unloads_mid_feed(references):
    # 300 rpm with the heavy strip: the windup transient exceeds the preload and the clutch
    # disengages during the feed (the thesis's min brake torque criterion, eqs 65-67).
    ref = references("press_feed_run2.toml")
    assert ref.headline["disengagements"] == 2.0
    assert ref.headline["mean_windup_feed"] < 0.95 * (300.0 / 2.0e5) ** (2.0 / 3.0)


# -- against the thesis ---------------------------------------------------------------------
def test_run1_against_the_thesis(runs):
    r = runs("press_feed_run1.toml")
    feed_deg = math.degrees(r.value("feed_length_mean") / ROLLER_RADIUS)
    assert feed_deg == pytest.approx(25.0, abs=0.6)  # rocker swing 25.57 deg minus windups
    assert 265.0 < math.degrees(r.value("feed_start_angle")) < 280.0  # App. H 271.1 deg
    assert 85.0 < math.degrees(r.value("overrun_start_angle")) < 100.0  # App. H 90.45 deg
    assert math.degrees(r.value("engage_angle")) == pytest.approx(255.65, abs=0.5)
    # peak windup of App. H's linearized model integrated here (derived): 0.0139 rad
    assert r.value("peak_windup") == pytest.approx(0.0139, rel=0.05)
    # peak strain at the gauge: about 112 microstrain in the same derived run (eq. 63, x1 = 11 in)
    assert r.value("peak_strain") == pytest.approx(112e-6, rel=0.1)


@pytest.mark.parametrize("name", DECAY_CASES)
def test_decay_ratio(name, runs):
    r = runs(name)
    assert r.accuracy["headline_error.decay_ratio"] < DECAY_TOL
    if name == "sprag_decay_72rpm.toml":
        assert 0.66 <= r.value("decay_ratio") <= 0.69  # Table 2: R = 0.669


# -- convergence in the macro step ----------------------------------------------------------
def _errors(name: str, steps: list[str], stop: str | None, cache: Path, tmp: Path):
    overrides = {"scene.stop": stop} if stop else {}
    ref = reference_of(load_scene(SCENARIOS / name, overrides))
    rows = []
    for h in steps:
        fixed = {**FIXED_STEP.get(name, {}), **overrides, "master.step": h}
        scene = load_scene(SCENARIOS / name, fixed)
        r = run_scene(scene, tmp / h.replace(" ", ""), cache, False, compare_reference=False)
        assert r.status == "completed", r.message
        feed = abs(r.value("feed_length_last") - ref.headline["feed_length_last"])
        row = {
            "feed": feed / ref.headline["feed_length_last"],
            "windup": _windup_error(scene, r, ref),
            "energy": r.value("energy_residual"),
        }
        if "decay_ratio" in ref.headline:
            row["decay"] = abs(r.value("decay_ratio") / ref.headline["decay_ratio"] - 1.0)
        rows.append(row)
    return rows


def _assert_first_order(rows: list[dict], key: str) -> None:
    errs = [row[key] for row in rows]
    for coarse, fine in zip(errs, errs[1:], strict=False):
        assert fine < coarse / 1.5, (key, errs)  # halving the step: about half the error


@pytest.mark.slow  # a convergence study: several runs
def test_run1_error_shrinks_with_the_step(fmu_cache, tmp_path):
    rows = _errors(
        "press_feed_run1.toml", ["0.4 ms", "0.2 ms", "0.1 ms"], "0.3 s", fmu_cache, tmp_path
    )
    for key in ("feed", "windup", "energy"):
        _assert_first_order(rows, key)


@pytest.mark.slow  # a convergence study: several runs
def test_decay_ratio_error_shrinks_with_the_step(fmu_cache, tmp_path):
    rows = _errors(
        "sprag_decay_197rpm.toml", ["0.2 ms", "0.1 ms", "0.05 ms"], None, fmu_cache, tmp_path
    )
    for key in ("decay", "windup", "energy"):
        _assert_first_order(rows, key)


@pytest.mark.slow
@pytest.mark.parametrize("name", SCENE_CASES)
def test_every_scene_converges(name, fmu_cache, tmp_path):
    rows = _errors(name, ["0.4 ms", "0.2 ms", "0.1 ms", "0.05 ms"], None, fmu_cache, tmp_path)
    for key in ("windup", "energy"):
        _assert_first_order(rows, key)


def test_a_reference_too_stiff_for_its_integrator_gives_up_with_a_reason() -> None:
    """A load inertia of 1e-9 kg.m2 makes the explicit reference crawl (it ran for more than
    17 minutes in a fuzzed run): it stops at its evaluation budget and says why, which the
    run turns into a note instead of hanging."""
    from dataclasses import replace

    from orchestrator.scenes.press_feed.monolithic import simulate_feed
    from orchestrator.scenes.press_feed.report import feed_options

    scene = load_scene(SCENARIOS / "press_feed_run1.toml", {"fmus.load.parameters.j": 1e-9})
    options = replace(feed_options(scene), max_evaluations=20_000)
    with pytest.raises(RuntimeError, match=r"20000 evaluations spent by t = .* too stiff"):
        simulate_feed(options)
