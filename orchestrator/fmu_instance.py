"""One instantiated co-simulation FMU, driven through fmpy.

Names are resolved to value references once; the hot-path calls (set inputs, do_step,
get outputs, get/set state) take prepared reference lists.  The last messages the FMU
logs are kept, so a failed step can say what the FMU said, and its warnings are counted
(``orchestrator.fmu_log``).
"""

from __future__ import annotations

import itertools
import struct
from collections.abc import Callable
from ctypes import byref
from pathlib import Path
from typing import Any

from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import (  # the allocators fmpy itself hands to FMUs, and its value types
    FMU2Slave,
    calloc,
    fmi2Boolean,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
    fmi2FMUstate,
    fmi2Integer,
    fmi2LastSuccessfulTime,
    fmi2Real,
    fmi2Terminated,
    fmi2True,
    fmi2ValueReference,
    free,
    printLogMessage,
)

from orchestrator import flight
from orchestrator.errors import RunError
from orchestrator.fmu_log import FmuLog
from orchestrator.unpacked_fmus import unpacked

STATUS_NAMES = ("fmi2OK", "fmi2Warning", "fmi2Discard", "fmi2Error", "fmi2Fatal", "fmi2Pending")
LAST_LINES = 3  # of an FMU's log, in the message of a call that failed


DISCARD = 2


class FmuTerminated(RunError):
    """An FMU asked to end the simulation: the run ends there, completed."""

    def __init__(self, message: str, time: float, fmu: str, last_time: float | None = None) -> None:
        RuntimeError.__init__(self, message)  # the message names FMU and time itself
        self.time, self.fmu = time, fmu
        # fmi2LastSuccessfulTime, where the FMU got to within the step it ended (None: it
        # did not say, or said the step start): FMPy records its outputs there.
        self.last_time = last_time


class FmiCallError(RunError):
    """An FMI call returned fmi2Discard, fmi2Error or fmi2Fatal."""

    def __init__(self, message: str, function: str, status: int, time: float, fmu: str) -> None:
        self.function, self.status = function, status
        super().__init__(message, time, fmu)


# The logger.  FMI 2.0 (2.1.5) makes its message a printf format with the arguments after
# it, which ctypes cannot receive; fmpy's native proxy (fmpy.logging) formats them and
# hands the text on.  The proxy keeps one logger for the process, so there is one here,
# which passes each message to its instance by the componentEnvironment it was given.
_LOGS: dict[int, Callable[[int, str, str], None]] = {}
_ENVIRONMENTS = itertools.count(1)
#: The FMI functions that set variables (what a get answers then changes only by the
#: outputs depending on them); fmi2SetRealInputDerivatives among them.
_SETS = ("fmi2SetReal", "fmi2SetInteger", "fmi2SetBoolean", "fmi2SetString")


def _log_message(env: Any, instance: bytes, status: int, category: bytes, message: bytes) -> None:
    keep = _LOGS.get(env or 0)
    if keep is not None:
        text = message.decode("utf-8", "replace") if message else ""
        keep(status, category.decode("utf-8", "replace") if category else "", text)
    else:  # an FMU instantiated with fmpy's default callbacks, in the same process
        printLogMessage(env, instance, status, category, message)


_LOGGER = fmi2CallbackLoggerTYPE(_log_message)


def _made_by_pythonfmu(md: Any) -> bool:
    """PythonFMU's runtime departs from FMI 2.0 in two ways that matter here: it passes a
    log message as the printf format itself (a '%' in it is no directive), so its messages
    are taken as they come; and after any doStep that returns False it reports
    fmi2Terminated true, so with it a discarded step is no request to end the simulation."""
    return (md.generationTool or "").startswith("PythonFMU")


class FmuInstance:
    """An FMU instance with named access and error reporting."""

    def __init__(self, instance_name: str, fmu_path: Path) -> None:
        self.name = instance_name
        self.path = Path(fmu_path)
        self.restores = 0  # states restored so far (inputs set before are no longer held)
        #: calls so far that may change what a get answers (any but a get), and of those the
        #: ones that may change more than the outputs of the inputs set (any but a set):
        #: a master that read the values after the last such call need not read them again
        self.changes = 0
        self.moves = 0
        md, unzip_dir = unpacked(str(self.path))
        self.model_description = md
        self.variables = {v.name: v for v in md.modelVariables}
        self.log = FmuLog()
        self._env = next(_ENVIRONMENTS)
        _LOGS[self._env] = self._logged
        self._callbacks = fmi2CallbackFunctions()
        self._callbacks.logger = _LOGGER
        self._callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        self._callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        self._callbacks.componentEnvironment = self._env
        self._pythonfmu = _made_by_pythonfmu(md)
        if not self._pythonfmu:
            from fmpy.logging import addLoggerProxy

            addLoggerProxy(byref(self._callbacks))
        # Every FMI call is noted before it is made (orchestrator.flight): a crash inside
        # the FMU can then be told apart and named by a supervising process.
        self._flight = flight.current()
        self._slot = flight.current().register(instance_name)
        self._flight.words[flight.CALL] = flight.call_word(self._slot, flight.CALLS[1])
        self.fmu = FMU2Slave(
            guid=md.guid,
            unzipDirectory=unzip_dir,
            modelIdentifier=md.coSimulation.modelIdentifier,
            instanceName=instance_name,
        )
        self._flight.words[flight.CALL] = flight.call_word(self._slot, "")
        self.fmu._call = self._noted(self.fmu._call)
        self._alive = self._freeable = False
        try:
            self.fmu.instantiate(callbacks=self._callbacks, loggingOn=True)
        except FmiCallError:
            raise
        except Exception:  # fmpy: "Failed to instantiate model" for a NULL instance
            self.fmu = None
            said = self.last_lines() or "the FMU logged nothing"
            raise RunError(f"fmi2Instantiate returned NULL: {said}", fmu=self.name) from None
        self._alive = True
        self._freeable = True
        # The calls of every macro step, prepared like the transfers below.
        self._do_step = self._function("fmi2DoStep")
        self._get_state = self._function("fmi2GetFMUstate")
        self._set_state = self._function("fmi2SetFMUstate")
        self._free_state = self._function("fmi2FreeFMUstate")

    def _logged(self, status: int, category: str, message: str) -> None:
        self.log.add(status, category, message, self._flight.time)

    def last_lines(self, n: int = LAST_LINES) -> str:
        """The FMU's last ``n`` log messages, oldest first."""
        return self.log.last(n)

    def _failed(self, function: str, status: int, logged: int | None = None) -> FmiCallError:
        """The error of an FMI call that returned ``status``: what the FMU logged during
        it (from message ``logged``) or else its last log lines."""
        said = self.said_since(logged) if logged is not None else ""
        if not said:
            last = self.last_lines()
            said = f"its last log lines: {last}" if last else "the FMU logged nothing"
        name = STATUS_NAMES[status] if 0 <= status < len(STATUS_NAMES) else str(status)
        return FmiCallError(
            f"{function} failed ({name}): {said}", function, status, self._flight.time, self.name
        )

    # -- names ------------------------------------------------------------------------
    def refs(self, names: list[str] | tuple[str, ...]) -> list[int]:
        try:
            return [self.variables[n].valueReference for n in names]
        except KeyError as exc:
            raise RunError(f"has no variable {exc.args[0]!r}", fmu=self.name) from None

    def is_integer(self, name: str) -> bool:
        """Read and written with fmi2Get/SetInteger (Integer and Enumeration)."""
        return self.variables[name].type in ("Integer", "Enumeration")

    def is_boolean(self, name: str) -> bool:
        return self.variables[name].type == "Boolean"

    # -- life cycle -------------------------------------------------------------------
    def initialize(
        self, start: float, stop: float, values: dict[str, float], tolerance: float | None = None
    ) -> None:
        """Set parameters and input start values, then leave initialization mode; a
        ``tolerance`` is the FMU's own integration tolerance (fmi2SetupExperiment)."""
        logged = self.log.count
        try:
            self.fmu.setupExperiment(tolerance=tolerance, startTime=start, stopTime=stop)
            self.fmu.enterInitializationMode()
            for name, value in values.items():
                if self.variables[name].type == "Boolean":
                    self.fmu.setBoolean(self.refs([name]), [bool(value)])
                elif self.is_integer(name):
                    self.fmu.setInteger(self.refs([name]), [int(value)])
                else:
                    self.fmu.setReal(self.refs([name]), [value])
            self.fmu.exitInitializationMode()
        except FmiCallError as exc:
            # pythonfmu's runtime crashes on terminating or freeing an instance whose
            # initialization raised: leave it allocated (a small leak, once per failed run).
            self._alive = self._freeable = False
            said = self.said_since(logged) or f"{exc.function} returned {STATUS_NAMES[exc.status]}"
            raise RunError(f"initialization failed: {said}", start, self.name) from None

    def do_step(self, t: float, h: float) -> None:
        logged = self.log.count
        try:
            self._do_step(self.fmu.component, t, h, fmi2True)
        except FmiCallError as exc:
            self._alive = False
            said = self.said_since(logged) or f"fmi2DoStep returned {STATUS_NAMES[exc.status]}"
            if exc.status == DISCARD and self._asks_to_terminate():
                last = self._last_successful_time(t, h)
                at = f"t = {t:.9g} s" if last is None else f"t = {last:.9g} s (last successful)"
                raise FmuTerminated(
                    f"terminated by FMU {self.name!r} at {at}: {said}", t, self.name, last
                ) from None
            raise RunError(f"doStep failed: {said}", t, self.name) from None

    def _last_successful_time(self, t: float, h: float) -> float | None:
        """fmi2GetRealStatus(fmi2LastSuccessfulTime) after a step that ended the run, if
        it lies past the step start (beyond round-off) and within the step."""
        try:
            last = float(self.fmu.getRealStatus(fmi2LastSuccessfulTime))
        except Exception:  # noqa: BLE001 - the FMU cannot say (fmi2Discard, no function)
            return None
        slack = 1e-9 * h  # the FMU's own sum of its steps differs from ours in the last bits
        return min(last, t + h) if t + slack < last <= t + h + slack else None

    def _asks_to_terminate(self) -> bool:
        """fmi2GetBooleanStatus(fmi2Terminated) after a doStep that returned fmi2Discard:
        the FMU asks to end the simulation (FMI 2.0, 4.2.3).  Not asked of PythonFMU's."""
        if self._pythonfmu:
            return False
        try:
            return self.fmu.getBooleanStatus(fmi2Terminated)
        except RunError:  # the FMU cannot say: a plain discard
            return False

    def said_since(self, index: int) -> str:
        """What the FMU logged since line ``index`` (its reason first, the runtime's after),
        its last lines only."""
        return self.log.said_since(index)

    # -- values -----------------------------------------------------------------------
    def get_real(self, refs: list[int]) -> list[float]:
        return self.fmu.getReal(refs)

    def set_real(self, refs: list[int], values: list[float]) -> None:
        self.fmu.setReal(refs, values)

    def get_integer(self, refs: list[int]) -> list[int]:
        return self.fmu.getInteger(refs)

    # Prepared transfers for the hot path: the reference and value arrays are built once
    # and the FMI function is called directly (fmpy builds both arrays on every call and
    # goes through its call logger; together about half the cost of a small transfer).
    def _noted(self, call: Callable[..., Any]) -> Callable[..., Any]:
        """fmpy's FMI call (``FMU2Slave._call``), noted in the flight record."""
        words, at, slot = self._flight.words, flight.CALL, self._slot
        idle = flight.call_word(slot, "")

        def noted(name: str, *args: Any) -> Any:
            if not name.startswith("fmi2Get"):
                self.changes += 1
                if not name.startswith(_SETS):
                    self.moves += 1
            words[at] = flight.call_word(slot, name)
            try:
                status = call(name, *args)
                if status == 1:  # fmi2Warning
                    self.log.returned_warning(name, self._flight.time)
                return status
            except FMICallException as exc:
                raise self._failed(name, exc.status) from None
            finally:
                words[at] = idle

        return noted

    def _function(self, name: str) -> Callable[..., int]:
        raw = self.fmu._functions[name]
        words, reals, at, at_time = self._flight.words, self._flight.reals, flight.CALL, flight.TIME
        busy, idle = flight.call_word(self._slot, name), flight.call_word(self._slot, "")

        if name == "fmi2DoStep":  # the time too: where the FMU is, should it crash

            def do_step(component: Any, t: float, h: float, last: int) -> int:
                self.changes += 1
                self.moves += 1
                words[at] = busy
                reals[at_time] = t
                status = raw(component, t, h, last)
                words[at] = idle
                if status:
                    if status > 1:
                        raise self._failed(name, status)
                    self.log.returned_warning(name, t)
                reals[at_time] = t + h
                return status

            return do_step

        if name.startswith(_SETS):

            def set_values(*args: Any) -> int:
                self.changes += 1
                words[at] = busy
                status = raw(*args)
                words[at] = idle
                if status:
                    if status > 1:
                        raise self._failed(name, status)
                    self.log.returned_warning(name, self._flight.time)
                return status

            return set_values

        changes = not name.startswith("fmi2Get") and name != "fmi2FreeFMUstate"

        def call(*args: Any) -> int:
            if changes:  # fmi2SetFMUstate
                self.changes += 1
                self.moves += 1
            words[at] = busy
            status = raw(*args)
            words[at] = idle
            if status:
                if status > 1:  # fmi2Discard, fmi2Error, fmi2Fatal (as fmpy raises them)
                    raise self._failed(name, status)
                self.log.returned_warning(name, self._flight.time)
            return status

        return call

    def _transfer(
        self, direction: str, refs: list[int], integer: bool, boolean: bool = False
    ) -> tuple[Any, ...]:
        """(FMI function, instance, value references, count, value buffer) of a prepared
        fmi2Get*/fmi2Set* ``direction`` ("Get" or "Set") of ``refs``."""
        n = len(refs)
        kind = "Boolean" if boolean else "Integer" if integer else "Real"
        function = self._function(f"fmi2{direction}{kind}")
        buf = ((fmi2Boolean if boolean else fmi2Integer if integer else fmi2Real) * n)()
        return function, self.fmu.component, (fmi2ValueReference * n)(*refs), n, buf

    def getter(
        self, refs: list[int], integer: bool = False, boolean: bool = False
    ) -> Callable[[], list]:
        """A function that reads the values of ``refs`` (Integer ones with ``integer``,
        Boolean ones, as 0 or 1, with ``boolean``)."""
        call, component, vr, n, buf = self._transfer("Get", refs, integer, boolean)

        def get() -> list:
            call(component, vr, n, buf)
            return buf[:]

        return get

    def setter(self, refs: list[int], integer: bool = False) -> Callable[[list], None]:
        """A function that sets the values of ``refs`` (Integer ones with ``integer``)."""
        call, component, vr, n, buf = self._transfer("Set", refs, integer)

        def set_values(values: list) -> None:
            buf[:] = values
            call(component, vr, n, buf)

        return set_values

    def derivative_setter(self, refs: list[int]) -> Callable[[list[float]], None]:
        """A function that sets the first time derivatives of the Real inputs ``refs``
        (fmi2SetRealInputDerivatives, order 1): over the next step the FMU ramps each input
        from its value set, u(t) = u + du (t - t_step_start)."""
        n = len(refs)
        call = self._function("fmi2SetRealInputDerivatives")
        vr, order, buf = (
            (fmi2ValueReference * n)(*refs),
            (fmi2Integer * n)(*[1] * n),
            (fmi2Real * n)(),
        )
        component = self.fmu.component

        def set_derivatives(values: list[float]) -> None:
            buf[:] = values
            call(component, vr, n, order, buf)

        return set_derivatives

    def get(self, name: str) -> float:
        ref = self.refs([name])
        return (self.fmu.getInteger(ref) if self.is_integer(name) else self.fmu.getReal(ref))[0]

    # -- state ------------------------------------------------------------------------
    def get_state(self) -> Any:
        state = fmi2FMUstate()
        self._get_state(self.fmu.component, byref(state))
        return state

    def set_state(self, state: Any) -> None:
        self._set_state(self.fmu.component, state)
        self.restores += 1  # its inputs are those of the state now, not the last ones set

    def free_state(self, state: Any) -> None:
        self._free_state(self.fmu.component, byref(state))

    def restore_fault(self, step: Callable[[], None]) -> str | None:
        """Whether restoring a saved state reproduces a step, as a master's rollback needs:
        save the state, take ``step``, read the outputs (and the serialized state, where
        the FMU can serialize), restore, take it again, compare bit for bit.  None where
        both agree, else what differs.  The FMU is left in the saved state."""
        outputs = [v for v in self.model_description.modelVariables if v.causality == "output"]
        reals = [v for v in outputs if v.type == "Real"]
        ints = [v for v in outputs if v.type in ("Integer", "Enumeration", "Boolean")]
        serializes = bool(self.model_description.coSimulation.canSerializeFMUstate)
        time_word = self._flight.reals[flight.TIME]  # the check moves no one's time

        def taken() -> tuple[list[float], list[int], bytes]:
            step()
            real_values = self.fmu.getReal([v.valueReference for v in reals]) if reals else []
            int_values = [
                self.fmu.getBoolean([v.valueReference])[0]
                if v.type == "Boolean"
                else self.fmu.getInteger([v.valueReference])[0]
                for v in ints
            ]
            serialized = b""
            if serializes:
                after = self.get_state()
                try:
                    serialized = self.fmu.serializeFMUstate(after)
                finally:
                    self.free_state(after)
            return real_values, int_values, serialized

        saved = self.get_state()
        try:
            first = taken()
            self.set_state(saved)
            second = taken()
        finally:
            self.set_state(saved)
            self.free_state(saved)
            self._flight.reals[flight.TIME] = time_word
        for v, a, b in zip(reals, first[0], second[0], strict=True):
            if struct.pack("<d", a) != struct.pack("<d", b):
                return f"output {v.name} differs by {b - a:.3g} ({a!r} then {b!r})"
        for v, a, b in zip(ints, first[1], second[1], strict=True):
            if a != b:
                return f"output {v.name} differs ({a} then {b})"
        if first[2] != second[2]:
            return "its serialized state differs"
        return None

    def close(self) -> None:
        if self.fmu is None:
            return
        try:
            if self._alive:
                self.fmu.terminate()
        except RunError:
            pass
        # Free the instance but keep the shared library loaded: pythonfmu's runtime embeds
        # the interpreter and does not survive being unloaded and loaded again in a process.
        if self._freeable:
            self.fmu.fmi2FreeInstance(self.fmu.component)
        self.fmu = None
        _LOGS.pop(self._env, None)
