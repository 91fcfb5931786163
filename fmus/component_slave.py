"""The one FMI 2.0 co-simulation slave every component is wrapped in.

A wrapper module in fmus/ only names its component; this class registers the component's
VARIABLES as FMI variables, forwards the life cycle, and saves and restores the
component's complete state (pythonfmu alone would save registered variables only).

Inside an FMU this module sits in a package whose name is unique to the build, next to
that build's ``components`` package, so several FMUs (or two builds of one) run each
their own code in one process.  It imports only the standard library and pythonfmu
(packed too); the component and what it needs (numpy, scipy) are imported when an
instance is made, so that a missing module is reported through the FMU's logger.

FMI calls defend themselves.  pythonfmu's runtime (0.7) turns an exception raised in
Python into fmi2Fatal, after which the instance cannot be used (a later call may crash the
host), and a ``do_step`` that returns False into fmi2Discard.  So a call that cannot be
accepted (a value reference that is unknown or of another type, a fixed parameter after
initialization, a non-finite value, a step that is not positive or does not start where
the last ended, another FMU's state, parameters or inputs the component cannot start from)
is not raised: the reason is logged with fmi2Error and the call returns with nothing
changed.  The FMU's loader (``fmus/loader/python_loader.c``) answers such a call with
fmi2Error and keeps FMI 2.0's state machine, which the calls pythonfmu's runtime answers by
itself (and the order of calls) need; without the loader the refusal is only logged.  A
step the component cannot complete (its step budget spent, say) is fmi2Discard with the
component's reason.  The FMU's log reaches the host at any logging setting through the
loader (pythonfmu's runtime alone, in a build without the loader, only with debug logging
on); a missing module, which ends instantiation before any logging, is also written to
standard error.

The runtime also corrupts the heap when a process exits with its library still loaded
(see ``release_runtime_at_exit``); each instance arranges the remedy.
"""

from __future__ import annotations

import atexit
import ctypes
import importlib
import math
import operator
import os
import sys
import threading
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Integer, Real
from pythonfmu.default_experiment import DefaultExperiment
from pythonfmu.enums import Fmi2Status

if TYPE_CHECKING:
    from components.base import Component, Variable


class FmiCallError(ValueError):
    """An FMI call the FMU cannot accept."""


_CAUSALITY = {
    "parameter": Fmi2Causality.parameter,
    "input": Fmi2Causality.input,
    "output": Fmi2Causality.output,
}


class ComponentSlave(Fmi2Slave):
    """Generic slave: subclasses state ``component`` and the metadata below, as literals
    (``fmus.registry`` reads them from the script; it requires all but ``examples``)."""

    #: "module.Class" of the component, the module inside the ``components`` package
    component: ClassVar[str]
    #: scenes (paths from the project root) that couple it with other FMUs; read, not run,
    #: by ``fmus.registry`` for the FMU's documentation
    examples: ClassVar[tuple[str, ...]] = ()
    description: ClassVar[str]
    #: (start, stop, step) of the experiment `fmpy simulate` runs when given the FMU alone
    default_run: ClassVar[tuple[float, float, float]]

    author = "mechcosim"
    license = "MIT"

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        # pythonfmu's runtime finds the slave class by re-running the wrapper module's source
        # in the module's namespace, then releases a reference to that namespace it never
        # took.  Defining the class (which that lookup does too) takes the missing
        # reference, so one process can instantiate an FMU any number of times.
        module = sys.modules.get(cls.__module__)
        if module is not None:
            ctypes.pythonapi.Py_IncRef(ctypes.py_object(module.__dict__))

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(**kwargs)
        release_runtime_at_exit(self.resources)
        start, stop, step = self.default_run
        self.default_experiment = DefaultExperiment(start, stop, step)
        try:
            self.component_class = _component_class(self.component)
            self._component_error = _component_class("base.ComponentError")
        except ImportError as exc:  # a module the FMU needs is not installed in this Python
            message = (
                f"{type(self).__name__} cannot load its Python code: {exc}. Install the "
                "packages listed in the FMU's resources/requirements.txt into the Python "
                f"that runs it ({sys.executable}, Python {sys.version.split()[0]})"
            )
            self.log(message, Fmi2Status.error)
            print(f"[{self.instance_name}] {message}", file=sys.stderr, flush=True)
            raise
        self.model = self.component_class()
        self._names: list[str] = []
        self._types: list[str] = []
        self._causalities: list[str] = []
        self._inputs: set[int] = set()
        # Inputs set since the outputs were last computed: a step that does not take its
        # inputs itself updates the outputs first (``do_step``).
        self._feedthrough_stale = False
        # The outputs a get would answer are out of date: an input some output depends on
        # (``Variable.depends_on``) changed since they were computed.  A get recomputes them
        # only then; sets of other inputs, or of the same values onto outputs computed from
        # those very inputs, keep them.
        self._outputs_stale = False
        # The outputs were last computed from the inputs as they are (initialization or
        # update_outputs), not by a step: setting an input to its value again changes none.
        self._outputs_from_inputs = False
        self._initializing = False
        self._initialized = False  # initialization mode left: fixed parameters are fixed
        self._init_stale = False
        self._start_time = 0.0
        self._t_end = 0.0  # where the last step ended: the next one starts there
        self._last_h = 0.0
        # the output by which a component that ends its step at its first event says where
        # (components.early_return), found by its role
        self._reached = next(
            (v.name for v in self.component_class.VARIABLES if _kind(v) == "reached_time"), None
        )
        for var in self.component_class.VARIABLES:
            self._register(var)
        reals = {vr for vr, kind in enumerate(self._types) if kind == "Real"}
        integers = set(range(len(self._types))) - reals
        settable = {vr for vr, c in enumerate(self._causalities) if c in ("parameter", "input")}
        self._readable = {"Real": frozenset(reals), "Integer": frozenset(integers)}
        self._settable_before = {
            "Real": frozenset(reals & settable),
            "Integer": frozenset(integers & settable),
        }
        self._settable_after = {
            kind: frozenset(vrs & self._inputs) for kind, vrs in self._settable_before.items()
        }
        by_name = {name: vr for vr, name in enumerate(self._names)}
        self._feeds_outputs = frozenset(
            by_name[name]
            for v in self.component_class.VARIABLES
            if v.causality == "output"
            for name in v.depends_on
            if by_name.get(name) in self._inputs
        )
        # value references -> a function reading them off the component, per type
        self._readers: dict[str, dict[tuple[int, ...], Any]] = {"Real": {}, "Integer": {}}
        # value references set -> their names and the positions of those some output
        # depends on (None: a reference given twice, set one after the other)
        self._set_plans: dict[tuple[int, ...], tuple[tuple[str, ...], tuple[int, ...]]]
        self._set_plans = {}

    def _register(self, var: Any) -> None:
        comp = self.model
        name = var.name
        kind = Integer if var.type == "Integer" else Real
        if var.causality == "parameter":
            variability = Fmi2Variability.fixed
        elif var.type == "Integer":
            variability = Fmi2Variability.discrete
        else:
            variability = Fmi2Variability.continuous
        cast = int if var.type == "Integer" else float
        fmi_var = kind(
            name,
            causality=_CAUSALITY[var.causality],
            variability=variability,
            description=var.description or None,
            getter=lambda: getattr(comp, name),
            setter=lambda v: setattr(comp, name, cast(v)),
        )
        self.register_variable(fmi_var)
        if var.causality == "input":
            self._inputs.add(fmi_var.value_reference)
        self._names.append(name)
        self._types.append("Integer" if var.type == "Integer" else "Real")
        self._causalities.append(var.causality)

    # -- life cycle -------------------------------------------------------------------
    # Outputs must be valid in initialization mode too (a master reads them there to set
    # consistent inputs), so the component is (re)initialized from the current parameters
    # whenever something was set and an output is read, and once more on leaving the mode.
    # Which call is allowed when is the FMU's loader's to check (fmus/loader/python_loader.c);
    # what needs the variables (types, fixed parameters, times) is checked here.
    def setup_experiment(self, start_time: float, stop_time: float | None, tolerance: float | None):
        if not math.isfinite(start_time):
            self._refuse(f"fmi2SetupExperiment: start time {start_time} is not finite")
            return
        self._start_time = self._t_end = float(start_time)
        # A tolerance the host defines is the internal integration's (FMI 2.0, 4.2.4), within
        # the parameter's range; a value the host then sets for `tolerance` still wins.
        declared = next((v for v in self.component_class.VARIABLES if v.name == "tolerance"), None)
        if tolerance is not None and declared is not None and math.isfinite(tolerance):
            low = declared.min if declared.min is not None else 0.0
            high = declared.max if declared.max is not None else math.inf
            self.model.tolerance = min(max(float(tolerance), low), high)
            self._init_stale = True

    def enter_initialization_mode(self) -> None:
        self._initializing = True
        self._init_stale = True

    def exit_initialization_mode(self) -> None:
        bad = [
            v.name
            for v in self.component_class.VARIABLES
            if v.type == "Real" and not math.isfinite(getattr(self.model, v.name))
        ]
        if bad:
            self._refuse(f"fmi2ExitInitializationMode: not finite: {', '.join(bad)}")
            return
        problem = self.model.parameter_problem()
        if problem is not None:
            self._refuse(f"fmi2ExitInitializationMode: {problem}")
            return
        if not self._computed("fmi2ExitInitializationMode", initialize=True):
            return
        self._initializing = False
        self._initialized = True
        self._init_stale = False
        self._feedthrough_stale = self._outputs_stale = False
        self._outputs_from_inputs = True
        self._t_end = self._start_time

    def _refresh(self, function: str) -> bool:
        """Bring the outputs up to date with what was set; False if the component cannot
        (refused, saying why)."""
        if self._initializing:
            if self._init_stale:
                if not self._computed(function, initialize=True):
                    return False
                self._init_stale = False
        elif self._outputs_stale:
            if not self._computed(function, initialize=False):
                return False
            self._feedthrough_stale = self._outputs_stale = False
            self._outputs_from_inputs = True
        return True

    def _computed(self, function: str, initialize: bool) -> bool:
        """(Re)initialize the component, or only its outputs; a failure is refused with the
        component's reason, never a Python error text alone."""
        try:
            if initialize:
                self.model.initialize(self._start_time)
            self.model.update_outputs()
        except self._component_error as exc:  # the component's own words name what is wrong
            self._refuse(f"{function}: {exc}")
            return False
        except Exception as exc:  # noqa: BLE001 - any failure is the host's to hear, by name
            zero = [
                f"{v.name} = {getattr(self.model, v.name)!r}"
                for v in self.component_class.VARIABLES
                if v.causality == "input" and getattr(self.model, v.name) == 0
            ]
            self._refuse(
                f"{function}: {type(self).__name__} cannot compute its outputs from the values "
                f"set ({exc})" + (f"; inputs at zero: {', '.join(zero)}" if zero else "")
            )
            return False
        return True

    def do_step(self, current_time: float, step_size: float) -> bool:
        refusal = ""
        expected = self._t_end
        if not (math.isfinite(current_time) and math.isfinite(current_time + step_size)):
            refusal = f"time {current_time} or step size {step_size} is not finite"
        elif not step_size > 0.0:
            refusal = f"step size {step_size} is not positive"
        elif abs(current_time - expected) > TIME_MATCH * max(
            abs(expected), abs(current_time), self._last_h
        ):
            refusal = f"the last step ended at t = {expected!r} s, where the next must start"
        if refusal:  # fmi2Error, nothing changed
            self._refuse(f"fmi2DoStep at t = {current_time!r} s refused: {refusal}")
            return True
        try:
            if self._feedthrough_stale and not self.model.STEP_TAKES_INPUTS:
                self.model.update_outputs()
            self.model.step(current_time, step_size)
            self._feedthrough_stale = self._outputs_stale = self._outputs_from_inputs = False
        except Exception as exc:  # noqa: BLE001 - the step cannot be completed: say why
            # fmi2Discard; nothing of the step is kept, so the last successful time is its
            # start, which pythonfmu's runtime answers to fmi2GetRealStatus
            why = (
                str(exc)
                if isinstance(exc, self._component_error)
                else f"{type(exc).__name__}: {exc}"
            )
            self.log(
                f"fmi2DoStep from t = {current_time!r} s over {step_size!r} s: {why}",
                Fmi2Status.error,
            )
            return False
        reached = self._reached
        self._t_end = float(getattr(self.model, reached) if reached else current_time + step_size)
        self._last_h = step_size
        return True

    def _refuse(self, message: str) -> None:
        """Refuse the call: log why with fmi2Error, which the FMU's loader answers with."""
        self.log(message, Fmi2Status.error)

    # -- variable access (the hot path of every master step) ---------------------------
    def _bad_reference(self, function: str, kind: str, vrs: list[int], allowed: frozenset) -> None:
        """Refuse a call with a value reference that is not in ``allowed``, saying why."""
        vr = next(vr for vr in vrs if vr not in allowed)
        if not 0 <= vr < len(self._names):
            self._refuse(f"{function}: no variable has value reference {vr}")
            return
        name, its = self._names[vr], self._types[vr]
        if its != kind:
            article = "an" if its[0] in "AEIOU" else "a"
            self._refuse(f"{function}: value reference {vr} is {name}, {article} {its}")
        elif self._causalities[vr] == "output":
            self._refuse(f"{function}: {name} is an output, which the host cannot set")
        else:
            self._refuse(
                f"{function}: {name} is a fixed parameter, which cannot change after initialization"
            )

    def get_real(self, vrs: list[int]) -> list[float]:
        return self._get("Real", vrs, float, 0.0, "fmi2GetReal")

    def get_integer(self, vrs: list[int]) -> list[int]:
        return self._get("Integer", vrs, int, 0, "fmi2GetInteger")

    def _get(self, kind: str, vrs: list[int], cast: type, zero: Any, function: str) -> list:
        """The values of ``vrs`` (of ``kind``), outputs brought up to date first; zeros
        where the call is refused."""
        key = tuple(vrs)
        read = self._readers[kind].get(key)
        if read is None:
            if not self._readable[kind].issuperset(vrs):
                self._bad_reference(function, kind, vrs, self._readable[kind])
                return [zero] * len(vrs)
            read = self._reader(kind, key, cast)
        if (self._outputs_stale or self._initializing) and not self._refresh(function):
            return [zero] * len(vrs)
        return read(self.model)

    def _reader(self, kind: str, vrs: tuple[int, ...], cast: type) -> Any:
        """A function reading the variables ``vrs`` (valid ones, of ``kind``) off the
        component as a list of ``cast``; kept for the next call with the same references."""
        readers = self._readers[kind]
        if len(readers) >= READERS_KEPT:  # a host asking ever other sets: no unbounded memo
            readers.clear()
        names = [self._names[vr] for vr in vrs]
        if len(names) == 1:
            one = operator.attrgetter(names[0])

            def read(comp: Any) -> list:
                return [cast(one(comp))]

        elif names:
            many = operator.attrgetter(*names)

            def read(comp: Any) -> list:
                return list(map(cast, many(comp)))

        else:

            def read(comp: Any) -> list:
                return []

        readers[vrs] = read
        return read

    def set_real(self, vrs: list[int], values: list[float]) -> None:
        settable = (self._settable_after if self._initialized else self._settable_before)["Real"]
        if not settable.issuperset(vrs):
            self._bad_reference("fmi2SetReal", "Real", vrs, settable)
            return
        if not all(map(math.isfinite, values)):
            vr, value = next(
                (r, v) for r, v in zip(vrs, values, strict=True) if not math.isfinite(v)
            )
            self._refuse(f"fmi2SetReal: {self._names[vr]} = {value} is not finite")
            return
        self._set(vrs, values, float)

    def set_integer(self, vrs: list[int], values: list[int]) -> None:
        settable = (self._settable_after if self._initialized else self._settable_before)["Integer"]
        if not settable.issuperset(vrs):
            self._bad_reference("fmi2SetInteger", "Integer", vrs, settable)
            return
        self._set(vrs, values, int)

    def _set(self, vrs: list[int], values: list, cast: type) -> None:
        """Set valid, checked values and say which outputs they leave out of date."""
        comp = self.model
        names = self._names
        if not self._initialized:  # initialization recomputes everything from what is set
            for vr, value in zip(vrs, values, strict=True):
                setattr(comp, names[vr], cast(value))
            self._feedthrough_stale = self._init_stale = self._outputs_stale = True
            return
        key = tuple(vrs)
        if len(values) != len(key):
            raise ValueError(f"{len(key)} references but {len(values)} values")
        plan = self._set_plans.get(key)
        if plan is None:
            plan = self._set_plan(key)
        set_names, feeding = plan
        values = list(map(cast, values))
        stale = self._outputs_stale
        if not stale and feeding:
            # after a step the outputs are the step's: a set recomputes them, as ever.  A
            # reference given twice is compared with the value before the call each time:
            # stale as soon as either differs, as when compared one set after the other.
            stale = not self._outputs_from_inputs
            for k in () if stale else feeding:
                if not _same(getattr(comp, set_names[k]), values[k]):
                    stale = True
                    break
        for name, value in zip(set_names, values, strict=True):  # the last of a twice-set wins
            setattr(comp, name, value)
        self._feedthrough_stale = self._init_stale = True
        self._outputs_stale = stale

    def _set_plan(self, vrs: tuple[int, ...]) -> tuple[tuple[str, ...], tuple[int, ...]]:
        """The names of ``vrs`` (valid, settable ones) and the positions of those some
        output depends on; kept for the next set of the same references."""
        plans = self._set_plans
        if len(plans) >= READERS_KEPT:  # a host setting ever other lists: no unbounded memo
            plans.clear()
        feeds = self._feeds_outputs
        plan = (
            tuple(self._names[vr] for vr in vrs),
            tuple(k for k, vr in enumerate(vrs) if vr in feeds),
        )
        plans[vrs] = plan
        return plan

    # no Boolean or String variables: an empty call is answered, any reference refused
    def get_boolean(self, vrs: list[int]) -> list[bool]:
        if vrs:
            self._bad_reference("fmi2GetBoolean", "Boolean", vrs, frozenset())
        return [False] * len(vrs)

    def get_string(self, vrs: list[int]) -> list[str]:
        if vrs:
            self._bad_reference("fmi2GetString", "String", vrs, frozenset())
        return [""] * len(vrs)

    def set_boolean(self, vrs: list[int], values: list[bool]) -> None:
        if vrs:
            self._bad_reference("fmi2SetBoolean", "Boolean", vrs, frozenset())

    def set_string(self, vrs: list[int], values: list[str]) -> None:
        if vrs:
            self._bad_reference("fmi2SetString", "String", vrs, frozenset())

    # -- complete state ---------------------------------------------------------------
    def _get_fmu_state(self) -> dict[str, Any]:
        return {
            "fmu": self.component,
            "component": self.model.get_state(),
            "stale": (self._feedthrough_stale, self._outputs_stale, self._outputs_from_inputs),
            "init_stale": self._init_stale,
            "phase": (self._initializing, self._initialized),
            "time": (self._start_time, self._t_end, self._last_h),
        }

    def _set_fmu_state(self, state: dict[str, Any]) -> None:
        owner = state.get("fmu") if isinstance(state, dict) else None
        if owner != self.component:
            self._refuse(
                f"fmi2SetFMUstate: the state is of {owner or 'no FMU of ours'}, "
                f"not of {self.component}"
            )
            return
        self.model.set_state(state["component"])
        self._feedthrough_stale, self._outputs_stale, self._outputs_from_inputs = state["stale"]
        self._init_stale = state["init_stale"]
        self._initializing, self._initialized = state["phase"]
        self._start_time, self._t_end, self._last_h = state["time"]


#: Reading functions kept per type (one per list of value references a host asks for), and
#: setting plans.
READERS_KEPT = 64


def _same(old: float, new: float) -> bool:
    """Whether a set value is the one held, bit for bit (0.0 and -0.0 differ)."""
    return old == new and (old != 0.0 or math.copysign(1.0, old) == math.copysign(1.0, new))


#: A step starts where the last ended, up to this relative difference (a host that computes
#: t_k = k h rather than summing the steps).
TIME_MATCH = 1e-9


def _kind(var: Variable) -> str | None:
    """The kind of a variable's coupling role (components.base.Role), None if it has none."""
    role = getattr(var, "role", None)
    return role.kind if role is not None else None


def _component_class(path: str) -> type[Component]:
    """The component class named "module.Class" in the ``components`` package beside this
    module (inside an FMU, the build's own copy)."""
    module, name = path.rsplit(".", 1)
    package = __package__ + ".components" if __package__ else "components"
    return getattr(importlib.import_module(f"{package}.{module}"), name)


_RUNTIMES_TO_RELEASE: set[str] = set()


def release_runtime_at_exit(resources: str | None) -> None:
    """Release pythonfmu's runtime of this FMU before the process exits.

    The runtime (0.7, Linux) keeps its interpreter state in a static ``shared_ptr`` and
    resets that pointer from a library destructor.  A library still loaded when the process
    exits (FMPy's freeLibrary does not unload it) has its static destructors run first, so
    the destructor then resets a freed pointer: the heap is corrupted and the exit aborts
    now and then ("corrupted double-linked list").  Resetting it from Python's own exit
    handlers, while everything is alive, leaves nothing for the destructors to free twice.
    """
    if not sys.platform.startswith("linux") or not resources:
        return
    for library in (Path(resources).parent / "binaries" / "linux64").glob("*.so"):
        if str(library) not in _RUNTIMES_TO_RELEASE:
            _RUNTIMES_TO_RELEASE.add(str(library))
            atexit.register(_release_runtime, str(library))


def _release_runtime(library: str) -> None:
    # Only where the host owns the interpreter: a host that is not Python has the runtime
    # finalize Python from a thread of its own, as part of that very release.
    if threading.get_native_id() != os.getpid():
        return
    try:
        runtime = ctypes.CDLL(library, mode=os.RTLD_NOLOAD | os.RTLD_NOW)
        release = runtime.finalizePythonInterpreter
    except (OSError, AttributeError):
        # unloaded already, its destructors run in order; or the FMU's loader, which
        # releases the runtime beside it by itself
        return
    release()
