"""What the master exchanges with the FMUs, and what it spares: it reads again after a feed
only the FMUs whose read values may depend on their inputs, does not set values an FMU
holds, and asks the FMUs for an integration tolerance where its scheme controls the
coupling error (the single pass)."""

from __future__ import annotations

from pathlib import Path

import pytest

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


def test_the_single_pass_asks_its_fmus_for_a_tolerance_below_its_own() -> None:
    """The master's setup sets the tolerance the FMUs are initialized with ("auto" resolved
    by the factory, once)."""
    from orchestrator.masters.registry import algorithm

    def asked_of(scene) -> float | None:
        system = CoupledSystem(scene)
        try:
            algorithm(scene.master.algorithm).make(scene.master.settings, system).setup()
            return system.tolerance
        finally:
            system.close()

    asked = {}
    for hold in ("auto", "extrapolated", "midpoint"):
        for tol in (1e-1, 1e-5):
            overrides = {"master.input_hold": hold, "master.tolerance": tol}
            asked[hold, tol] = asked_of(load_scene(SCENARIOS / "m739.toml", overrides))
    assert asked["auto", 1e-1] == asked["extrapolated", 1e-1] == 1e-5  # at most 1e-5
    assert asked["auto", 1e-5] == pytest.approx(1e-6)  # a tenth of its own below that
    assert asked["midpoint", 1e-1] is None and asked["midpoint", 1e-5] is None
    assert asked_of(load_scene(SCENARIOS / "m739.toml", {"master.algorithm": "jacobi"})) is None


def test_a_hosts_tolerance_is_the_fmus_unless_the_parameter_is_set() -> None:
    scene = load_scene(SCENARIOS / "m739.toml")
    for given, expected in (({}, 3e-6), ({"tolerance": 1e-9}, 1e-9)):
        system = CoupledSystem(scene)
        try:
            verge = system.instance("verge")
            verge.initialize(scene.start, scene.stop, given, tolerance=3e-6)
            assert verge.get("tolerance") == expected
        finally:
            system.close()
    system = CoupledSystem(scene)
    try:
        train = system.instance("train")
        train.initialize(scene.start, scene.stop, {}, tolerance=None)
        assert train.get("tolerance") == 1e-8  # the FMU's own default
    finally:
        system.close()


def _counting_gets(system: CoupledSystem) -> list[tuple[int, str]]:
    """Wrap every prepared get of ``system``: the list of (instance, kind) read."""
    gets: list[tuple[int, str]] = []
    for kind, getters in (("real", system._get_reals), ("int", system._get_ints)):
        for i, get in enumerate(getters):
            if get is not None:
                getters[i] = lambda get=get, i=i, kind=kind: (gets.append((i, kind)), get())[1]
    return gets


def test_an_exchange_reads_again_only_what_a_call_since_may_have_changed() -> None:
    system = CoupledSystem(load_scene(SCENARIOS / "m739.toml"))
    try:
        system.initialize()
        verge, train = system.index["verge"], system.index["train"]
        gets = _counting_gets(system)
        system.exchange()  # everything read after the last feed: nothing to read again
        assert gets == []
        system.step(train, 0.0, 1e-6)
        system.read(train)
        del gets[:]
        system.exchange()
        # The verge was given the train's new state: its Reals depend on it, its regime
        # and impact count (its own state) do not; the train was set nothing new.
        assert gets == [(verge, "real")]
        after = [list(v) for v in system.values], [list(v) for v in system.ints]
        system.read_all()  # a full read gives the very same values
        assert ([list(v) for v in system.values], [list(v) for v in system.ints]) == after
        system.step(verge, 0.0, 1e-6)  # stepped, not read: an exchange reads it whole
        del gets[:]
        system.exchange()
        assert (verge, "real") in gets and (verge, "int") in gets
    finally:
        system.close()
