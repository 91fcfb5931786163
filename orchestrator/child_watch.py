"""Watching a forked process that runs FMUs: how it ended, and the summary of its run.

A process that calls an FMU can be ended by it (a segfault, ``abort()``, ``exit()``),
stopped by it (an FMU that raises SIGSTOP) or held by it for ever (an FMI call in an
endless loop, where no signal handler of the process gets to run).  The parent watches it
without blocking (``ChildWatch.poll``): a stopped child is killed, an FMI call under way
for longer than the run's ``master.call_timeout`` (``flight.CallWatch``) is ended by
killing the child, and a child asked to stop by a signal that has not ended within
``SIGNAL_GRACE`` is killed too.  What happened is then written into the run's
``summary.json`` from the flight record (``ended_summary``): status "crashed", "timed out"
or "interrupted", the FMU, the call and the time reached.

The child ends with its parent (``die_with_parent``): SIGTERM when the parent dies (a run
then stops at its next step and keeps its data) and, should it be stuck in an FMI call,
SIGALRM's default action ``SIGNAL_GRACE`` later.
"""

from __future__ import annotations

import contextlib
import ctypes
import json
import os
import signal
import sys
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from orchestrator import flight
from orchestrator.interrupt import signal_name
from orchestrator.summary_file import write_summary

CRASHED, TIMED_OUT, INTERRUPTED = "crashed", "timed out", "interrupted"
#: How long a child asked to stop by SIGINT/SIGTERM (or orphaned) has to reach its next
#: step boundary before it is killed [s]: a step of any scene takes far less.
SIGNAL_GRACE = 5.0
POLL = 0.05  # s between looks at a running child


@dataclass
class Ending:
    """How a watched child ended."""

    status: int  # its wait status
    stopped_by: int | None = None  # it was stopped by this signal, then killed
    stuck: flight.StuckCall | None = None  # its FMI call ran over the limit: killed
    interrupted_by: int | None = None  # asked to stop by this signal, it was killed
    at_once: bool = False  # ... by a third signal (else: after SIGNAL_GRACE)


class ChildWatch:
    """A forked child and its flight record, looked at without blocking."""

    def __init__(self, pid: int, record: flight.Flight) -> None:
        self.pid, self.record = pid, record
        self.calls = flight.CallWatch(record)
        self.stopped_by: int | None = None
        self.stuck: flight.StuckCall | None = None
        self.asked: tuple[int, float] | None = None  # (signal, when) it was asked to stop
        self.interrupted_by: int | None = None
        self.at_once = False

    def ask_to_stop(self, signum: int) -> None:
        """Pass ``signum`` on; the child is killed if it has not ended SIGNAL_GRACE later."""
        if self.asked is None:
            self.asked = (signum, time.monotonic())
        with contextlib.suppress(ProcessLookupError):
            os.kill(self.pid, signum)

    def kill(self, interrupted_by: int | None = None, at_once: bool = False) -> None:
        if interrupted_by is not None and self.interrupted_by is None:
            self.interrupted_by, self.at_once = interrupted_by, at_once
        with contextlib.suppress(ProcessLookupError):
            os.kill(self.pid, signal.SIGKILL)

    def poll(self) -> int | None:
        """The child's wait status once it has ended, else None (having killed it if it
        stopped, hangs in an FMI call, or ignores a signal)."""
        try:
            pid, status = os.waitpid(self.pid, os.WNOHANG | os.WUNTRACED)
        except ChildProcessError:
            return 0
        if pid and os.WIFSTOPPED(status):
            if self.stopped_by is None:
                self.stopped_by = os.WSTOPSIG(status)
            self.kill()
            return None
        if pid:
            return status
        now = time.monotonic()
        if self.stuck is None and self.interrupted_by is None:
            self.stuck = self.calls.stuck(now)
            if self.stuck is not None:
                self.kill()
        if self.asked is not None and now - self.asked[1] > SIGNAL_GRACE:
            self.kill(interrupted_by=self.asked[0])
        return None

    def wait(self) -> int:
        """Poll until the child has ended; its wait status."""
        while (status := self.poll()) is None:
            time.sleep(POLL)
        return status

    def ending(self, status: int) -> Ending:
        return Ending(status, self.stopped_by, self.stuck, self.interrupted_by, self.at_once)


def crash_cause(status: int) -> str:
    """What ended a process, from its wait status."""
    if os.WIFSIGNALED(status):
        sig = os.WTERMSIG(status)
        return f"killed by {signal_name(sig)} (signal {sig})"
    if os.WIFEXITED(status):
        return f"exit code {os.WEXITSTATUS(status)} (an exit() before the run had ended)"
    return f"wait status {status}"


def outcome(record: flight.Flight, ending: Ending) -> tuple[str, str, dict[str, Any]]:
    """(status, message, crash entry) of a run whose process ended before finishing."""
    status = ending.status
    under_way = record.call_under_way()
    t = record.time
    if under_way is not None:
        fmu, call = under_way
    else:
        fmu, call = record.last_instance(), None
    cause = crash_cause(status)
    if ending.stopped_by is not None:
        cause = (
            f"stopped by {signal_name(ending.stopped_by)} (signal {ending.stopped_by}), then killed"
        )
    crash: dict[str, Any] = {
        "cause": cause,
        "signal": os.WTERMSIG(status) if os.WIFSIGNALED(status) else None,
        "exit_code": os.WEXITSTATUS(status) if os.WIFEXITED(status) else None,
        "fmu": fmu,
        "call": call,
    }
    if ending.stopped_by is not None:
        crash["stopped_by"] = ending.stopped_by
    if ending.interrupted_by is not None:
        name = signal_name(ending.interrupted_by)
        how = "a third signal" if ending.at_once else f"it did not stop within {SIGNAL_GRACE:g} s"
        where = f"FMU {fmu!r} was in {call}" if call else "the run was between FMI calls"
        crash["cause"] = f"killed after {name}: {how}"
        return (
            INTERRUPTED,
            f"interrupted by {name}: {where} at t = {t:.9g} s and {how}: killed; "
            "everything up to there is kept",
            crash,
        )
    if ending.stuck is not None:
        crash["cause"] = f"no return within {ending.stuck.limit:g} s: killed"
        crash["call_timeout"] = ending.stuck.limit
        return TIMED_OUT, f"{ending.stuck.describe()}: killed", crash
    if under_way is not None:
        where = f"FMU {fmu!r} crashed in {call}"
    elif fmu is not None:
        where = f"the run crashed outside any FMI call (last FMU called: {fmu!r})"
    else:
        where = "the run crashed before any FMU was loaded"
    return CRASHED, f"{where} at t = {t:.9g} s: {cause}", crash


def ended_summary(record: flight.Flight, ending: Ending, wall_time: float) -> dict[str, Any] | None:
    """The summary of the run the record announces (None if none was announced yet)."""
    run = record.announcement()
    if run is None:
        return None
    status, message, crash = outcome(record, ending)
    if record.summary_written:  # it crashed closing its FMUs: the results are whole
        written = _written_summary(Path(run["output_dir"]))
        if written is not None:
            note = f"after the run ended: {message}"
            written["notes"] = [*written.get("notes", []), note]
            return {**written, "crash": crash, "output_dir": run["output_dir"]}
    return {
        "scene": run.get("scene"),
        "status": status,
        "message": message,
        "time_reached": record.time,
        "crash": crash,
        "headline": {},
        "accuracy": {},
        "notes": [
            f"the run's process was {'stopped' if status != CRASHED else 'ended'} in it: the "
            "series hold every step completed before; no headline quantities, analyses or "
            "reference comparison"
        ],
        "stats": {"wall_time": wall_time},
        "metadata": {k: run[k] for k in ("scene_file", "fmus") if k in run},
        "output_dir": run["output_dir"],
    }


def _written_summary(out: Path) -> dict[str, Any] | None:
    try:
        summary = json.loads((out / "summary.json").read_text())
    except (OSError, ValueError):
        return None
    return summary if isinstance(summary, dict) else None


def write_ended_summary(summary: dict[str, Any]) -> bool:
    """``summary.json`` written whole (temporary file, then renamed), under the lock of the
    results directory the dead run held."""
    from orchestrator.output_lock import OutputLock

    summary = dict(summary)
    out = Path(summary.pop("output_dir"))
    try:
        with OutputLock(out):
            write_summary(out, summary)
    except Exception as exc:  # noqa: BLE001 - the ending is reported even so
        print(f"error: cannot write {out / 'summary.json'}: {exc}", file=sys.stderr)
        return False
    return True


# -- ending with the parent -------------------------------------------------------------
_DEATH_PIPE: tuple[int, int] | None = None


def prepare_children() -> None:
    """Before forking children that must end with this process: the pipe whose write end
    only this process keeps (its end of file tells a child that this process is gone)."""
    global _DEATH_PIPE
    if _DEATH_PIPE is None:
        _DEATH_PIPE = os.pipe()


def die_with_parent(parent: int) -> None:
    """In a child forked after ``prepare_children``: SIGTERM when the parent dies (Linux),
    and SIGALRM's default action (the end) SIGNAL_GRACE later, even in an FMI call that
    never returns."""
    global _DEATH_PIPE
    if _DEATH_PIPE is not None:
        read_end, write_end = _DEATH_PIPE
        _DEATH_PIPE = None
        os.close(write_end)
        threading.Thread(target=_await_parent_death, args=(read_end,), daemon=True).start()
    if not sys.platform.startswith("linux"):
        return
    with contextlib.suppress(Exception):
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, signal.SIGTERM, 0, 0, 0)  # PR_SET_PDEATHSIG
        if os.getppid() != parent:  # it died before the call
            os.kill(os.getpid(), signal.SIGTERM)


def _await_parent_death(read_end: int) -> None:
    with contextlib.suppress(OSError):
        while os.read(read_end, 1):
            pass
    # SIGALRM has its default action (no handler is installed for it): the process ends.
    signal.alarm(max(1, round(SIGNAL_GRACE)))
