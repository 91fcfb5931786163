"""The regime-aware master on the two-inertia scene: error control and exact stopping."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from scene_run import run_file

from orchestrator.run import run_scene
from orchestrator.scenario import load_scene

SCENE = Path(__file__).resolve().parents[2] / "scenarios" / "two_inertias.toml"
STOP_AT_ONE_RADIAN = {"signal": "a.phi", "above": "1 rad"}


def run(tmp_path, fmu_cache, **overrides):
    return run_file(SCENE, tmp_path / "run", overrides)


# a convergence study over tolerances: long validation
@pytest.mark.slow
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
    assert ours.status == "completed" and ours.stats.stopped_by_condition
    assert ours.signal("a.phi")[-1] == pytest.approx(1.0, abs=1e-9)
    fixed = run(tmp_path, fmu_cache, **{"scene.stop_when": STOP_AT_ONE_RADIAN})
    assert fixed.stats.stopped_by_condition
    overshoot = fixed.signal("a.phi")[-1] - 1.0
    assert 0.0 < overshoot < 10.0 * 1e-4  # at most one step of about 10 rad/s x 0.1 ms


def test_bad_stop_condition_is_refused(tmp_path) -> None:
    from orchestrator.errors import ScenarioError

    with pytest.raises(ScenarioError, match=r"\[scene.stop_when\] expected exactly one"):
        load_scene(SCENE, {"scene.stop_when": {"signal": "a.phi"}})
    with pytest.raises(ScenarioError, match=r"stop_when.above.*cannot be converted to rad"):
        load_scene(SCENE, {"scene.stop_when": {"signal": "a.phi", "above": "1 s"}})


M739 = Path(__file__).resolve().parents[2] / "scenarios" / "m739.toml"


def _m739_first_4_ms(tmp_path, fmu_cache, zero_error_restart: float):
    # The midpoint hold's restart (the single pass restarts from the step it remembers).
    overrides = {"scene.stop": "4 ms", "master.tolerance": 1e-2, "master.input_hold": "midpoint"}
    scene = load_scene(M739, overrides)
    settings = scene.master.settings
    control = replace(settings.control, zero_error_restart=zero_error_restart)
    master = replace(scene.master, settings=replace(settings, control=control))
    return run_scene(
        replace(scene, master=master),
        output_dir=tmp_path / f"restart{zero_error_restart}",
        cache_dir=fmu_cache,
        show_progress=False,
        plots=False,
        compare_reference=False,
    )


def _first_steps_into(result, regime: str) -> list[float]:
    """The first step after each switch of the verge into ``regime``."""
    t = result.data[:, 0]
    return [
        float(t[t > te + 1e-12][0] - te)
        for te, sub, _, to in result.events
        if sub == "verge" and to == regime and np.any(t > te + 1e-12)
    ]


def test_free_flight_restarts_at_a_quarter_of_the_step_it_reached(tmp_path, fmu_cache) -> None:
    """In free flight the coupling error is small: after the first one, a switch into
    it restarts at a quarter of the step proposed there (max_step 100 µs, so 25 µs), not at
    master.step; the coupled phases, whose error is not zero, still restart at 1 µs.  The
    motion and its switches are the same."""
    ramp = _m739_first_4_ms(tmp_path, fmu_cache, 0.0)
    remembered = _m739_first_4_ms(tmp_path, fmu_cache, 0.25)
    assert _first_steps_into(ramp, "free") == pytest.approx([1e-6] * 12, rel=1e-6)
    free = _first_steps_into(remembered, "free")
    assert len(free) == 12 and free[0] == pytest.approx(1e-6, rel=1e-6)
    # Not at 1 µs; one of them may end earlier on an event of the train in free flight.
    assert min(free[1:]) > 10e-6 and max(free[1:]) == pytest.approx(25e-6, rel=1e-6), free
    assert sum(f == pytest.approx(25e-6, rel=1e-6) for f in free[1:]) >= len(free) - 2, free
    for coupled in ("coupled-entrance", "coupled-exit"):
        steps = _first_steps_into(remembered, coupled)
        assert steps and steps == pytest.approx([1e-6] * len(steps), rel=1e-6), steps
    assert [e[1:] for e in remembered.events] == [e[1:] for e in ramp.events]
    switch_times = np.array([e[0] for e in remembered.events])
    # The verge's copy of the wheel follows the train's reduced model (its response and
    # slopes at the step start), not the midpoint of the held values, so longer free-flight
    # steps move the switches by a few ns (measured: 4.9e-9 s, and 1.4e-6 in phi at 4 ms).
    assert np.max(np.abs(switch_times - [e[0] for e in ramp.events])) < 1e-8
    phi = remembered.header.index("train.phi")
    assert remembered.data[-1, phi] == pytest.approx(ramp.data[-1, phi], rel=5e-6)
    assert remembered.stats.do_steps < 0.95 * ramp.stats.do_steps


TWIN_MESHES = """
[scene]
name = "twin_meshes"
stop = "0.12 s"

[fmus.a]
component = "GearMesh"
parameters = { model = 1, mesh = 2, printed_run = 0, mu = 0.1, speed = "100 rpm" }
inputs = { load_torque = "1 lbf*in" }

[fmus.b]
component = "GearMesh"
parameters = { model = 1, mesh = 2, printed_run = 0, mu = 0.2, speed = "100 rpm" }
inputs = { load_torque = "2 lbf*in" }

[master]
algorithm = "regime-aware"
first_step = "10 us"
event_tolerance = "1e-10 s"
"""


def test_two_fmus_switching_at_one_instant_both_switch_there(tmp_path, fmu_cache) -> None:
    """Two meshes of one geometry at one speed change contact phase at the same instants:
    the master lands once on each instant and logs both switches there, none lost."""
    path = tmp_path / "twin_meshes.toml"
    path.write_text(TWIN_MESHES)
    result = run_scene(
        load_scene(path, {}),
        output_dir=tmp_path / "run",
        cache_dir=fmu_cache,
        show_progress=False,
        plots=False,
    )
    assert result.status == "completed", result.message
    by_fmu: dict[str, list[tuple[float, str, str]]] = {"a": [], "b": []}
    for t, who, old, new in result.events:
        by_fmu[who].append((t, old, new))
    assert len(by_fmu["a"]) >= 9  # three phase changes per base pitch, three pitches
    assert [(o, n) for _, o, n in by_fmu["a"]] == [(o, n) for _, o, n in by_fmu["b"]]
    for (ta, _, _), (tb, _, _) in zip(by_fmu["a"], by_fmu["b"], strict=True):
        assert ta == tb  # one landing, both logged at it


def test_the_restart_after_a_switch_remembers_per_regimes() -> None:
    """The midpoint hold remembers the largest step proposed while every step in those
    regimes had zero coupling error, the single pass the last one proposed; either restarts
    at a fraction of it, never below master.first_step."""
    from orchestrator.masters.regime_aware import RestartSteps

    zero_only = RestartSteps(1e-6, 0.25, zero_error_only=True)
    zero_only.remember((0, 1), 0.0, 8e-5)
    zero_only.remember((0, 1), 0.0, 4e-5)
    assert zero_only.step((0, 1)) == 0.25 * 8e-5
    zero_only.remember((0, 1), 0.5, 1e-4)  # an error: nothing remembered there any more
    assert zero_only.step((0, 1)) == 1e-6
    last = RestartSteps(1e-6, 0.25, zero_error_only=False)
    last.remember((2,), 0.5, 8e-5)
    last.remember((2,), 0.9, 4e-5)
    assert last.step((2,)) == 0.25 * 4e-5
    assert last.step((3,)) == 1e-6


def test_a_step_lands_on_a_switch_within_its_window() -> None:
    """An estimated switch (an indicator's secant) within the event tolerance of the step
    end; an instant an FMU reported within one instant (10 event tolerances)."""
    from orchestrator.master_settings import RegimeAwareSettings
    from orchestrator.masters.switches import Landing, Switch

    landing = Landing.of(RegimeAwareSettings(first_step=1e-6, event_tolerance=1e-10))
    assert landing.instant == 10 * 1e-10
    t, h = 0.0, 1e-3
    assert landing.lands(t, h, Switch(h - 0.5e-10, located=False))
    assert not landing.lands(t, h, Switch(h - 5e-10, located=False))
    assert landing.lands(t, h, Switch(h - 5e-10, located=True))
    assert not landing.lands(t, h, Switch(h - 2e-9, located=True))
    assert landing.lands(t, 1e-14, Switch(0.0, located=False))  # at min_step: cannot shorten
