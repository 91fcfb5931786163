"""Which FMI call is under way, kept where a supervising process can read it after a crash.

An FMU that crashes (a segfault, ``abort()``, ``exit()``) ends the process that called it
before any Python code there can say where it was.  So before each FMI call the calling
process writes two integers, the FMU instance and the function, and clears the function
once the call has returned; doStep also writes the time it starts from.  The record lives
in shared memory once ``share`` has been called (``orchestrator.supervisor`` does, before
it forks the run), and the supervisor reads it when the run's process has died.  Three
assignments to a ctypes structure cost about 0.1 µs, against 1-30 µs for the FMI call
(README, "A crashing FMU").

The run also announces itself here (scene, results directory), so that the supervisor
knows where to write the summary of a run that crashed.
"""

from __future__ import annotations

import ctypes
import json
import mmap
from typing import Any

from fmpy.fmi2 import FMU2Slave

#: FMI functions by number; 0 is "none under way", 1 the loading of the shared library.
CALLS: tuple[str, ...] = (
    "",
    "loading its shared library",
    *sorted(n for n in dir(FMU2Slave) if n.startswith("fmi2")),
)
CALL_INDEX = {name: i for i, name in enumerate(CALLS)}

MAX_INSTANCES = 256  # instance names kept (a study's process makes many: slots are reused)
NAME_BYTES = 256
ANNOUNCEMENT_BYTES = 1 << 16


class Record(ctypes.Structure):
    _fields_ = [
        ("instance", ctypes.c_int32),  # slot of the FMU instance called last
        ("call", ctypes.c_int32),  # CALLS index of the call under way, 0 if none
        ("time", ctypes.c_double),  # where the last doStep started, or ended once it returned
        ("finished", ctypes.c_int32),  # 1 once the run's process has ended its work itself
        ("code", ctypes.c_int32),  # its exit code then
        ("instances", ctypes.c_int32),  # instance slots handed out
        ("announced", ctypes.c_int32),  # length of the announcement (JSON), 0 if none
    ]


_NAMES_AT = 64
_ANNOUNCEMENT_AT = _NAMES_AT + MAX_INSTANCES * NAME_BYTES
_SIZE = _ANNOUNCEMENT_AT + ANNOUNCEMENT_BYTES


class Flight:
    """The record and the tables beside it, in one buffer."""

    def __init__(self, buffer: Any) -> None:
        self.buffer = buffer
        self.record = Record.from_buffer(buffer)

    def register(self, name: str) -> int:
        """A slot for FMU instance ``name`` (its name is written once, here)."""
        slot = self.record.instances % MAX_INSTANCES
        self.record.instances += 1
        data = name.encode("utf-8", "replace")[: NAME_BYTES - 1]
        at = _NAMES_AT + slot * NAME_BYTES
        self.buffer[at : at + NAME_BYTES] = data.ljust(NAME_BYTES, b"\0")
        return slot

    def instance_name(self, slot: int) -> str:
        at = _NAMES_AT + (slot % MAX_INSTANCES) * NAME_BYTES
        return bytes(self.buffer[at : at + NAME_BYTES]).split(b"\0", 1)[0].decode("utf-8")

    def announce(self, info: dict[str, Any]) -> None:
        data = json.dumps(info, default=str).encode("utf-8")
        if len(data) > ANNOUNCEMENT_BYTES:  # very many FMUs: keep what names the run
            info = {k: info[k] for k in ("scene", "output_dir") if k in info}
            data = json.dumps(info, default=str).encode("utf-8")[:ANNOUNCEMENT_BYTES]
        self.record.announced = 0
        self.buffer[_ANNOUNCEMENT_AT : _ANNOUNCEMENT_AT + len(data)] = data
        self.record.announced = len(data)

    def announcement(self) -> dict[str, Any] | None:
        n = self.record.announced
        if not n:
            return None
        try:
            return json.loads(bytes(self.buffer[_ANNOUNCEMENT_AT : _ANNOUNCEMENT_AT + n]))
        except ValueError:
            return None

    def finish(self, code: int) -> None:
        self.record.code = code
        self.record.finished = 1

    def call_under_way(self) -> tuple[str, str] | None:
        """(FMU instance, FMI call) under way, None if no FMI call was."""
        r = self.record
        if r.call <= 0 or r.call >= len(CALLS) or not r.instances:
            return None
        return self.instance_name(r.instance), CALLS[r.call]

    def last_instance(self) -> str | None:
        return self.instance_name(self.record.instance) if self.record.instances else None


_current = Flight(bytearray(_SIZE))  # private until shared


def current() -> Flight:
    """The flight record of this process (FMU instances take it when they are made)."""
    return _current


def share() -> Flight:
    """A fresh record in anonymous shared memory: a process forked after this call writes
    where this one reads."""
    global _current
    _current = Flight(mmap.mmap(-1, _SIZE))
    return _current


def announce_run(scene: Any, output_dir: Any) -> None:
    """Say which run this process is making (read only if it crashes)."""
    _current.record.time = scene.start
    _current.announce(
        {
            "scene": scene.name,
            "output_dir": str(output_dir),
            "scene_file": str(scene.path),
            "start": scene.start,
            "fmus": {name: str(spec.path) for name, spec in scene.fmus.items()},
        }
    )
