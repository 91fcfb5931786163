"""The regime-aware master's single-pass scheme (``master.input_hold = "extrapolated"``):
each FMU stepped once per macro step, switches landed on by early return.

Here: the cost of a landing counted in doSteps (default suite).  The press feed runs
under it with the assertions of its midpoint hold ("auto" keeps the midpoint there):
tests/scenes/test_press_feed_regime_aware.py runs each of them under both schemes.  M739
and the clock train run it by default: their scene tests (tests/scenes/test_m739_scene.py,
test_clock_gear_train.py) check both schemes, and the stability suite
(tests/orchestrator/test_stability.py) runs every case under both.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from scene_run import run_file

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
SINGLE_PASS = {"master.algorithm": "regime-aware", "master.input_hold": "extrapolated"}


def run(tmp_path: Path, fmu_cache: Path, scene: str, reference: bool = True, **overrides):
    overrides = {**SINGLE_PASS, **overrides}
    return run_file(SCENARIOS / scene, tmp_path, overrides, reference=reference, plots=reference)


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
        stats = r.stats
        assert r.status == "completed", r.message
        assert stats.landings >= 20
        assert stats.landing_pass_do_steps_max == 2
        # Passes rejected by the error test on the way included: at most 4 passes.
        assert stats.landing_do_steps_max <= 8
        assert stats.landing_do_steps <= 2.5 * stats.landings


@pytest.mark.parametrize(
    ("scene", "max_error", "max_do_steps"),
    [
        ("m739.toml", 1e-4, 2100),
        pytest.param("clock_train_sa.toml", 1e-4, 5500, marks=pytest.mark.slow),
    ],
)
def test_the_reduced_train_model_makes_steps_follow_switches_not_tolerance(
    tmp_path, fmu_cache, scene, max_error, max_do_steps
) -> None:
    """The train sends its response with its slopes in the wheel state and the verge's copy
    follows them: the copy's mismatch is so small that the passes are bounded by the
    switches.  Counted (doSteps) and against the monolithic model at tolerance 1e-10, with
    no longest step but the run (the single pass's default): M739 1334 / 2010 doSteps,
    turns error 7.5e-5 / 8.0e-7 at 1e-2 / 1e-5; the clock train 1737 / 5237 doSteps,
    8.4e-5 / 6.7e-6 (every error within its tolerance and within the 1e-4 the speed
    targets ask)."""
    from orchestrator.scenes.clock_train.monolithic import run_clock_train
    from orchestrator.scenes.m739.monolithic import run_m739

    monolithic = run_m739 if scene == "m739.toml" else run_clock_train
    truth = monolithic(tolerance=1e-10).turns
    for tol in (1e-2, 1e-5):
        r = run(tmp_path / str(tol), fmu_cache, scene, reference=False, **{"master.tolerance": tol})
        error = abs(r.value("turns_to_arm") - truth) / truth
        assert error <= min(tol, max_error), (tol, error)
        assert r.stats.do_steps <= max_do_steps, (tol, r.stats.do_steps)
