"""Which FMI call is under way, kept where a supervising process can read it after a crash.

An FMU that crashes (a segfault, ``abort()``, ``exit()``) ends the process that called it
before any Python code there can say where it was.  So before each FMI call the calling
process writes which FMU instance calls which function, and clears the function once the
call has returned; doStep also writes the time it starts from.  The record lives in shared
memory once ``share`` has been called (``orchestrator.supervisor`` does, before it forks
the run), and the supervisor reads it when the run's process has died.  That is two stores
into a memoryview per call (four for doStep), against 1-30 µs for the FMI call itself
(docs/cli.md, "A crashing FMU").

The run also announces itself here (scene, results directory, the longest an FMI call may
take), so that the supervisor knows where to write the summary of a run that crashed, and
when a call that does not return is to be ended (``CallWatch``).
"""

from __future__ import annotations

import json
import mmap
from dataclasses import dataclass
from typing import Any

from fmpy.fmi2 import FMU2Slave

from orchestrator.master_settings import CALL_TIMEOUT

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

# The record: int64 words and one float64 word, stored through memoryviews (an item store
# costs about half of a ctypes field's).  Word CALL holds (instance slot << 16 | call
# index): one store before a call, one after it (the slot alone: no call under way).
CALL, FINISHED, CODE, INSTANCES, ANNOUNCED = 0, 2, 3, 4, 5  # int64 words
TIME = 1  # float64 word: where the last doStep started, or where it ended once it returned
LIMIT = 6  # float64 word: the longest an FMI call may take [s] (0: no limit)
WRITTEN = 7  # int64 word: 1 once the run has written its summary (its FMUs still to close)
_NAMES_AT = 64
_ANNOUNCEMENT_AT = _NAMES_AT + MAX_INSTANCES * NAME_BYTES
_SIZE = _ANNOUNCEMENT_AT + ANNOUNCEMENT_BYTES


def call_word(slot: int, call: str) -> int:
    """The CALL word of instance ``slot`` calling ``call`` ("" for none)."""
    return slot << 16 | CALL_INDEX.get(call, 0)


class Flight:
    """The record and the tables beside it, in one buffer."""

    def __init__(self, buffer: Any) -> None:
        self.buffer = buffer
        self.words = memoryview(buffer)[:_NAMES_AT].cast("q")
        self.reals = memoryview(buffer)[:_NAMES_AT].cast("d")

    def register(self, name: str) -> int:
        """A slot for FMU instance ``name`` (its name is written once, here)."""
        slot = self.words[INSTANCES] % MAX_INSTANCES
        self.words[INSTANCES] += 1
        data = name.encode("utf-8", "replace")[: NAME_BYTES - 1]
        at = _NAMES_AT + slot * NAME_BYTES
        self.buffer[at : at + NAME_BYTES] = data.ljust(NAME_BYTES, b"\0")
        return slot

    def instance_name(self, slot: int) -> str:
        at = _NAMES_AT + (slot % MAX_INSTANCES) * NAME_BYTES
        raw = bytes(self.buffer[at : at + NAME_BYTES]).split(b"\0", 1)[0]
        return raw.decode("utf-8", "replace")

    def announce(self, info: dict[str, Any]) -> None:
        data = json.dumps(info, default=str).encode("utf-8")
        if len(data) > ANNOUNCEMENT_BYTES:  # very many FMUs: keep what names the run
            info = {k: info[k] for k in ("scene", "output_dir") if k in info}
            data = json.dumps(info, default=str).encode("utf-8")[:ANNOUNCEMENT_BYTES]
        self.words[ANNOUNCED] = 0
        self.buffer[_ANNOUNCEMENT_AT : _ANNOUNCEMENT_AT + len(data)] = data
        self.words[ANNOUNCED] = len(data)

    def announcement(self) -> dict[str, Any] | None:
        n = self.words[ANNOUNCED]
        if not n:
            return None
        try:
            return json.loads(bytes(self.buffer[_ANNOUNCEMENT_AT : _ANNOUNCEMENT_AT + n]))
        except ValueError:
            return None

    def reset(self) -> None:
        """Ready for the next run of the same process (a study's worker)."""
        for word in (CALL, FINISHED, CODE, INSTANCES, ANNOUNCED, WRITTEN):
            self.words[word] = 0
        self.reals[TIME] = self.reals[LIMIT] = 0.0

    @property
    def summary_written(self) -> bool:
        return bool(self.words[WRITTEN])

    @property
    def call_timeout(self) -> float:
        return self.reals[LIMIT]

    def finish(self, code: int) -> None:
        self.words[CODE] = code
        self.words[FINISHED] = 1

    @property
    def finished(self) -> bool:
        return bool(self.words[FINISHED])

    @property
    def code(self) -> int:
        return self.words[CODE]

    @property
    def time(self) -> float:
        return self.reals[TIME]

    def call_under_way(self) -> tuple[str, str] | None:
        """(FMU instance, FMI call) under way, None if no FMI call was."""
        word = self.words[CALL]
        call = word & 0xFFFF
        if call <= 0 or call >= len(CALLS) or not self.words[INSTANCES]:
            return None
        return self.instance_name(word >> 16), CALLS[call]

    def last_instance(self) -> str | None:
        """The FMU instance called last, None if none was."""
        if not self.words[INSTANCES]:
            return None
        return self.instance_name(self.words[CALL] >> 16)


@dataclass(frozen=True)
class StuckCall:
    """An FMI call under way for longer than the run's limit."""

    fmu: str
    call: str
    time: float  # where the FMU was: the start of its doStep, or the end of the last one
    limit: float  # [s]

    def describe(self) -> str:
        return (
            f"FMU {self.fmu!r} did not return from {self.call} within {self.limit:g} s "
            f"(master.call_timeout) at t = {self.time:.9g} s"
        )


class CallWatch:
    """Watches a record from another process: a call is stuck when the record has shown it
    under way, unchanged (same instance, function and time), at every look for longer than
    the limit.  Looking every 0.1 s, calls of one function that return and start again
    unseen for a whole minute are as good as one call that never returns."""

    def __init__(self, record: Flight) -> None:
        self.record = record
        self.seen: tuple[int, float] | None = None
        self.since = 0.0

    def stuck(self, now: float) -> StuckCall | None:
        """The call under way if it has been for longer than the limit (``now``: a
        monotonic clock [s])."""
        word, t, limit = self.record.words[CALL], self.record.time, self.record.call_timeout
        if word & 0xFFFF == 0:  # no call under way
            self.seen = None
            return None
        if (word, t) != self.seen:
            self.seen, self.since = (word, t), now
            return None
        if limit <= 0.0 or now - self.since <= limit:
            return None
        under_way = self.record.call_under_way()
        if under_way is None:
            return None
        return StuckCall(under_way[0], under_way[1], t, limit)


_current = Flight(bytearray(_SIZE))  # private until shared


def current() -> Flight:
    """The flight record of this process (FMU instances take it when they are made)."""
    return _current


def share() -> Flight:
    """A fresh record in anonymous shared memory: a process forked after this call writes
    where this one reads."""
    use(shared())
    return _current


def shared() -> Flight:
    """A fresh record in anonymous shared memory, for a process about to be forked (which
    takes it with ``use``)."""
    return Flight(mmap.mmap(-1, _SIZE))


def use(record: Flight) -> None:
    """Make ``record`` this process's record."""
    global _current
    _current = record


def summary_written() -> None:
    """Say that the run's summary is written (only closing its FMUs is left)."""
    _current.words[WRITTEN] = 1


def announce_run(scene: Any, output_dir: Any) -> None:
    """Say which run this process is making (read only if it crashes or hangs)."""
    _current.reals[TIME] = scene.start
    _current.words[WRITTEN] = 0
    settings = getattr(getattr(scene, "master", None), "settings", None)
    _current.reals[LIMIT] = getattr(settings, "call_timeout", CALL_TIMEOUT)
    _current.announce(
        {
            "scene": scene.name,
            "output_dir": str(output_dir),
            "scene_file": str(scene.path),
            "start": scene.start,
            "fmus": {name: str(spec.path) for name, spec in scene.fmus.items()},
        }
    )
