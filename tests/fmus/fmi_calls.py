"""Our FMUs driven call by call through FMPy, with FMI 2.0's co-simulation state machine
(FMI 2.0.4, section 4.2.4, the table of which function may be called in which state) as
the expected answer.  Shared by the table test and the fuzz test of the call sequences.

Every call is made with arguments that are valid where the call is allowed (a value
reference of the right type, the time where the last step ended), so the only reason for
fmi2Error is the state, and the answer tells the state the instance is in after it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave, fmi2LastSuccessfulTime

INSTANTIATED = "instantiated"
INIT = "initialization mode"
COMPLETE = "step complete"
FAILED = "step failed"
TERMINATED = "terminated"
ERROR = "error"
STATES = (INSTANTIATED, INIT, COMPLETE, FAILED, TERMINATED, ERROR)

SETTABLE = {INSTANTIATED, INIT, COMPLETE}
READABLE = {INIT, COMPLETE, FAILED, TERMINATED, ERROR}
ANY = set(STATES)
#: FMI 2.0's table: the states each call may be made in (its "step in progress" and "step
#: canceled" are never entered: our steps are synchronous, so fmi2CancelStep never applies)
ALLOWED: dict[str, set[str]] = {
    "setupExperiment": {INSTANTIATED},
    "enterInitializationMode": {INSTANTIATED},
    "exitInitializationMode": {INIT},
    "doStep": {COMPLETE},
    "cancelStep": set(),
    "terminate": {COMPLETE, FAILED},
    "reset": ANY,
    "setDebugLogging": ANY,
    "getReal": READABLE,
    "getInteger": READABLE,
    "getBoolean": READABLE,
    "getString": READABLE,
    "setReal": SETTABLE,
    "setInteger": SETTABLE,
    "setBoolean": SETTABLE,
    "setString": SETTABLE,
    "getFMUstate": ANY,
    "setFMUstate": ANY,
    "getRealStatus": {COMPLETE, FAILED, TERMINATED},
}
#: where an accepted call takes the instance (else it stays where it is)
MOVES = {
    "enterInitializationMode": INIT,
    "exitInitializationMode": COMPLETE,
    "doStep": COMPLETE,
    "terminate": TERMINATED,
    "reset": INSTANTIATED,
}
OK, DISCARD, ERROR_STATUS = 0, 2, 3


@dataclass
class Driven:
    """One instance of an FMU, the state the standard says it is in, and what it needs."""

    name: str
    fmu: FMU2Slave
    real_out: int
    real_in: tuple[int, float] | None  # an input and its start value
    int_out: int | None
    step: float
    messages: list[str] = field(default_factory=list)
    state: str = INSTANTIATED
    t_end: float = 0.0
    saved: dict[str, Any] = field(default_factory=dict)  # FMU states by the state taken in

    def call(self, name: str) -> int:
        """Make the call ``name`` with valid arguments; its status."""
        f, step = self.fmu, self.step
        actions: dict[str, Callable[[], Any]] = {
            "setupExperiment": lambda: f.setupExperiment(startTime=0.0),
            "enterInitializationMode": f.enterInitializationMode,
            "exitInitializationMode": f.exitInitializationMode,
            "doStep": lambda: f.doStep(self.t_end, step),
            "cancelStep": lambda: f.fmi2CancelStep(f.component),
            "terminate": f.terminate,
            "reset": f.reset,
            "setDebugLogging": lambda: f.setDebugLogging(False, []),
            "getReal": lambda: f.getReal([self.real_out]),
            "getInteger": lambda: f.getInteger([] if self.int_out is None else [self.int_out]),
            "getBoolean": lambda: f.getBoolean([]),
            "getString": lambda: f.getString([]),
            "setReal": lambda: f.setReal(*self._real_input()),
            "setInteger": lambda: f.setInteger([], []),
            "setBoolean": lambda: f.setBoolean([], []),
            "setString": lambda: f.setString([], []),
            "getFMUstate": self._get_state,
            "setFMUstate": lambda: f.setFMUstate(self.saved[COMPLETE]),
            "getRealStatus": lambda: f.getRealStatus(fmi2LastSuccessfulTime),
        }
        try:
            actions[name]()
        except FMICallException as exc:
            return exc.status
        return OK

    def _real_input(self) -> tuple[list[int], list[float]]:
        if self.real_in is None:
            return [], []
        return [self.real_in[0]], [self.real_in[1]]

    def _get_state(self) -> None:
        state = self.fmu.getFMUstate()
        self.fmu.freeFMUstate(state)

    def expect(self, name: str) -> int:
        """The status FMI 2.0 asks of ``name`` now; the state follows the call."""
        if self.state not in ALLOWED[name]:
            self.state = ERROR
            return ERROR_STATUS
        if name == "setFMUstate":
            self.state, self.t_end = COMPLETE, self.saved_t_end
        elif name in MOVES:
            self.state = MOVES[name]
            if name == "doStep":
                self.t_end += self.step
            elif name in ("reset", "exitInitializationMode"):
                self.t_end = 0.0
        return OK

    saved_t_end: float = 0.0

    def states(self) -> tuple[str, ...]:
        """The states this instance can be brought to (step failed: where a step can fail)."""
        return tuple(s for s in STATES if s != FAILED or FAILED in self.saved)

    def put_in(self, state: str) -> None:
        """Bring the instance to ``state`` (FMU states taken once, restored)."""
        f = self.fmu
        if state == INSTANTIATED:
            f.reset()
        elif state == INIT:
            f.reset()
            f.setupExperiment(startTime=0.0)
            f.enterInitializationMode()
        else:
            f.setFMUstate(self.saved[COMPLETE])
            self.t_end = self.saved_t_end
            if state == TERMINATED:
                f.terminate()
            elif state == ERROR:
                assert self.call("cancelStep") == ERROR_STATUS
            elif state == FAILED:
                f.setFMUstate(self.saved[FAILED])
        self.state = state
        if state in (INSTANTIATED, INIT):
            self.t_end = 0.0


def drive(name: str, path: Path, scratch: Path) -> Driven:
    """An instance of the FMU at ``path``, initialized, one step taken and that state saved
    (the state to come back to)."""
    md = read_model_description(str(path))
    variables = {v.name: v for v in md.modelVariables}
    messages: list[str] = []
    fmu = FMU2Slave(
        guid=md.guid,
        unzipDirectory=extract(str(path), str(scratch)),
        modelIdentifier=md.coSimulation.modelIdentifier,
        instanceName=name,
    )
    logger = _logger(messages)
    fmu.instantiate(loggingOn=False, callbacks=_callbacks(logger))
    fmu._mechcosim_logger = logger  # kept alive as long as the instance
    real_out = next(v for v in variables.values() if v.causality == "output" and v.type == "Real")
    real_in = next(
        (v for v in variables.values() if v.causality == "input" and v.type == "Real"), None
    )
    int_out = next((v for v in variables.values() if v.type in ("Integer", "Enumeration")), None)
    step = float(md.defaultExperiment.stepSize)
    d = Driven(
        name,
        fmu,
        real_out.valueReference,
        None if real_in is None else (real_in.valueReference, float(real_in.start or 0.0)),
        None if int_out is None else int_out.valueReference,
        step,
        messages,
    )
    budget = variables.get("max_internal_steps")
    if budget is not None:  # a step over its budget of one internal step: fmi2Discard
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.setInteger([budget.valueReference], [1])
        moving = variables.get("phi_dot")  # a wheel at rest would take the step at once
        if moving is not None and moving.causality == "input":
            fmu.setReal([moving.valueReference], [50.0])
        fmu.exitInitializationMode()
        try:
            fmu.doStep(0.0, 1e6)
            status = OK
        except FMICallException as exc:
            status = exc.status
        if status == DISCARD:
            d.saved[FAILED] = fmu.getFMUstate()
        fmu.reset()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    fmu.doStep(0.0, step)
    d.saved[COMPLETE] = fmu.getFMUstate()
    d.saved_t_end = step
    d.state, d.t_end = COMPLETE, step
    return d


def _logger(messages: list[str]) -> Any:
    from fmpy.fmi2 import fmi2CallbackLoggerTYPE

    def log(env: Any, instance: bytes, status: int, category: bytes, message: bytes) -> None:
        messages.append(message.decode(errors="replace"))

    return fmi2CallbackLoggerTYPE(log)


def _callbacks(logger: Any) -> Any:
    from fmpy.fmi2 import (
        calloc,
        fmi2CallbackAllocateMemoryTYPE,
        fmi2CallbackFreeMemoryTYPE,
        fmi2CallbackFunctions,
        free,
    )

    callbacks = fmi2CallbackFunctions()
    callbacks.logger = logger
    callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    return callbacks
