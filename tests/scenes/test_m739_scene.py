"""The M739 scene through FMUs and the regime-aware master, against the report and the
monolithic reference (Lowen & Tepper 1982, ARLCD-TR-82013)."""

from __future__ import annotations

import csv
from pathlib import Path

import pytest
from scene_run import run_file

from components.m739_data import LBF

SCENE = Path(__file__).resolve().parents[2] / "scenarios" / "m739.toml"


def run(tmp_path: Path, fmu_cache: Path, name: str, plots: bool = False, **overrides):
    return run_file(SCENE, tmp_path / name, overrides, plots=plots)


@pytest.fixture(scope="module")
def default_run(tmp_path_factory, fmu_cache):
    """The scene as written: the single pass ("auto", the verge keeps a copy of the wheel)."""
    return run(tmp_path_factory.mktemp("m739"), fmu_cache, "default", plots=True)


@pytest.fixture(scope="module")
def midpoint_run(tmp_path_factory, fmu_cache):
    """The scene under the regime-aware master's other scheme."""
    hold = {"master.input_hold": "midpoint"}
    return run(tmp_path_factory.mktemp("m739"), fmu_cache, "midpoint", plots=True, **hold)


#: The validations below hold for both schemes of the regime-aware master (the midpoint
#: hold, no longer this scene's default, in the slow suite).
BOTH = pytest.mark.parametrize(
    "scheme", ["default_run", pytest.param("midpoint_run", marks=pytest.mark.slow)]
)


@BOTH
def test_report_numbers(request, scheme) -> None:
    r = request.getfixturevalue(scheme)
    assert r.status == "completed" and r.value("armed") == 1.0
    assert r.value("turns_to_arm") == pytest.approx(25.78, rel=0.01)
    assert r.value("F23_max") / LBF == pytest.approx(3.24, rel=0.02)
    assert r.value("F12_max") / LBF == pytest.approx(11.41, rel=0.02)
    assert r.value("FF23_max") / LBF == pytest.approx(2.93, rel=0.02)
    assert r.value("FF12_max") / LBF == pytest.approx(10.94, rel=0.02)
    assert r.value("PN_max") / LBF == pytest.approx(0.66, rel=0.05)
    # Force peaks against the monolithic model's, taken at its every internal step.  The
    # FMUs' own peaks over their internal steps (PN_peak, F*_peak) do not depend on the
    # communication steps: under the single pass PN measured 4.1e-5 off (the largest
    # recorded PN alone was 2.9e-2 off).  The train's forces follow its load, which the
    # single pass ramps linearly over a step: F23 8.5e-5, F12 9.4e-5 off.
    assert r.accuracy["headline_error.PN_max"] < 1e-4
    for force in ("F23_max", "F12_max", "FF23_max", "FF12_max"):
        assert r.accuracy[f"headline_error.{force}"] < 5e-3, force
    assert abs(r.value("impacts") - 181) <= 2


@BOTH
def test_cosimulation_matches_the_monolithic_reference(request, scheme) -> None:
    r = request.getfixturevalue(scheme)
    acc = r.accuracy
    assert acc["headline_error.turns_to_arm"] < 1e-4
    assert acc["headline_error.impacts"] == 0.0
    assert acc["event_time_error"] < 1e-5
    assert acc["trajectory_error"] < 2e-4
    assert r.value("energy_residual") < 1e-3


@pytest.mark.slow
def test_the_single_pass_is_the_cheaper_at_the_same_accuracy(default_run, midpoint_run) -> None:
    # Counted, not timed: 1676 doSteps against 20448 (turns errors 2.2e-6 and 8.0e-5).
    assert default_run.stats.input_hold == "extrapolated"
    assert midpoint_run.stats.input_hold == "midpoint"
    assert default_run.stats.do_steps < 0.2 * midpoint_run.stats.do_steps


@BOTH
def test_regime_log_and_outputs(request, scheme) -> None:
    r = request.getfixturevalue(scheme)
    with open(r.output_dir / "events.csv") as f:
        events = list(csv.DictReader(f))
    transitions = {(e["from"], e["to"]) for e in events if e["subsystem"] == "verge"}
    assert ("coupled-entrance", "free") in transitions
    assert ("free", "coupled-exit") in transitions
    # Two switches per impact-to-impact half cycle: 2 x 181 plus the start and the end.
    assert 360 <= sum(e["subsystem"] == "verge" for e in events) <= 366
    assert r.stats.rollbacks > 0 and r.stats.events >= 360
    assert (r.output_dir / "m739.png").stat().st_size > 10_000
    # The run stops on the arming angle, within the event tolerance (1e-10 s) times the
    # wheel speed (below 1000 rad/s).
    overshoot = r.signal("train.phi")[-1] - 1485.0 * 3.141592653589793 / 180.0
    assert 0.0 <= overshoot < 1e-7


@pytest.mark.slow  # a second whole run of the scene
def test_a_coarse_tolerance_stays_accurate(tmp_path, fmu_cache, default_run) -> None:
    # The scene's tolerance: within the report's accuracy (measured 2e-4: turns 2.2e-6).
    # Midpoint hold at tolerance 1e-2: within the same bounds (measured: turns 8.0e-5,
    # trajectory 1.7e-4, events 4.9e-6 s; its verge takes the train's response at the step
    # start with its slopes, not the predictor's and corrector's mean).
    hold = {"master.tolerance": 1e-2, "master.input_hold": "midpoint"}
    coarse = run(tmp_path, fmu_cache, "coarse", **hold)
    for r in (coarse, default_run):
        assert r.accuracy["headline_error.turns_to_arm"] < 1e-4
        assert r.accuracy["trajectory_error"] < 2e-4
        assert r.accuracy["event_time_error"] < 1e-5
    # The single pass (the default here) at 1e-2: the turns error within the 1e-4 the speed
    # targets ask (measured 7.5e-5: steps bounded by the switches alone, the train's reduced
    # model in the verge), in fewer steps than at the scene's (630 against 765).
    single = run(tmp_path, fmu_cache, "coarse_single_pass", **{"master.tolerance": 1e-2})
    assert single.stats.input_hold == default_run.stats.input_hold
    assert single.stats.input_hold == "extrapolated"
    assert single.accuracy["headline_error.turns_to_arm"] < 1e-4
    assert single.stats.steps < default_run.stats.steps


def test_jammed_train_does_not_arm_and_says_why(tmp_path, fmu_cache) -> None:
    friction = {
        "parameters.mu": 0.3,
        "fmus.verge.parameters.mu1": 0.3,
    }
    r = run(tmp_path, fmu_cache, "jam", **friction)
    assert r.status == "completed" and r.value("armed") == 0.0
    assert "stalled: the train is held by friction" in r.headline["not_armed_reason"]["value"]


def test_too_short_a_run_does_not_arm(tmp_path, fmu_cache) -> None:
    r = run(tmp_path, fmu_cache, "short", **{"scene.stop": "2 ms"})
    assert r.status == "completed" and r.value("armed") == 0.0
    assert "stop time" in r.headline["not_armed_reason"]["value"]
