"""Master settings: one typed dataclass per master, read from a scene's [master] table."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from orchestrator.errors import ScenarioError
from orchestrator.lazy import resolve
from orchestrator.master_settings import (
    FixedStepSettings,
    MasterStepControl,
    RegimeAwareSettings,
    SinglePassControl,
)
from orchestrator.masters.registry import ALGORITHMS, setting_kinds, tolerance_masters
from orchestrator.scenario import load_scene

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
TWO = SCENARIOS / "two_inertias.toml"


def test_every_master_has_settings_and_every_key_is_a_field() -> None:
    assert set(ALGORITHMS) == {"jacobi", "gauss-seidel", "regime-aware"}
    for entry in ALGORITHMS.values():  # every factory can be imported
        assert callable(resolve(entry.factory))
    assert tolerance_masters() == ("regime-aware",)
    fields = {f.name for a in ALGORITHMS.values() for f in dataclasses.fields(a.settings)}
    kinds = setting_kinds()
    assert set(kinds) <= fields
    assert kinds["input_hold"].choices == ("auto", "start", "midpoint", "extrapolated")
    assert kinds["max_iterations"].is_count
    assert kinds["event_tolerance"].unit == "s"


def test_scene_settings_are_typed_with_defaults_filled_in() -> None:
    scene = load_scene(TWO, {"master.algorithm": "regime-aware", "master.tolerance": 1e-3})
    s = scene.master.settings
    assert isinstance(s, RegimeAwareSettings)
    assert s.tolerance == 1e-3
    assert s.event_tolerance == 1e-10 and s.min_step == 1e-14
    assert s.first_step == scene.master.step
    assert s.max_step is None  # the scheme's own: the midpoint hold's 100 first steps
    assert s.longest_step == min(100.0 * scene.master.step, scene.stop - scene.start)
    assert s.input_hold == "auto" and s.control == MasterStepControl()
    # A setting another master uses is accepted and ignored.
    jacobi = load_scene(TWO, {"master.algorithm": "jacobi", "master.tolerance": 1e-3})
    assert jacobi.master.settings == FixedStepSettings(jacobi.master.step)


def test_step_control_factors() -> None:
    c = MasterStepControl()
    assert c.grow(0.0, False) == c.max_growth
    assert c.grow(1e-9, True) == c.max_growth
    assert c.shrink(1e9, False) == c.max_shrink
    assert c.grow(0.8, False) == pytest.approx(1.0)
    assert c.shrink(0.9 * 2.0, True) == pytest.approx(0.5)
    # The single pass grows its steps a safety factor less than the estimate allows.
    assert c.grow(0.8, False, safety=0.8) == pytest.approx(0.8)
    assert c.grow(0.0, False, safety=0.8) == c.max_growth


def test_the_single_pass_asks_its_fmus_for_a_tenth_of_its_tolerance_at_most_1e_5() -> None:
    c = SinglePassControl()
    assert c.fmu_tolerance(1e-5) == pytest.approx(1e-6, rel=1e-15)
    assert c.fmu_tolerance(2e-4) == 1e-5


@pytest.mark.parametrize(
    ("overrides", "key", "fragment"),
    [
        ({"master.input_hold": "end"}, "master.input_hold", "expected one of"),
        ({"master.max_iterations": 0}, "master.max_iterations", "positive integer"),
        ({"master.tolerance": -1.0}, "master.tolerance", "must be positive"),
        (
            {"master.min_step": "1 ms", "master.max_step": "1 us"},
            "master.max_step",
            "less than master.min_step",
        ),
    ],
)
def test_bad_settings_name_the_key(overrides: dict, key: str, fragment: str) -> None:
    with pytest.raises(ScenarioError) as info:
        load_scene(TWO, {"master.algorithm": "regime-aware", **overrides})
    assert f"[{key}]" in str(info.value) and fragment in str(info.value)


M739 = SCENARIOS / "m739.toml"


def test_each_master_reads_its_own_step_key() -> None:
    """master.step is the fixed-step masters' macro step, master.first_step the
    regime-aware master's first step; a scene that gives only one lends it to the other."""
    m739 = load_scene(M739)  # regime-aware, first_step = "1 us"
    assert m739.master.settings.first_step == 1e-6 and m739.master.step == 1e-6
    jacobi = load_scene(M739, {"master.algorithm": "jacobi"})
    assert jacobi.master.settings == FixedStepSettings(1e-6)
    both = {"master.step": 5e-6}
    assert load_scene(M739, both).master.settings.first_step == 1e-6
    assert load_scene(M739, both).master.step == 5e-6
    assert load_scene(M739, {**both, "master.algorithm": "jacobi"}).master.settings.step == 5e-6
    two = load_scene(TWO, {"master.algorithm": "regime-aware"})  # jacobi, step = "0.1 ms"
    assert two.master.settings.first_step == two.master.step == 1e-4


@pytest.mark.parametrize(
    ("overrides", "key", "fragment"),
    [
        ({"master.first_step": "-1 us"}, "master.first_step", "must be positive"),
        ({"master.first_step": "1 s"}, "master.first_step", "longer than the run"),
        ({"master.step": "0 s"}, "master.step", "must be positive"),
    ],
)
def test_bad_steps_name_their_key(overrides: dict, key: str, fragment: str) -> None:
    with pytest.raises(ScenarioError) as info:
        load_scene(M739, overrides)
    assert f"[{key}]" in str(info.value) and fragment in str(info.value)


def test_a_missing_step_names_the_masters_own_key(tmp_path: Path) -> None:
    text = M739.read_text().replace('first_step = "1 us"\n', "")
    path = tmp_path / "m739.toml"
    path.write_text(text)
    with pytest.raises(ScenarioError, match=r"\[master\.first_step\] missing; expected the first"):
        load_scene(path)


def test_auto_input_hold_picks_the_single_pass_where_a_copy_judges_the_coupling(
    tmp_path, fmu_cache
) -> None:
    """``input_hold = "auto"`` (the default): the single pass for M739 (the verge reports its
    copy of the escape wheel), the midpoint hold for two black-box inertias."""
    from orchestrator.run import run_scene

    chosen = {}
    for name, path, stop in (("m739", SCENARIOS / "m739.toml", "0.5 ms"), ("two", TWO, "0.01 s")):
        overrides = {"master.algorithm": "regime-aware", "scene.stop": stop}
        scene = load_scene(path, overrides)
        assert scene.master.settings.input_hold == "auto"
        r = run_scene(
            scene,
            output_dir=tmp_path / name,
            cache_dir=fmu_cache,
            show_progress=False,
            plots=False,
            compare_reference=False,
        )
        chosen[name] = r.stats.input_hold
        assert r.metadata["master_ran"]["input_hold"] == r.stats.input_hold
    assert chosen == {"m739": "extrapolated", "two": "midpoint"}


@pytest.mark.parametrize(
    ("overrides", "longest"),
    [
        ({}, 0.2),  # the single pass: the run (scene.stop 0.2 s)
        ({"master.max_step": "50 us"}, 50e-6),  # the scene's own wins
        ({"master.input_hold": "midpoint"}, 100e-6),  # the midpoint hold: 100 first steps
    ],
)
def test_the_single_pass_takes_no_longest_step_of_its_own(overrides: dict, longest: float) -> None:
    from orchestrator.masters.regime_aware_choice import regime_aware
    from orchestrator.system import CoupledSystem

    scene = load_scene(M739, overrides)
    system = CoupledSystem(scene)
    try:
        master = regime_aware(scene.master.settings, system)
        assert master.settings.longest_step == pytest.approx(longest, rel=1e-12)
    finally:
        system.close()


def test_error_scales_start_at_the_declared_nominals() -> None:
    """The press feed's drive and load declare 1 rad and 1 rad/s: the midpoint hold's
    relative error measures start there, not at zero (the load starts at rest)."""
    from orchestrator.masters.regime_aware_choice import regime_aware
    from orchestrator.system import CoupledSystem

    scene = load_scene(SCENARIOS / "press_feed_run1.toml", {"master.algorithm": "regime-aware"})
    system = CoupledSystem(scene)
    try:
        master = regime_aware(scene.master.settings, system)
        master.setup()
        system.initialize()
        master.start(scene.start, scene.stop)
        scales = {
            (system.names[i], system.real_names[i][k]): v
            for (i, k), v in master.scheme.held.out_scale.items()
        }
        assert scales == {
            ("drive", "angle"): 1.0,
            ("drive", "speed"): 1.0,
            ("load", "angle"): 1.0,
            ("load", "speed"): 1.0,
            ("clutch", "torque"): 0.0,  # declares none
        }
    finally:
        system.close()


@pytest.mark.parametrize(("hold", "ramped"), [("midpoint", {"drive", "load"}), ("start", set())])
def test_the_midpoint_hold_ramps_the_inputs_whose_receivers_take_a_rate(
    hold: str, ramped: set
) -> None:
    """The press feed's drive and load take ``torque_rate``: the midpoint corrector ramps
    their clutch torque; the start hold (and every other master) leaves it held."""
    from orchestrator.masters.regime_aware_choice import regime_aware
    from orchestrator.system import CoupledSystem

    overrides = {"master.algorithm": "regime-aware", "master.input_hold": hold}
    scene = load_scene(SCENARIOS / "press_feed_run1.toml", overrides)
    system = CoupledSystem(scene)
    try:
        master = regime_aware(scene.master.settings, system)
        master.setup()
        system.initialize()
        master.start(scene.start, scene.stop)
        ramps = master.scheme.ramps
        assert {system.names[j] for j, _, _ in ramps} == ramped
        for j, k, _ in ramps:
            (source, slot), averaged, _, interpolated = master.scheme.held.inputs[j][k]
            assert averaged and system.real_names[source][slot] == "torque"
            # our FMUs take it through torque_rate, not fmi2SetRealInputDerivatives
            assert not interpolated and master.scheme.slopes == []
    finally:
        system.close()
