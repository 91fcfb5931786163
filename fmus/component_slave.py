"""The one FMI 2.0 co-simulation slave every component is wrapped in.

A wrapper module in fmus/ only names its component class; this class registers the
component's VARIABLES as FMI variables, forwards the life cycle, and saves and restores
the component's complete state (pythonfmu alone would save registered variables only).

This module is packed inside every FMU next to the ``components`` package, so it may
import only the standard library, numpy, pythonfmu and ``components``.
"""

from __future__ import annotations

import ctypes
import sys
import traceback
from typing import Any, ClassVar

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Integer, Real
from pythonfmu.default_experiment import DefaultExperiment
from pythonfmu.enums import Fmi2Status

from components.base import Component

_CAUSALITY = {
    "parameter": Fmi2Causality.parameter,
    "input": Fmi2Causality.input,
    "output": Fmi2Causality.output,
}


class ComponentSlave(Fmi2Slave):
    """Generic slave: subclasses set ``component_class`` and the metadata below."""

    component_class: ClassVar[type[Component]]
    description: ClassVar[str] = ""
    #: (start, stop, step) of the experiment `fmpy simulate` runs when given the FMU alone
    default_run: ClassVar[tuple[float, float, float]] = (0.0, 1.0, 1.0e-3)

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
        start, stop, step = self.default_run
        self.default_experiment = DefaultExperiment(start, stop, step)
        self.component = self.component_class()
        self._names: list[str] = []
        self._inputs: set[int] = set()
        self._feedthrough_stale = False
        self._initializing = False
        self._init_stale = False
        self._start_time = 0.0
        for var in self.component_class.VARIABLES:
            self._register(var)

    def _register(self, var: Any) -> None:
        comp = self.component
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

    # -- life cycle -------------------------------------------------------------------
    # Outputs must be valid in initialization mode too (a master reads them there to set
    # consistent inputs), so the component is (re)initialized from the current parameters
    # whenever something was set and an output is read, and once more on leaving the mode.
    def setup_experiment(self, start_time: float, stop_time: float | None, tolerance: float | None):
        self._start_time = float(start_time)

    def enter_initialization_mode(self) -> None:
        self._initializing = True
        self._init_stale = True

    def exit_initialization_mode(self) -> None:
        self.component.initialize(self._start_time)
        self.component.update_outputs()
        self._initializing = False
        self._init_stale = False
        self._feedthrough_stale = False

    def _refresh(self) -> None:
        if self._initializing:
            if self._init_stale:
                self.component.initialize(self._start_time)
                self.component.update_outputs()
                self._init_stale = False
        elif self._feedthrough_stale:
            self.component.update_outputs()
        self._feedthrough_stale = False

    def do_step(self, current_time: float, step_size: float) -> bool:
        try:
            if self._feedthrough_stale:
                self._refresh()
            self.component.step(current_time, step_size)
        except Exception as exc:  # the FMU cannot go on: say why through the FMI logger
            self.log(
                f"{type(exc).__name__}: {exc}\n{traceback.format_exc(limit=3)}",
                Fmi2Status.error,
            )
            return False
        return True

    # -- lean variable access (the hot path of every master step) ----------------------
    def get_real(self, vrs: list[int]) -> list[float]:
        if self._feedthrough_stale or self._initializing:
            self._refresh()
        comp = self.component
        names = self._names
        return [float(getattr(comp, names[vr])) for vr in vrs]

    def get_integer(self, vrs: list[int]) -> list[int]:
        if self._feedthrough_stale or self._initializing:
            self._refresh()
        comp = self.component
        names = self._names
        return [int(getattr(comp, names[vr])) for vr in vrs]

    def set_real(self, vrs: list[int], values: list[float]) -> None:
        comp = self.component
        names = self._names
        for vr, value in zip(vrs, values, strict=True):
            setattr(comp, names[vr], float(value))
        self._feedthrough_stale = self._init_stale = True

    def set_integer(self, vrs: list[int], values: list[int]) -> None:
        comp = self.component
        names = self._names
        for vr, value in zip(vrs, values, strict=True):
            setattr(comp, names[vr], int(value))
        self._feedthrough_stale = self._init_stale = True

    # -- complete state ---------------------------------------------------------------
    def _get_fmu_state(self) -> dict[str, Any]:
        return {"component": self.component.get_state(), "stale": self._feedthrough_stale}

    def _set_fmu_state(self, state: dict[str, Any]) -> None:
        self.component.set_state(state["component"])
        self._feedthrough_stale = state["stale"]
