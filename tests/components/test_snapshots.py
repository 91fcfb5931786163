"""Components that snapshot by sharing (an empty SnapshotPlan) hold only immutable values."""

from __future__ import annotations

import pytest

from components.base import Component, SnapshotPlan
from fmus.registry import FMU_RECORDS

#: Every FMU's component that snapshots by sharing everything (an empty plan).
SHARED = sorted(
    {
        cls
        for cls in (w.component_class for w in FMU_RECORDS.values())
        if cls.SNAPSHOT == SnapshotPlan()
    },
    key=lambda cls: cls.__name__,
)


def test_the_shared_ones_are_found() -> None:
    names = {cls.__name__ for cls in SHARED}
    assert names >= {"CrankCouplerDrive", "SpragClutch", "BrakeLoad", "DetachedLever", "Inertia"}


def immutable(value: object) -> bool:
    if isinstance(value, int | float | bool | str | bytes | type(None)):
        return True
    if isinstance(value, tuple | frozenset):
        return all(immutable(v) for v in value)
    params = getattr(type(value), "__dataclass_params__", None)
    return params is not None and params.frozen


def stepped(cls: type[Component]) -> Component:
    component = cls()
    component.initialize(0.0)
    for k in range(200):
        component.update_outputs()
        component.step(k * 1e-4, 1e-4)
    return component


@pytest.mark.parametrize("cls", SHARED, ids=lambda cls: cls.__name__)
def test_shared_snapshots_hold_only_immutable_values(cls: type[Component]) -> None:
    component = stepped(cls)
    mutable = {
        k: type(v).__name__
        for k, v in component.__dict__.items()
        if not k.startswith("_cache") and not immutable(v)
    }
    assert mutable == {}, f"{cls.__name__} would share these between snapshots: {mutable}"


@pytest.mark.parametrize("cls", SHARED, ids=lambda cls: cls.__name__)
def test_a_restored_snapshot_retakes_the_same_steps(cls: type[Component]) -> None:
    component = stepped(cls)
    state = component.get_state()
    runs = []
    for _ in range(2):
        component.set_state(state)
        for k in range(50):
            component.step(0.02 + k * 1e-4, 1e-4)
            component.update_outputs()
        runs.append({v.name: getattr(component, v.name) for v in cls.VARIABLES})
    assert runs[0] == runs[1]
