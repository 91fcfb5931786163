"""Which FMUs exist: the name a scene uses, the wrapper script, the component inside, and
the example scenes that couple it with other FMUs (listed in its documentation)."""

from __future__ import annotations

import ast
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

_HERE = Path(__file__).resolve().parent


@dataclass(frozen=True)
class FmuWrapper:
    name: str  # model identifier, as a scene names it
    script: Path  # pythonfmu script with exactly one ComponentSlave subclass
    #: Scenes (paths relative to the project root) that couple this FMU with others; the
    #: FMU's documentation lists their connections.  Empty: no scene couples it.
    examples: tuple[str, ...] = ()

    @cached_property
    def component(self) -> str:
        """Dotted path of the component class, as the wrapper script names it (its
        ``component = "module.Class"`` inside the ``components`` package)."""
        for node in ast.walk(ast.parse(self.script.read_text())):
            if (
                isinstance(node, ast.Assign)
                and [getattr(t, "id", None) for t in node.targets] == ["component"]
                and isinstance(node.value, ast.Constant)
            ):
                return f"components.{node.value.value}"
        raise ValueError(f"{self.script} names no component (component = 'module.Class')")


def _wrapper(name: str, module: str, *examples: str) -> FmuWrapper:
    return FmuWrapper(name, _HERE / f"{module}.py", tuple(examples))


_TWO_INERTIAS = "scenarios/two_inertias.toml"
_M739 = "scenarios/m739.toml"
_CLOCK_TRAIN = "scenarios/clock_train_sa.toml"
_PRESS_FEED = "scenarios/press_feed_run1.toml"


FMU_WRAPPERS: dict[str, FmuWrapper] = {
    w.name: w
    for w in (
        _wrapper("Inertia", "inertia_fmu", _TWO_INERTIAS),
        _wrapper(
            "SpringDamperInertia",
            "spring_damper_inertia_fmu",
            _TWO_INERTIAS,
        ),
        _wrapper("GearTrain", "gear_train_fmu", _M739),
        _wrapper(
            "VergeEscapement",
            "verge_escapement_fmu",
            _M739,
            _CLOCK_TRAIN,
        ),
        _wrapper(
            "CrankCouplerDrive",
            "crank_coupler_drive_fmu",
            _PRESS_FEED,
        ),
        _wrapper("SpragClutch", "sprag_clutch_fmu", _PRESS_FEED),
        _wrapper("BrakeLoad", "brake_load_fmu", _PRESS_FEED),
        # The lever and mesh scenes run one FMU alone: nothing to couple.
        _wrapper("DetachedLever", "detached_lever_fmu"),
        _wrapper("GearMesh", "gear_mesh_fmu"),
        _wrapper(
            "ClockGearTrain",
            "clock_gear_train_fmu",
            _CLOCK_TRAIN,
        ),
    )
}
