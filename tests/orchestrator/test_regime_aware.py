"""The regime-aware master on the two-inertia scene: error control and exact stopping."""

from __future__ import annotations

from pathlib import Path

import pytest

from orchestrator.run import run_scene
from orchestrator.scenario import load_scene

SCENE = Path(__file__).resolve().parents[2] / "scenarios" / "two_inertias.toml"
STOP_AT_ONE_RADIAN = {"signal": "a.phi", "above": "1 rad"}


def run(tmp_path, fmu_cache, **overrides):
    scene = load_scene(SCENE, overrides)
    return run_scene(
        scene, output_dir=tmp_path / "run", cache_dir=fmu_cache, show_progress=False, plots=False
    )


def test_error_follows_the_tolerance_with_inputs_held_at_the_step_start(
    tmp_path, fmu_cache
) -> None:
    errors = []
    for tol in (1e-2, 1e-3):
        result = run(
            tmp_path,
            fmu_cache,
            **{
                "master.algorithm": "regime-aware",
                "master.input_hold": "start",
                "master.tolerance": tol,
                "scene.stop": "0.1 s",
            },
        )
        assert result.status == "completed"
        errors.append(result.accuracy["trajectory_error"])
        assert result.stats.rollbacks == result.stats.rejections
    # Held inputs: the error is first order in the step, and the step follows the tolerance.
    assert errors[0] / errors[1] == pytest.approx(10.0, rel=0.3), errors
    assert errors[1] < 2e-3


def test_midpoint_hold_is_second_order_in_the_step(tmp_path, fmu_cache) -> None:
    errors, steps = [], []
    for tol in (1e-3, 1e-4):
        result = run(
            tmp_path,
            fmu_cache,
            **{"master.algorithm": "regime-aware", "master.tolerance": tol, "scene.stop": "0.1 s"},
        )
        assert result.status == "completed"
        errors.append(result.accuracy["trajectory_error"])
        steps.append(result.stats.steps)
    # The predictor's error is second order in h per step: steps grow as tol^-1/2, and the
    # (corrected) error falls with the square of the step count, i.e. as the tolerance.
    assert steps[1] / steps[0] == pytest.approx(10**0.5, rel=0.2), steps
    assert errors[0] / errors[1] == pytest.approx((steps[1] / steps[0]) ** 2, rel=0.3), errors
    assert errors[1] < 5e-4


def test_stop_condition_is_landed_on_exactly(tmp_path, fmu_cache) -> None:
    ours = run(
        tmp_path,
        fmu_cache,
        **{
            "master.algorithm": "regime-aware",
            "master.tolerance": 1e-2,
            "scene.stop_when": STOP_AT_ONE_RADIAN,
        },
    )
    assert ours.status == "completed" and ours.stats.extra["stopped_by_condition"]
    assert ours.signal("a.phi")[-1] == pytest.approx(1.0, abs=1e-9)
    fixed = run(tmp_path, fmu_cache, **{"scene.stop_when": STOP_AT_ONE_RADIAN})
    assert fixed.stats.extra["stopped_by_condition"]
    overshoot = fixed.signal("a.phi")[-1] - 1.0
    assert 0.0 < overshoot < 10.0 * 1e-4  # at most one step of about 10 rad/s x 0.1 ms


def test_bad_stop_condition_is_refused(tmp_path) -> None:
    from orchestrator.errors import ScenarioError

    with pytest.raises(ScenarioError, match=r"\[scene.stop_when\] expected exactly one"):
        load_scene(SCENE, {"scene.stop_when": {"signal": "a.phi"}})
    with pytest.raises(ScenarioError, match=r"stop_when.above.*cannot be converted to rad"):
        load_scene(SCENE, {"scene.stop_when": {"signal": "a.phi", "above": "1 s"}})
