"""Which FMUs the master reads again after setting their inputs: those whose read values
may depend on them (by the FMU's declared output dependencies)."""

from __future__ import annotations

from pathlib import Path

from orchestrator.scenario import load_scene
from orchestrator.system import CoupledSystem

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"


def _dependent(scene_file: str, record: list[str] | None = None) -> list[str]:
    overrides = {"master.algorithm": "regime-aware"}
    if record is not None:
        overrides["output.record"] = record
    system = CoupledSystem(load_scene(SCENARIOS / scene_file, overrides))
    try:
        return [system.names[i] for i in system.input_dependent()]
    finally:
        system.close()


def test_an_fmu_whose_outputs_follow_its_state_is_not_read_again() -> None:
    # The crank drive's outputs follow its state; the clutch torque and the brake's
    # breakaway indicator depend on their inputs.
    assert _dependent("press_feed_run1.toml") == ["clutch", "load"]


def test_reading_an_input_makes_an_fmu_input_dependent() -> None:
    # Recording the drive's own input (the clutch torque it takes) changes with a feed.
    needed = ["drive.regime", "clutch.regime", "clutch.windup", "load.regime", "load.feed_length"]
    assert "drive" in _dependent("press_feed_run1.toml", [*needed, "drive.torque"])


def test_values_an_fmu_holds_are_not_set_again_until_a_state_is_restored() -> None:
    system = CoupledSystem(load_scene(SCENARIOS / "two_inertias.toml"))
    try:
        system.initialize()
        i = next(i for i, s in enumerate(system._set_reals) if s is not None)
        sets = []
        real_set = system._set_reals[i]
        system._set_reals[i] = lambda values: (sets.append(list(values)), real_set(values))
        state = system.get_state()
        system.feed(i, [1.5])
        system.feed(i, [1.5])  # the FMU holds 1.5: not set again
        assert sets == [[1.5]]
        system.feed(i, [2.5])
        assert sets == [[1.5], [2.5]]
        system.restore(state)  # the state's own inputs are back: set again
        system.feed(i, [2.5])
        assert sets == [[1.5], [2.5], [2.5]]
        system.free_state(state)
    finally:
        system.close()
