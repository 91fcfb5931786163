"""The contract every mechanical subsystem fulfils.

A component is plain Python (no FMI imports). It declares its variables once, in
``VARIABLES``; the FMU wrapper, the scenario loader and the recorder all read that
table, so a variable's name, unit and meaning are stated in exactly one place.

Life cycle (mirrors FMI 2.0 co-simulation):

1. ``Component(**parameters)``: parameters are set, everything else takes its start value.
2. ``initialize(t0)``: derived quantities and consistent initial outputs are computed.
3. ``step(t, h)``: advance from ``t`` to ``t + h`` with the inputs held at their current
   values (zero-order hold).  Internal events are located inside the step; the regime
   never changes inside an integrator stage.
4. ``get_state()`` / ``set_state(s)``: a complete snapshot, including regime flags and
   hidden variables, so that restoring and stepping again reproduces the same numbers
   bit for bit.

Every component outputs ``regime`` (Integer), ``stored_energy`` [J] and
``dissipated_work`` [J]; a component that brings work in from outside the scene (a
prescribed drive, a spin field) also outputs ``external_work`` [J].  Any run that records
these can be checked for energy balance: stored + dissipated - external = constant.
"""

from __future__ import annotations

import copy
import math
import pickle
from dataclasses import dataclass, field, replace
from typing import Any, ClassVar, Literal

Causality = Literal["parameter", "input", "output"]
#: What a master may rely on a variable for beyond its causality, where FMI 2.0 has no word
#: for it (the model description carries it in our vendor annotation, fmus/description.py):
#: rate_of X (a Real input: X's rate over a step, ramped about its held value at mid-step),
#: step_mean_of X (an output: X's mean over the last step), own_copy_of X (an output: the
#: component's own copy of its sampled input X at the step end), early_return (the Integer
#: input asking a step to end at its first event), reached_time (the output saying where
#: the last step ended).
RoleKind = Literal["rate_of", "step_mean_of", "own_copy_of", "early_return", "reached_time"]
#: The role kinds that name another variable (``Role.of``).
ROLES_OF = ("rate_of", "step_mean_of", "own_copy_of")
#: Of each role kind: the causality of the variable that carries it, and of the one it names.
ROLE_CAUSALITY: dict[str, tuple[str, str | None]] = {
    "rate_of": ("input", "input"),
    "step_mean_of": ("output", "output"),
    "own_copy_of": ("output", "input"),
    "early_return": ("input", None),
    "reached_time": ("output", None),
}


@dataclass(frozen=True)
class Role:
    """A variable's coupling role: its kind and, for rate_of, step_mean_of and
    own_copy_of, the variable it refers to."""

    kind: RoleKind
    of: str | None = None

    def __str__(self) -> str:
        return f"{self.kind} {self.of}" if self.of else self.kind


@dataclass(frozen=True)
class Variable:
    """One externally visible variable of a component, in SI units."""

    name: str
    causality: Causality
    unit: str  # SI unit as an FMI unit name, e.g. "rad", "rad/s", "N.m", "kg.m2", "1"
    start: float
    description: str = ""
    type: Literal["Real", "Integer"] = "Real"
    #: An input that is an initial state taken at the start of each step (e.g. the angle of
    #: a shaft the component follows), not a signal held over the step.  Masters judge the
    #: error of holding inputs on held signals only.
    sampled: bool = False
    #: Valid range of a parameter (inclusive, SI); None where there is no bound.
    min: float | None = None
    max: float | None = None
    #: The lower bound is excluded: zero (say) is no valid value where it means nothing
    #: physical (a Young's modulus, a length, an inertia).  FMI cannot say so: checked
    #: when initialization ends (``Component.parameter_problem``).
    exclusive_min: bool = False
    #: Of an output: the inputs it depends on directly within one instant (direct
    #: feedthrough, recomputed by ``update_outputs``).  Empty: it changes only by stepping.
    depends_on: tuple[str, ...] = ()
    #: Of a Real: its typical magnitude (FMI 2.0 ``nominal``), where a relative measure of
    #: it needs a floor: a speed starting from rest has no running scale yet.
    nominal: float | None = None
    #: Of a parameter: a quantity of the mechanism's design, as its source program read it
    #: (its description ends with the source symbol, "[SANDA2V: CAPRB1]").  A scene states
    #: it once, in its design, and every FMU of the scene that declares it takes that value.
    design: bool = False
    #: Its coupling role (see ``Role``); None: a plain variable.
    role: Role | None = None


def role_problem(var: Variable, by_name: dict[str, Variable]) -> str | None:
    """What is wrong with a variable's role among the variables ``by_name``, said in one
    line; None if nothing is (or it has none)."""
    role = var.role
    if role is None:
        return None
    own, other = ROLE_CAUSALITY[role.kind]
    if var.causality != own:
        return f"{var.name} has the role {role} but is an {var.causality}; expected an {own}"
    if other is None:
        return None
    target = by_name.get(role.of or "")
    if target is None or target.causality != other:
        return f"{var.name} has the role {role}, but {role.of!r} is not an {other} of it"
    return None


def design_parameter(
    name: str,
    unit: str,
    start: float,
    meaning: str,
    source: str,
    type: Literal["Real", "Integer"] = "Real",
    **bounds: Any,
) -> Variable:
    """A design quantity: a parameter whose description names its source symbol,
    ``meaning [source]`` (e.g. source "SANDA2V: CAPRB1")."""
    return Variable(
        name, "parameter", unit, start, f"{meaning} [{source}]", type, design=True, **bounds
    )


@dataclass(frozen=True)
class SnapshotPlan:
    """A cheap snapshot for components whose state is a few plain values plus some helper
    objects: everything is shared except the members named here, which are copied one level
    deep.  Sharing is right for what is immutable in use (constants, memos of parameters).

    lists: attributes holding lists of numbers (the state vector), copied.
    objects: attribute -> {its attribute: component attribute}: objects whose ``__dict__`` is
        copied; the named links point to another copied object and are re-pointed on restore.
    """

    lists: tuple[str, ...] = ()
    objects: dict[str, dict[str, str]] = field(default_factory=dict)

    def take(self, members: dict[str, Any]) -> dict[str, Any]:
        snap = dict(members)
        for name in self.lists:
            if name in snap:
                snap[name] = list(snap[name])
        for name, links in self.objects.items():
            if name in snap:
                obj = snap[name]
                fields = dict(obj.__dict__)  # a copy at C speed, then the links out
                for link in links:
                    fields.pop(link, None)
                snap[name] = (type(obj), fields)
        return snap

    def restore(self, snap: dict[str, Any]) -> dict[str, Any]:
        members = dict(snap)
        for name in self.lists:
            if name in members:
                members[name] = list(members[name])
        for name in self.objects:
            if name in members:
                cls, fields = members[name]
                obj = cls.__new__(cls)
                obj.__dict__.update(fields)
                members[name] = obj
        for name, links in self.objects.items():
            if name in members:
                for attribute, target in links.items():
                    setattr(members[name], attribute, members[target])
        return members


class ComponentError(RuntimeError):
    """A component cannot go on (bad parameters, divergence, impossible state)."""


class Component:
    """Base class: parameter handling, state snapshot, variable access."""

    #: Every variable visible from outside, in declaration order.
    VARIABLES: ClassVar[tuple[Variable, ...]] = ()
    #: Rotational ports: port name -> {role: variable}; roles are "angle", "speed", "torque"
    #: and any extra signal a joint needs (e.g. "inertia").  Connecting two ports joins each
    #: role present on both sides, from the side where it is an output to the other.
    PORTS: ClassVar[dict[str, dict[str, str]]] = {}
    #: How get_state copies the component; None: the whole of it, pickled (always safe).
    SNAPSHOT: ClassVar[SnapshotPlan | None] = None
    #: step() takes the inputs itself (as update_outputs does, idempotently) and computes
    #: the outputs at its end, so inputs set just before a step need no update_outputs.
    STEP_TAKES_INPUTS: ClassVar[bool] = False

    def __init__(self, **parameters: float) -> None:
        for var in self.VARIABLES:
            value = var.start
            setattr(self, var.name, int(value) if var.type == "Integer" else float(value))
        known = {v.name for v in self.VARIABLES if v.causality == "parameter"}
        for name, value in parameters.items():
            if name not in known:
                raise ComponentError(
                    f"{type(self).__name__}: unknown parameter {name!r}; "
                    f"expected one of {sorted(known)}"
                )
            setattr(self, name, float(value))

    # -- life cycle -------------------------------------------------------------------
    def parameter_problem(self) -> str | None:
        """The first parameter that is not finite or not above an exclusive lower bound,
        said in one line naming it; None if there is none."""
        for v in self.VARIABLES:
            if v.causality != "parameter":
                continue
            value = getattr(self, v.name)
            if not math.isfinite(value):
                return f"parameter {v.name} is {value!r}; expected a finite number"
            if v.exclusive_min and v.min is not None and not value > v.min:
                what = f" ({v.description})" if v.description else ""
                return (
                    f"parameter {v.name} = {value!r} {v.unit}; expected more than {v.min:g}{what}"
                )
        return None

    def check_parameters(self) -> None:
        """Raise ComponentError naming the first parameter ``parameter_problem`` finds."""
        problem = self.parameter_problem()
        if problem is not None:
            raise ComponentError(f"{type(self).__name__}: {problem}")

    def initialize(self, t0: float) -> None:
        """Compute derived quantities and consistent initial outputs."""

    def step(self, t: float, h: float) -> None:
        """Advance from t to t + h with inputs held."""
        raise NotImplementedError

    def update_outputs(self) -> None:
        """Recompute outputs that depend directly on inputs (direct feedthrough).

        Called after inputs change and before outputs are read; a component without
        feedthrough leaves it empty.
        """

    # -- state ------------------------------------------------------------------------
    def get_state(self) -> bytes | dict[str, Any]:
        """A complete, independent snapshot of everything the component holds.

        With a ``SNAPSHOT`` plan, a shallow copy with the plan's mutable members copied.
        Otherwise pickled bytes where possible: several times cheaper than a deep copy,
        immutable, and restoring them builds fresh objects, so a snapshot can be restored
        many times.
        """
        if self.SNAPSHOT is not None:
            return self.SNAPSHOT.take(self.__dict__)
        # Attributes named _cache* hold values derived from parameters only: not state.
        state = {k: v for k, v in self.__dict__.items() if not k.startswith("_cache")}
        try:
            return pickle.dumps(state, pickle.HIGHEST_PROTOCOL)
        except (pickle.PicklingError, TypeError, AttributeError):  # e.g. a local function held
            return copy.deepcopy(state)

    def set_state(self, state: bytes | dict[str, Any]) -> None:
        """Restore a snapshot taken by get_state (the snapshot stays reusable)."""
        if self.SNAPSHOT is not None:
            self.__dict__.clear()
            self.__dict__.update(self.SNAPSHOT.restore(state))
            return
        restored = pickle.loads(state) if isinstance(state, bytes) else copy.deepcopy(state)
        caches = {k: v for k, v in self.__dict__.items() if k.startswith("_cache")}
        self.__dict__.clear()
        self.__dict__.update(restored)
        self.__dict__.update(caches)

    # -- introspection ----------------------------------------------------------------
    @classmethod
    def variables(cls, causality: Causality | None = None) -> tuple[Variable, ...]:
        if causality is None:
            return cls.VARIABLES
        return tuple(v for v in cls.VARIABLES if v.causality == causality)

    @classmethod
    def variable(cls, name: str) -> Variable:
        for v in cls.VARIABLES:
            if v.name == name:
                return v
        raise KeyError(name)

    def values(self, names: list[str] | tuple[str, ...]) -> list[float]:
        return [getattr(self, n) for n in names]


# Variables every component carries; subclasses append their own.
COMMON_OUTPUTS: tuple[Variable, ...] = (
    Variable("regime", "output", "1", 0, "discrete regime (mode) index", "Integer"),
    Variable("stored_energy", "output", "J", 0.0, "kinetic + potential energy held"),
    Variable("dissipated_work", "output", "J", 0.0, "work dissipated since start"),
)


def common_outputs(**depends_on: tuple[str, ...]) -> tuple[Variable, ...]:
    """COMMON_OUTPUTS with the direct feedthrough a component gives some of them, e.g.
    ``common_outputs(stored_energy=("phi_in",))`` for a spring stretched by an input."""
    unknown = sorted(set(depends_on) - {v.name for v in COMMON_OUTPUTS})
    if unknown:
        raise KeyError(f"not common outputs: {unknown}")
    return tuple(replace(v, depends_on=depends_on.get(v.name, ())) for v in COMMON_OUTPUTS)


def rate_input(name: str, unit: str) -> Variable:
    """The Real input ``<name>_rate`` by which a component takes how its input ``name``
    moves over a step: the input then ramps through the step about its held value at
    mid-step (a master's first-order hold; 0, the start value: held)."""
    return Variable(
        f"{name}_rate",
        "input",
        f"{unit}/s",
        0.0,
        f"rate of {name} over a step: it ramps about its held value at mid-step",
        role=Role("rate_of", name),
    )
