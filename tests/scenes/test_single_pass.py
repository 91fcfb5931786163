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
from collections import defaultdict
from pathlib import Path

import pytest

from components.m739_data import LBF
from orchestrator.run import RunResult, run_scene
from orchestrator.scenario import load_scene
from orchestrator.scenes.press_feed.report import (
    FEED,
    OVERRUN,
    UNWIND,
    WINDUP,
    feed_scene,
    run_regime_sequences,
)
from orchestrator.studies.stability import run_suite

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
SINGLE_PASS = {"master.algorithm": "regime-aware", "master.input_hold": "extrapolated"}
#: The press feed's regime-aware settings in tests/scenes/test_press_feed_regime_aware.py.
PRESS_FEED = {"master.first_step": "1 us", "master.tolerance": 1e-3}


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


@pytest.fixture(scope="module")
def press(fmu_cache, tmp_path_factory):
    """Press feed runs (and their references) under the single pass at the settings of
    tests/scenes/test_press_feed_regime_aware.py, each run once."""
    done: dict[str, RunResult] = {}

    def get(name: str) -> RunResult:
        if name not in done:
            scene = load_scene(SCENARIOS / name, {**SINGLE_PASS, **PRESS_FEED})
            out = tmp_path_factory.mktemp(scene.name)
            result = run_scene(scene, out, cache_dir=fmu_cache, show_progress=False, plots=False)
            assert result.reference is not None, result.notes
            done[name] = result
        return done[name]

    return get


def _grouped(events) -> dict[tuple[str, str, str], list[float]]:
    groups: dict[tuple[str, str, str], list[float]] = defaultdict(list)
    for t, *key in events:
        groups[tuple(key)].append(t)
    return groups


# The assertions of tests/scenes/test_press_feed_regime_aware.py, under the single pass.
@pytest.mark.slow
def test_press_feed_run1_switches_are_located(press):
    r = press("press_feed_run1.toml")
    ref = r.reference
    assert r.status == "completed", r.message
    run_events, ref_events = _grouped(r.events), _grouped(ref.events)
    assert sorted(run_events) == sorted(ref_events)
    assert {k: len(v) for k, v in run_events.items()} == {k: len(v) for k, v in ref_events.items()}
    assert r.accuracy["event_time_error"] < 1e-4
    assert r.stats.events >= len(ref.events)


@pytest.mark.slow
def test_press_feed_run1_against_the_reference(press):
    r = press("press_feed_run1.toml")
    acc = r.accuracy
    assert acc["headline_error.feed_length_mean"] < 2e-4
    assert acc["headline_error.mean_windup_feed"] < 1e-3
    assert acc["headline_error.peak_windup"] < 1e-3
    assert acc["trajectory_error"] < 5e-3
    assert r.value("energy_residual") < 1e-3


@pytest.mark.slow
def test_press_feed_run1_four_regimes_in_every_cycle(press):
    r = press("press_feed_run1.toml")
    for seq in run_regime_sequences(r.scene, r.header, r.data):
        assert set(seq) == {WINDUP, FEED, UNWIND, OVERRUN}, seq
        assert seq[-1] == OVERRUN


@pytest.mark.slow
def test_press_feed_run2_finds_the_grazing_disengagements(press):
    r = press("press_feed_run2.toml")
    ref = r.reference
    assert r.status == "completed", r.message
    assert ref.headline["disengagements"] == 2.0
    assert r.value("disengagements") == ref.headline["disengagements"]
    run_events, ref_events = _grouped(r.events), _grouped(ref.events)
    assert {k: len(v) for k, v in run_events.items()} == {k: len(v) for k, v in ref_events.items()}
    for key, ref_times in ref_events.items():
        errors = [abs(a - b) for a, b in zip(run_events[key], ref_times, strict=True)]
        if key == ("clutch", "engaged", "overrun"):
            assert max(errors) < 1e-3, errors
            assert min(errors) < 1e-4, errors
        else:
            assert max(errors) < 1e-4, (key, errors)


@pytest.mark.slow
def test_press_feed_run2_feed_still_ends_in_the_thesis_regimes(press):
    r = press("press_feed_run2.toml")
    ref = r.reference
    assert r.accuracy["headline_error.feed_length_mean"] < 1e-3
    k_sp = feed_scene(r.scene).p_clutch["k"]
    t_b = feed_scene(r.scene).p_load["brake_torque"]
    assert r.value("mean_windup_feed") < (t_b / k_sp) ** (2.0 / 3.0)
    assert math.isclose(r.value("mean_windup_feed"), ref.headline["mean_windup_feed"], rel_tol=3e-3)
    seqs = run_regime_sequences(r.scene, r.header, r.data)
    assert any(seq.count(FEED) > 1 for seq in seqs), seqs


@pytest.mark.slow
def test_press_feed_run3_against_its_reference(press):
    # Run 3 has no regime-aware test of its own: the bounds of Run 1's.
    r = press("press_feed_run3.toml")
    assert r.status == "completed", r.message
    acc = r.accuracy
    assert acc["trajectory_error"] < 5e-3
    assert acc["event_time_error"] < 1e-4
    assert r.value("energy_residual") < 1e-3


STABLE = (
    "m739_friction_zero",
    "m739_jam",
    "m739_pallet_inertia_div100",
    "m739_pallet_inertia_x100",
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
