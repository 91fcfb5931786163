"""The regime-aware master's single-pass scheme (``master.input_hold = "extrapolated"``):
each FMU stepped once per macro step, switches landed on by early return.

The validations of the midpoint-hold master, with the same assertions, on M739, the clock
train, press feed Runs 1-3 and the stability suite (slow), and the cost of a landing
counted in doSteps (default suite).  The single-pass scheme's tolerance means accuracy
(M739 turns error 6.1e-4 at 1e-2, 2.1e-4 at 1e-3, 5.8e-5 at 2e-4, measured): the scenes
run at the tolerance that meets their stated error.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import pytest

from components.m739_data import LBF
from orchestrator.run import run_scene
from orchestrator.scenario import load_scene
from orchestrator.studies.stability import run_suite

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
SINGLE_PASS = {"master.algorithm": "regime-aware", "master.input_hold": "extrapolated"}


def run(tmp_path: Path, fmu_cache: Path, scene: str, reference: bool = True, **overrides):
    loaded = load_scene(SCENARIOS / scene, {**SINGLE_PASS, **overrides})
    return run_scene(
        loaded,
        output_dir=tmp_path,
        cache_dir=fmu_cache,
        show_progress=False,
        compare_reference=reference,
        plots=reference,
    )


def test_a_switch_costs_one_doStep_of_each_fmu(tmp_path, fmu_cache) -> None:
    # The first 4 ms of M739: 24 verge switches (impacts, separations).  The verge ends
    # its step at its event and the train is stepped once, to that instant: the pass that
    # lands on a switch takes one doStep of each FMU, nothing is retaken to land (the
    # midpoint-hold master took 10-25 doSteps a switch).  Counted at two tolerances.
    for tol in (1e-2, 2e-4):
        r = run(
            tmp_path / str(tol),
            fmu_cache,
            "m739.toml",
            reference=False,
            **{"master.tolerance": tol, "scene.stop": "4 ms"},
        )
        extra = r.stats.extra
        assert r.status == "completed", r.message
        assert extra["landings"] >= 20
        assert extra["landing_pass_do_steps_max"] == 2
        # Passes rejected by the error test on the way included: at most 4 passes.
        assert extra["landing_do_steps_max"] <= 8
        assert extra["landing_do_steps"] <= 2.5 * extra["landings"]


@pytest.fixture(scope="module")
def m739(tmp_path_factory, fmu_cache):
    return run(
        tmp_path_factory.mktemp("m739"), fmu_cache, "m739.toml", **{"master.tolerance": 2e-4}
    )


@pytest.mark.slow
def test_m739_report_numbers(m739) -> None:
    r = m739
    assert r.status == "completed" and r.value("armed") == 1.0
    assert r.value("turns_to_arm") == pytest.approx(25.78, rel=0.01)
    assert r.value("F23_max") / LBF == pytest.approx(3.24, rel=0.02)
    assert r.value("F12_max") / LBF == pytest.approx(11.41, rel=0.02)
    assert r.value("FF23_max") / LBF == pytest.approx(2.93, rel=0.02)
    assert r.value("FF12_max") / LBF == pytest.approx(10.94, rel=0.02)
    assert r.value("PN_max") / LBF == pytest.approx(0.66, rel=0.05)
    assert abs(r.value("impacts") - 181) <= 2


@pytest.mark.slow
def test_m739_matches_the_monolithic_reference(m739) -> None:
    acc = m739.accuracy
    assert acc["headline_error.turns_to_arm"] < 1e-4
    assert acc["headline_error.impacts"] == 0.0
    assert acc["event_time_error"] < 1e-5
    assert acc["trajectory_error"] < 2e-4
    assert m739.value("energy_residual") < 1e-3


@pytest.mark.slow
def test_m739_regime_log(m739) -> None:
    with open(m739.output_dir / "events.csv") as f:
        events = list(csv.DictReader(f))
    transitions = {(e["from"], e["to"]) for e in events if e["subsystem"] == "verge"}
    assert ("coupled-entrance", "free") in transitions
    assert ("free", "coupled-exit") in transitions
    assert 360 <= sum(e["subsystem"] == "verge" for e in events) <= 366
    overshoot = m739.signal("train.phi")[-1] - 1485.0 * math.pi / 180.0
    assert 0.0 <= overshoot < 1e-7


@pytest.mark.slow
def test_m739_cheaper_than_the_midpoint_hold_at_the_same_accuracy(m739) -> None:
    # Counted, not timed: the midpoint-hold master takes 15877 doSteps at its scene
    # tolerance (5e-4, turns error 1.4e-5) and 12384 at 1e-2 (6.9e-7).
    assert m739.stats.do_steps < 12384


@pytest.mark.slow
def test_clock_train_matches_the_monolithic_reference(tmp_path, fmu_cache) -> None:
    r = run(tmp_path, fmu_cache, "clock_train_sa.toml")
    assert r.status == "completed" and r.value("armed") == 1.0
    acc = r.accuracy
    assert acc["headline_error.turns_to_arm"] < 1e-3
    assert acc["headline_error.impacts"] == 0.0
    assert r.value("energy_residual") < 1e-4
    assert r.value("turns_to_arm") == pytest.approx(25.92, rel=0.1)


@pytest.mark.slow
@pytest.mark.parametrize(
    "scene", ["press_feed_run1.toml", "press_feed_run2.toml", "press_feed_run3.toml"]
)
def test_press_feed_against_its_reference(tmp_path, fmu_cache, scene) -> None:
    # The stated bounds of the midpoint-hold master at 1e-3 (tests/scenes/
    # test_press_feed_regime_aware.py): event times 1e-4 s (Run 2's grazing
    # disengagement 1 ms), trajectory 5e-3, energy residual 1e-3.
    r = run(tmp_path, fmu_cache, scene, **{"master.step": "1 us", "master.tolerance": 1e-3})
    assert r.status == "completed", r.message
    acc = r.accuracy
    assert acc["trajectory_error"] < 5e-3
    assert acc["event_time_error"] < (1e-3 if "run2" in scene else 1e-4)
    assert r.value("energy_residual") < 1e-3


#: Not yet under the single-pass scheme: with the verge 100 times heavier the wheel stops
#: and restarts every cycle, and at one stop (t = 0.0173 s) the verge's copy of the wheel
#: and the train start differently, a mismatch no shorter step removes: the run ends in
#: "chattering" (50 jumps within 1 ns).  The midpoint-hold master passes it.
NOT_YET = pytest.mark.xfail(
    reason="single pass: wheel stop of the heavy verge ends in chattering", strict=True
)
STABLE = (
    "m739_friction_zero",
    "m739_jam",
    "m739_pallet_inertia_div100",
    pytest.param("m739_pallet_inertia_x100", marks=NOT_YET),
    "m739_spin_x4",
    "press_feed_brake_below_min",
    "press_feed_brake_near_min",
    "press_feed_coupler_x100",
    "press_feed_hertz_clutch",
    "two_inertias_huge_step",
)


@pytest.fixture(scope="module")
def stability(tmp_path_factory, fmu_cache):
    import os

    os.environ["MECHCOSIM_FMU_CACHE"] = str(fmu_cache)
    rows = run_suite(
        out_dir=tmp_path_factory.mktemp("stability"),
        masters=("regime-aware",),
        workers=2,
        overrides={"master.input_hold": "extrapolated"},
    )
    return {r.case: r for r in rows}


@pytest.mark.slow
@pytest.mark.parametrize("case", STABLE)
def test_stability_case_within_its_stated_error(stability, case) -> None:
    row = stability[case]
    assert row.status == "completed", row.diagnosis
    assert row.stable, row.diagnosis
