"""Variable declarations of every FMU component: parameter ranges and direct feedthrough.

Ranges: each parameter's start value, and every value a scenario under ``scenarios/`` sets
(parameters, ``[sweep]`` values and ``[[sweep.series]]`` overrides), lies within its
[min, max].

Feedthrough: in a few states reached by initializing and stepping, each input is perturbed
and ``update_outputs`` recomputed (no step).  An output that changes must list the input in
``depends_on``; each declared dependency must be seen to act in at least one of the states.
Some dependencies act only in one regime (a train at rest, where the load decides start,
direction or stick; a verge in contact; a clutch engaged), so each component's states are
chosen to include those regimes.
"""

from __future__ import annotations

import tomllib
from collections.abc import Callable, Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest

from components.base import Component, Variable
from components.detached_lever_design import symmetric_friction
from fmus.registry import FMU_RECORDS
from orchestrator.units import to_si

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
COMPONENTS = sorted(FMU_RECORDS)


def component_class(name: str) -> type[Component]:
    return FMU_RECORDS[name].component_class


def within(var: Variable, value: float) -> bool:
    return (var.min is None or value >= var.min) and (var.max is None or value <= var.max)


def bounds(var: Variable) -> str:
    lo = "-inf" if var.min is None else f"{var.min:.9g}"
    hi = "inf" if var.max is None else f"{var.max:.9g}"
    return f"[{lo}, {hi}] {var.unit}"


# ---------------------------------------------------------------------------------------
# Ranges
# ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", COMPONENTS)
def test_declarations_are_well_formed(name: str) -> None:
    cls = component_class(name)
    inputs = {v.name for v in cls.variables("input")}
    for var in cls.VARIABLES:
        if var.causality != "parameter":
            assert var.min is None and var.max is None, f"{name}.{var.name}: range on non-parameter"
        if var.min is not None and var.max is not None:
            assert var.min < var.max, f"{name}.{var.name}: empty range {bounds(var)}"
        if var.type == "Integer":
            for b in (var.min, var.max):
                assert b is None or b == int(b), f"{name}.{var.name}: bound {b} not an integer"
        if var.causality != "output":
            assert var.depends_on == (), f"{name}.{var.name}: depends_on on a non-output"
        assert len(set(var.depends_on)) == len(var.depends_on), f"{name}.{var.name}: repeats"
        unknown = set(var.depends_on) - inputs
        assert not unknown, f"{name}.{var.name} depends on {sorted(unknown)}: not inputs"


@pytest.mark.parametrize("name", COMPONENTS)
def test_parameter_start_values_lie_within_range(name: str) -> None:
    cls = component_class(name)
    outside = [
        f"{v.name} = {v.start!r} outside {bounds(v)}"
        for v in cls.variables("parameter")
        if not within(v, v.start)
    ]
    assert not outside, f"{name}: " + "; ".join(outside)


def scenario_parameter_values() -> Iterator[tuple[str, str, str, Any]]:
    """(where, component, parameter, value as written) for every parameter value that a
    scenario sets: the fmus tables, the sweep values and the sweep series overrides."""
    for path in sorted(SCENARIOS.rglob("*.toml")):
        raw = tomllib.loads(path.read_text())
        rel = path.relative_to(SCENARIOS).as_posix()
        fmus = raw.get("fmus", {})
        component = {inst: table["component"] for inst, table in fmus.items()}
        for inst, table in fmus.items():
            for pname, value in table.get("parameters", {}).items():
                yield f"{rel}:fmus.{inst}.parameters.{pname}", component[inst], pname, value

        def takers(pname: str, component: dict[str, str] = component) -> list[str]:
            """The components a shared [parameters] value reaches."""
            return [
                c
                for c in component.values()
                if pname in {v.name for v in component_class(c).variables("parameter")}
            ]

        for pname, value in raw.get("parameters", {}).items():
            for c in takers(pname):
                yield f"{rel}:parameters.{pname}", c, pname, value
        sweep = raw.get("sweep")
        if not sweep:
            continue
        keyed = [(f"{rel}:sweep.values", sweep["parameter"], v) for v in sweep.get("values", [])]
        for i, series in enumerate(sweep.get("series", [])):
            for key, value in series.get("set", {}).items():
                keyed.append((f"{rel}:sweep.series[{i}]", key, value))
        for where, key, value in keyed:
            parts = key.split(".")
            if len(parts) == 4 and parts[0] == "fmus" and parts[2] == "parameters":
                yield f"{where}:{key}", component[parts[1]], parts[3], value
            elif len(parts) == 2 and parts[0] == "parameters":
                for c in takers(parts[1]):
                    yield f"{where}:{key}", c, parts[1], value


SCENARIO_VALUES = list(scenario_parameter_values())


def test_scenario_values_were_found() -> None:
    # The sweeps as well as the fmus tables: a parser that lost either would pass vacuously.
    wheres = [w for w, *_ in SCENARIO_VALUES]
    assert any(":sweep.values:" in w for w in wheres)
    assert any(":sweep.series[" in w for w in wheres)
    assert {c for _, c, _, _ in SCENARIO_VALUES} <= set(FMU_RECORDS)


@pytest.mark.parametrize(
    ("component", "parameter", "value"),
    [pytest.param(c, p, v, id=w) for w, c, p, v in SCENARIO_VALUES],
)
def test_scenario_values_lie_within_range(component: str, parameter: str, value: Any) -> None:
    var = component_class(component).variable(parameter)
    assert var.causality == "parameter"
    si = to_si(value, var.unit)
    assert within(var, si), f"{value!r} = {si:.9g} {var.unit} outside {bounds(var)}"


# ---------------------------------------------------------------------------------------
# Feedthrough
# ---------------------------------------------------------------------------------------
def initialized(cls: type[Component], inputs: dict[str, float] | None = None, **params: float):
    c = cls(**params)
    for k, v in (inputs or {}).items():
        setattr(c, k, v)
    c.initialize(0.0)
    return c


def stepped(c: Component, n: int, h: float) -> Component:
    for k in range(n):
        c.step(k * h, h)
    return c


def with_inputs(c: Component, **inputs: float) -> Component:
    """The component with inputs set and taken in (update_outputs), as a master leaves it."""
    for k, v in inputs.items():
        setattr(c, k, v)
    c.update_outputs()
    return c


def copy_of(c: Component) -> Component:
    other = type(c).__new__(type(c))
    other.set_state(c.get_state())
    return other


def stuck_load(cls: type[Component]) -> float:
    """A held T_esc inside the static-friction band of a train at rest at its start."""
    c = initialized(cls)
    snap = c.get_state()

    def direction(t_esc: float) -> int:
        c.set_state(snap)
        with_inputs(c, T_esc=t_esc)
        return (c.phi_ddot > 0.0) - (c.phi_ddot < 0.0)

    def edge(moving: int, inside: float, outside: float) -> float:
        """Bisect to the end of a motion: direction(outside) == moving, inside it is not."""
        for _ in range(60):
            mid = 0.5 * (inside + outside)
            inside, outside = (inside, mid) if direction(mid) == moving else (mid, outside)
        return inside

    assert direction(0.0) == 1 and direction(-1.0) == -1  # spin drives; a big load wins
    upper = edge(1, -1.0, 0.0)
    lower = edge(-1, upper, -1.0)
    return 0.5 * (upper + lower)


def train_states(cls: type[Component]) -> list[tuple[str, Component]]:
    """At rest (free to start, stuck, loaded through J_esc) and moving, each also with an
    impact speed waiting for the next count and with an impact pending, so that the load's
    start/direction/stick decision and the impact inputs can each be seen.  The M739 train
    starts on a tooth change (phi = 0), where the mesh signs s1, s2 follow that direction."""
    stuck = stuck_load(cls)
    stuck_train = initialized(cls, {"T_esc": stuck})
    assert stuck_train.regime == 0, "the stuck state must be stuck"
    bases = {
        "rest": initialized(cls),
        "stuck": stuck_train,
        "moving": stepped(initialized(cls), 20, 1e-5),
    }
    states = [
        ("rest, backward static load", initialized(cls, {"T_esc_static": -0.1})),
        ("rest, load through J_esc", initialized(cls, {"J_esc": 1e-9})),
        ("stuck, load through J_esc", initialized(cls, {"J_esc": 1e-9, "T_esc_static": stuck})),
    ]
    for label, base in bases.items():
        states.append((label, base))
        states.append((f"{label}, recoil waiting", with_inputs(copy_of(base), phi_dot_impact=-100)))
        for speed in (100.0, 0.0):
            # The master has set the impact inputs; the outputs read next take them.
            c = copy_of(base)
            c.impact_count, c.phi_dot_impact = c.impact_count + 1, speed
            states.append((f"{label}, impact to {speed} rad/s pending", c))
    return states


#: The train's response slopes the verge takes with the wheel state.
SLOPES = ("J_ref_phi", "T_ref_phi", "T_ref_phi_dot", "J_stot_phi")


def verge_states() -> list[tuple[str, Component]]:
    """At the start (wheel at rest on the entrance face), then from an M739 run exchanging
    the escape-wheel port every microsecond: coupled on the entrance face, free after the
    tooth leaves it, coupled on the exit face after the first impact."""
    train_cls, verge_cls = component_class("GearTrain"), component_class("VergeEscapement")
    start = initialized(verge_cls, {"T_ref": 1e-2})
    train, verge = initialized(train_cls), verge_cls()
    wheel = ("phi", "phi_dot", "J_ref", "T_ref", "c_load", "J_stot", *SLOPES)

    def exchange() -> None:
        with_inputs(
            train,
            T_esc=verge.T_esc,
            T_esc_static=verge.T_esc_static,
            J_esc=verge.J_esc,
            impact_count=verge.impact_count,
            phi_dot_impact=verge.phi_dot_post,
        )
        with_inputs(verge, **{k: getattr(train, k) for k in wheel})

    for k in wheel:
        setattr(verge, k, getattr(train, k))
    verge.initialize(0.0)
    exchange()
    states, h = [("start", start)], 1e-6
    for n in range(500):
        train.step(n * h, h)
        verge.step(n * h, h)
        exchange()
        if n + 1 in (200, 440, 500):
            states.append((f"M739 run, step {n + 1}, regime {verge.regime}", copy_of(verge)))
    assert [c.regime for _, c in states] == [1, 1, 0, 2], "coupled, free and exit states"
    return states


def single(cls_name: str, *cases: tuple[str, dict[str, float], dict[str, float], int, float]):
    """States of one component: (label, parameters, inputs, steps, step size)."""

    def build() -> list[tuple[str, Component]]:
        cls = component_class(cls_name)
        return [
            (label, stepped(initialized(cls, inputs, **params), n, h))
            for label, params, inputs, n, h in cases
        ]

    return build


#: name -> (states, absolute perturbation per input)
FEEDTHROUGH_CASES: dict[str, tuple[Callable[[], list[tuple[str, Component]]], dict]] = {
    "Inertia": (
        single("Inertia", ("start", {}, {}, 0, 0.0), ("pushed", {}, {"tau": 1e-3}, 10, 1e-3)),
        {"tau": 1e-3},
    ),
    "SpringDamperInertia": (
        single(
            "SpringDamperInertia",
            ("start", {}, {"phi_in": 0.1, "w_in": 2.0}, 0, 0.0),
            ("stepped", {}, {"phi_in": 0.1, "w_in": 2.0}, 10, 1e-4),
        ),
        {"phi_in": 1e-2, "w_in": 1.0},
    ),
    "GearTrain": (lambda: train_states(component_class("GearTrain")), None),
    "ClockGearTrain": (lambda: train_states(component_class("ClockGearTrain")), None),
    "VergeEscapement": (
        verge_states,
        {
            "phi": 1e-3,
            "phi_dot": 1e3,
            "J_ref": 1e-9,
            "T_ref": 1e-2,
            "c_load": 0.5,
            "J_stot": 1e-9,
            "J_ref_phi": 1e-9,
            "T_ref_phi": 1e-2,
            "T_ref_phi_dot": 1e-5,
            "J_stot_phi": 1e-9,
        },
    ),
    "CrankCouplerDrive": (
        single(
            "CrankCouplerDrive",
            ("start", {}, {}, 0, 0.0),
            ("loaded", {}, {"torque": 10.0}, 5, 1e-3),
        ),
        {"torque": 10.0, "torque_rate": 1e5},  # the rate: a step's ramp, no output takes it
    ),
    "SpragClutch": (
        single(
            "SpragClutch",
            ("engaged", {}, {"speed_outer": 1.0}, 1, 1e-4),
            ("overrunning", {"engaged0": 0.0}, {"speed_outer": -1.0}, 1, 1e-4),
        ),
        {"angle_outer": 1e-4, "angle_inner": 1e-4, "speed_outer": 0.1, "speed_inner": 0.1},
    ),
    "BrakeLoad": (
        single("BrakeLoad", ("stuck", {}, {}, 0, 0.0), ("slipping", {}, {"torque": 50.0}, 1, 1e-3)),
        {"torque": 30.0, "torque_rate": 1e5},
    ),
    "DetachedLever": (
        single(
            "DetachedLever",
            ("start", {}, {}, 0, 0.0),
            ("phase-scheduled", {}, {}, 10, 1e-2),
            ("angle-switched", {"switching_mode": 1, **symmetric_friction(0.0)}, {}, 10, 1e-2),
        ),
        {"drive_torque": 1e-5},
    ),
    "GearMesh": (
        single("GearMesh", ("start", {}, {}, 0, 0.0), ("running", {}, {}, 3, 1e-3)),
        {"load_torque": 0.05},
    ),
}

#: Trains: a load of 0.1 N.m exceeds the spin drive at the wheel (about 0.01 N.m), so it
#: starts, reverses or stops the wheel; 1000 rad/s reverses any impact speed.
TRAIN_SCALES = {
    "T_esc": 0.1,
    "T_esc_static": 0.1,
    "J_esc": 1e-9,
    "T_esc_rate": 1e3,  # 0.1 N.m over 0.1 ms: the step's ramp, no output takes it
    "phi_dot_impact": 1e3,
    "J_load": 1e-9,
}


def test_every_registry_component_has_a_feedthrough_case() -> None:
    assert set(FEEDTHROUGH_CASES) == set(FMU_RECORDS)


def same(a: float, b: float) -> bool:
    return a == b or (a != a and b != b)


def perturbed(var: Variable, x: float, scales: dict[str, float]) -> list[float]:
    """Relative, large and small absolute perturbations (Integer: the next value)."""
    if var.type == "Integer":
        return [x + 1]
    scale = scales[var.name]
    return [v for v in (x * (1.0 + 1e-3), x + scale, x - scale, x + 1e-3 * scale) if v != x]


@pytest.mark.parametrize("name", sorted(FEEDTHROUGH_CASES))
def test_direct_feedthrough_is_declared_exactly(name: str) -> None:
    cls = component_class(name)
    build, scales = FEEDTHROUGH_CASES[name]
    scales = TRAIN_SCALES if scales is None else scales
    outputs = cls.variables("output")
    names = [v.name for v in outputs]
    declared = {(v.name, i) for v in outputs for i in v.depends_on}
    seen: set[tuple[str, str]] = set()
    undeclared: list[str] = []
    for label, comp in build():
        snap = comp.get_state()

        def evaluate(changes: dict[str, float], comp: Component = comp, snap: Any = snap):
            comp.set_state(snap)
            for k, v in changes.items():
                setattr(comp, k, v)
            comp.update_outputs()
            return comp.values(names)

        base = evaluate({})
        again = evaluate({})
        assert all(map(same, base, again)), f"{name} ({label}): outputs not reproducible"
        for var in cls.variables("input"):
            x = getattr(comp, var.name)
            for value in perturbed(var, x, scales):
                after = evaluate({var.name: value})
                for out, a, b in zip(names, base, after, strict=True):
                    if same(a, b):
                        continue
                    seen.add((out, var.name))
                    if (out, var.name) not in declared:
                        undeclared.append(
                            f"{out} <- {var.name} ({label}: {var.name} {x!r} -> {value!r}, "
                            f"{out} {a!r} -> {b!r})"
                        )
    assert not undeclared, f"{name}: undeclared feedthrough:\n" + "\n".join(undeclared)
    unseen = sorted(declared - seen)
    assert not unseen, f"{name}: declared but never seen to act: " + ", ".join(
        f"{o} <- {i}" for o, i in unseen
    )


def test_feedthrough_check_can_fail(monkeypatch: pytest.MonkeyPatch) -> None:
    """Dropping a true dependency, or declaring a false one, is caught."""
    cls = component_class("SpringDamperInertia")
    original = cls.VARIABLES
    for patch in ({"tau": ("phi_in",)}, {"w": ("w_in",)}):
        table = tuple(
            replace(v, depends_on=patch[v.name]) if v.name in patch else v for v in original
        )
        monkeypatch.setattr(cls, "VARIABLES", table)
        with pytest.raises(AssertionError):
            test_direct_feedthrough_is_declared_exactly("SpringDamperInertia")
    monkeypatch.setattr(cls, "VARIABLES", original)
    test_direct_feedthrough_is_declared_exactly("SpringDamperInertia")
