"""Which FMUs exist: the name a scene uses, the wrapper script, the component inside, and
the example scenes that couple it with other FMUs (listed in its documentation)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

_HERE = Path(__file__).resolve().parent


@dataclass(frozen=True)
class FmuWrapper:
    name: str  # model identifier, as a scene names it
    script: Path  # pythonfmu script with exactly one ComponentSlave subclass
    component: str  # dotted path of the component class
    #: Scenes (paths relative to the project root) that couple this FMU with others; the
    #: FMU's documentation lists their connections.  Empty: no scene couples it.
    examples: tuple[str, ...] = ()


def _wrapper(name: str, module: str, component: str, *examples: str) -> FmuWrapper:
    return FmuWrapper(name, _HERE / f"{module}.py", component, tuple(examples))


_TWO_INERTIAS = "scenarios/two_inertias.toml"
_M739 = "scenarios/m739.toml"
_CLOCK_TRAIN = "scenarios/clock_train_sa.toml"
_PRESS_FEED = "scenarios/press_feed_run1.toml"


FMU_WRAPPERS: dict[str, FmuWrapper] = {
    w.name: w
    for w in (
        _wrapper("Inertia", "inertia_fmu", "components.rotational.Inertia", _TWO_INERTIAS),
        _wrapper(
            "SpringDamperInertia",
            "spring_damper_inertia_fmu",
            "components.rotational.SpringDamperInertia",
            _TWO_INERTIAS,
        ),
        _wrapper("GearTrain", "gear_train_fmu", "components.gear_train.GearTrain", _M739),
        _wrapper(
            "VergeEscapement",
            "verge_escapement_fmu",
            "components.verge_escapement.VergeEscapement",
            _M739,
            _CLOCK_TRAIN,
        ),
        _wrapper(
            "CrankCouplerDrive",
            "crank_coupler_drive_fmu",
            "components.rssr_coupler.CrankCouplerDrive",
            _PRESS_FEED,
        ),
        _wrapper(
            "SpragClutch", "sprag_clutch_fmu", "components.sprag_clutch.SpragClutch", _PRESS_FEED
        ),
        _wrapper("BrakeLoad", "brake_load_fmu", "components.brake_load.BrakeLoad", _PRESS_FEED),
        # The lever and mesh scenes run one FMU alone: nothing to couple.
        _wrapper("DetachedLever", "detached_lever_fmu", "components.detached_lever.DetachedLever"),
        _wrapper("GearMesh", "gear_mesh_fmu", "components.gear_mesh.GearMesh"),
        _wrapper(
            "ClockGearTrain",
            "clock_gear_train_fmu",
            "components.clock_gear_train.ClockGearTrain",
            _CLOCK_TRAIN,
        ),
    )
}
