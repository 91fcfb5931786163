"""Which FMUs exist: the name a scene uses, the wrapper script, and the component inside."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

_HERE = Path(__file__).resolve().parent


@dataclass(frozen=True)
class FmuWrapper:
    name: str  # model identifier, as a scene names it
    script: Path  # pythonfmu script with exactly one ComponentSlave subclass
    component: str  # dotted path of the component class


def _wrapper(name: str, module: str, component: str) -> FmuWrapper:
    return FmuWrapper(name, _HERE / f"{module}.py", component)


FMU_WRAPPERS: dict[str, FmuWrapper] = {
    w.name: w
    for w in (
        _wrapper("Inertia", "inertia_fmu", "components.rotational.Inertia"),
        _wrapper(
            "SpringDamperInertia",
            "spring_damper_inertia_fmu",
            "components.rotational.SpringDamperInertia",
        ),
        _wrapper("GearTrain", "gear_train_fmu", "components.gear_train.GearTrain"),
        _wrapper(
            "VergeEscapement", "verge_escapement_fmu", "components.verge_escapement.VergeEscapement"
        ),
        _wrapper(
            "CrankCouplerDrive",
            "crank_coupler_drive_fmu",
            "components.rssr_coupler.CrankCouplerDrive",
        ),
        _wrapper("SpragClutch", "sprag_clutch_fmu", "components.sprag_clutch.SpragClutch"),
        _wrapper("BrakeLoad", "brake_load_fmu", "components.brake_load.BrakeLoad"),
        _wrapper("DetachedLever", "detached_lever_fmu", "components.detached_lever.DetachedLever"),
        _wrapper("GearMesh", "gear_mesh_fmu", "components.gear_mesh.GearMesh"),
        _wrapper(
            "ClockGearTrain", "clock_gear_train_fmu", "components.clock_gear_train.ClockGearTrain"
        ),
    )
}
