"""One instantiated co-simulation FMU, driven through fmpy.

Names are resolved to value references once; the hot-path calls (set inputs, do_step,
get outputs, get/set state) take prepared reference lists.  Messages the FMU logs are
kept, so a failed step can say what the FMU said.
"""

from __future__ import annotations

import atexit
import hashlib
import shutil
from collections.abc import Callable
from ctypes import byref
from pathlib import Path
from typing import Any

from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import (  # the allocators fmpy itself hands to FMUs, and its value types
    FMU2Slave,
    calloc,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
    fmi2FMUstate,
    fmi2Integer,
    fmi2Real,
    fmi2True,
    fmi2ValueReference,
    free,
)

from orchestrator import flight
from orchestrator.errors import RunError

_UNPACKED: dict[str, tuple[Any, str]] = {}


def _unpacked(fmu_path: str) -> tuple[Any, str]:
    """Model description and unzip directory, once per FMU file and process."""
    if fmu_path not in _UNPACKED:
        _UNPACKED[fmu_path] = (read_model_description(fmu_path), extract(fmu_path))
    return _UNPACKED[fmu_path]


@atexit.register
def _remove_unpacked(keep: frozenset[str] = frozenset()) -> None:
    """Remove the unzip directories, but those of the FMU files in ``keep``."""
    for fmu_path, (_, directory) in _UNPACKED.items():
        if fmu_path not in keep:
            shutil.rmtree(directory, ignore_errors=True)


def unpacked_files() -> frozenset[str]:
    """FMU files unpacked by this process so far (a forked child shares their folders)."""
    return frozenset(_UNPACKED)


def file_sha256(path: Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


class FmuInstance:
    """An FMU instance with named access and error reporting."""

    def __init__(self, instance_name: str, fmu_path: Path) -> None:
        self.name = instance_name
        self.path = Path(fmu_path)
        md, unzip_dir = _unpacked(str(self.path))
        self.model_description = md
        self.variables = {v.name: v for v in md.modelVariables}
        self.messages: list[str] = []
        self._callbacks = fmi2CallbackFunctions()
        self._callbacks.logger = fmi2CallbackLoggerTYPE(self._log)
        self._callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        self._callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        # Every FMI call is noted before it is made (orchestrator.flight): a crash inside
        # the FMU can then be told apart and named by a supervising process.
        self._flight = flight.current().record
        self._slot = flight.current().register(instance_name)
        self._flight.instance, self._flight.call = self._slot, flight.CALL_INDEX[flight.CALLS[1]]
        self.fmu = FMU2Slave(
            guid=md.guid,
            unzipDirectory=unzip_dir,
            modelIdentifier=md.coSimulation.modelIdentifier,
            instanceName=instance_name,
        )
        self._flight.call = 0
        self.fmu._call = self._noted(self.fmu._call)
        self.fmu.instantiate(callbacks=self._callbacks, loggingOn=True)
        self._alive = True
        self._freeable = True
        # The calls of every macro step, prepared like the transfers below.
        self._do_step = self._function("fmi2DoStep")
        self._get_state = self._function("fmi2GetFMUstate")
        self._set_state = self._function("fmi2SetFMUstate")
        self._free_state = self._function("fmi2FreeFMUstate")

    def _log(self, env: Any, instance: bytes, status: int, category: bytes, message: bytes) -> None:
        self.messages.append(message.decode("utf-8", "replace") if message else "")

    # -- names ------------------------------------------------------------------------
    def refs(self, names: list[str] | tuple[str, ...]) -> list[int]:
        try:
            return [self.variables[n].valueReference for n in names]
        except KeyError as exc:
            raise RunError(f"has no variable {exc.args[0]!r}", fmu=self.name) from None

    def is_integer(self, name: str) -> bool:
        """Read and written with fmi2Get/SetInteger (Integer and Enumeration)."""
        return self.variables[name].type in ("Integer", "Enumeration")

    # -- life cycle -------------------------------------------------------------------
    def initialize(self, start: float, stop: float, values: dict[str, float]) -> None:
        """Set parameters and input start values, then leave initialization mode."""
        logged = len(self.messages)
        try:
            self.fmu.setupExperiment(startTime=start, stopTime=stop)
            self.fmu.enterInitializationMode()
            for name, value in values.items():
                if self.variables[name].type == "Boolean":
                    self.fmu.setBoolean(self.refs([name]), [bool(value)])
                elif self.is_integer(name):
                    self.fmu.setInteger(self.refs([name]), [int(value)])
                else:
                    self.fmu.setReal(self.refs([name]), [value])
            self.fmu.exitInitializationMode()
        except FMICallException as exc:
            # pythonfmu's runtime crashes on terminating or freeing an instance whose
            # initialization raised: leave it allocated (a small leak, once per failed run).
            self._alive = self._freeable = False
            raise RunError(
                f"initialization failed: {self.said_since(logged) or exc}", start, self.name
            ) from None

    def do_step(self, t: float, h: float) -> None:
        logged = len(self.messages)
        try:
            self._flight.time = t
            self._do_step(self.fmu.component, t, h, fmi2True)
            self._flight.time = t + h
        except FMICallException as exc:
            self._alive = False
            raise RunError(
                f"doStep failed: {self.said_since(logged) or exc}", t, self.name
            ) from None

    def said_since(self, index: int) -> str:
        """What the FMU logged since ``index`` (its reason first, the runtime's after)."""
        return "; ".join(m.strip() for m in self.messages[index:] if m.strip())

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
        record, slot, index = self._flight, self._slot, flight.CALL_INDEX

        def noted(name: str, *args: Any) -> Any:
            record.instance, record.call = slot, index.get(name, 0)
            try:
                return call(name, *args)
            finally:
                record.call = 0

        return noted

    def _function(self, name: str) -> Callable[..., int]:
        raw = self.fmu._functions[name]
        record, slot, index = self._flight, self._slot, flight.CALL_INDEX[name]

        def call(*args: Any) -> int:
            record.instance = slot
            record.call = index
            status = raw(*args)
            record.call = 0
            if status > 1:  # fmi2Discard, fmi2Error, fmi2Fatal (as fmpy raises them)
                raise FMICallException(function=name, status=status)
            return status

        return call

    def _transfer(self, direction: str, refs: list[int], integer: bool) -> tuple[Any, ...]:
        """(FMI function, instance, value references, count, value buffer) of a prepared
        fmi2Get*/fmi2Set* ``direction`` ("Get" or "Set") of ``refs``."""
        n = len(refs)
        function = self._function(f"fmi2{direction}{'Integer' if integer else 'Real'}")
        buf = ((fmi2Integer if integer else fmi2Real) * n)()
        return function, self.fmu.component, (fmi2ValueReference * n)(*refs), n, buf

    def getter(self, refs: list[int], integer: bool = False) -> Callable[[], list]:
        """A function that reads the values of ``refs`` (Integer ones with ``integer``)."""
        call, component, vr, n, buf = self._transfer("Get", refs, integer)

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

    def free_state(self, state: Any) -> None:
        self._free_state(self.fmu.component, byref(state))

    def close(self) -> None:
        if self.fmu is None:
            return
        try:
            if self._alive:
                self.fmu.terminate()
        except FMICallException:
            pass
        # Free the instance but keep the shared library loaded: pythonfmu's runtime embeds
        # the interpreter and does not survive being unloaded and loaded again in a process.
        if self._freeable:
            self.fmu.fmi2FreeInstance(self.fmu.component)
        self.fmu = None
