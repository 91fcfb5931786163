"""A run in a child process, so that an FMU that crashes cannot take the run's data along.

``mechcosim run`` forks: the child runs the scene exactly as an unsupervised run would
(its own signal guard, its own messages and exit code); the parent waits, forwards
SIGINT/SIGTERM to it, and if the child dies without having finished its work (killed by
a signal, or ended by an FMU's ``exit()``) writes ``summary.json`` with status "crashed",
the signal or exit code, the FMU and FMI call under way and the time reached, read from
the flight record the child kept in shared memory (``orchestrator.flight``).  The CSV
files are written a row at a time (``Recorder``), so they hold every completed step.

The child gets its own process group: a Ctrl-C at the terminal then reaches the parent
only, which forwards it, so the run sees each signal once, as it did unsupervised.
"""

from __future__ import annotations

import codecs
import contextlib
import ctypes
import faulthandler
import io
import os
import signal
import sys
import threading
import time
import traceback
from collections.abc import Callable
from pathlib import Path
from typing import Any, TextIO

from orchestrator import flight
from orchestrator.interrupt import SIGNALS, SignalGuard, signal_name
from orchestrator.summary_file import write_summary

CRASHED = "crashed"


def can_supervise() -> bool:
    """Forking is there, and this is the main thread (only it can forward signals)."""
    return hasattr(os, "fork") and threading.current_thread() is threading.main_thread()


def supervised(work: Callable[[], int], guard: SignalGuard) -> int:
    """Run ``work`` (returning an exit code) in a child process; its exit code, or 1 for a
    crash (reported and summarized here).  ``guard``: the signal guard installed around
    this call; the child inherits it as it stands."""
    record = flight.share()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    relays = [_Relay(stream, fd) for stream, fd in ((sys.stdout, 1), (sys.stderr, 2))]
    signals_before = guard.count
    started = time.perf_counter()
    parent = os.getpid()
    pid = os.fork()
    if pid == 0:  # the run
        _child(work, record, relays, parent)
    for relay in relays:
        relay.parent()
    forwarder = _Forwarder(pid, guard)
    with forwarder.installed(signals_before):
        status = _wait(pid)
    for relay in relays:
        relay.join()
    if record.finished:
        return record.code
    if forwarder.killed is not None:  # the third signal: ended at once, as unsupervised
        return 128 + forwarder.killed
    return _report_crash(record, status, time.perf_counter() - started)


def _child(
    work: Callable[[], int], record: flight.Flight, relays: list[_Relay], parent: int
) -> None:
    from orchestrator.fmu_instance import _remove_unpacked, unpacked_files

    code = 1
    inherited = unpacked_files()  # the parent's, left to it
    # A crash is reported by the parent, from the flight record (the FMU, its FMI call, the
    # time, the signal): an inherited fault handler (``python -X faulthandler``, pytest's)
    # would add the child's Python stack, which at an FMU's crash is the master's call.
    faulthandler.disable()
    try:
        os.setpgid(0, 0)
        _end_with_parent(parent)
        _exit_at_once_on_exit()
        for relay in relays:
            relay.child()
        code = work()
    except BaseException:  # noqa: BLE001 - the child must end here, whatever happened
        traceback.print_exc()
    finally:
        for sig in SIGNALS:  # the work is done and its exit code decided
            signal.signal(sig, signal.SIG_IGN)
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(Exception):
                stream.flush()
        record.finish(code)
        with contextlib.suppress(Exception):
            _remove_unpacked(keep=inherited)
        os._exit(code)


def _end_with_parent(parent: int) -> None:
    """Linux: a SIGTERM when the parent dies (the run then stops at a step boundary and
    keeps its data), rather than running on as an orphan."""
    if not sys.platform.startswith("linux"):
        return
    with contextlib.suppress(Exception):
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, signal.SIGTERM, 0, 0, 0)  # PR_SET_PDEATHSIG
        if os.getppid() != parent:  # it died before the call
            os.kill(os.getpid(), signal.SIGTERM)


_ON_EXIT: list[Any] = []  # the handler, kept alive


def _exit_at_once_on_exit() -> None:
    """glibc: an ``exit()`` called by an FMU ends the child at once with its status.  The
    exit handlers registered before (libraries' destructors, an embedded interpreter's)
    would otherwise run in a process that is in the middle of an FMI call, and can crash
    it, hiding the FMU's exit code behind a signal."""
    if not sys.platform.startswith("linux"):
        return
    with contextlib.suppress(Exception):
        libc = ctypes.CDLL(None)
        handler = ctypes.CFUNCTYPE(None, ctypes.c_int, ctypes.c_void_p)(
            lambda status, arg: os._exit(status & 0xFF)
        )
        if libc.on_exit(handler, None) == 0:
            _ON_EXIT.append(handler)


def _wait(pid: int) -> int:
    while True:
        try:
            _, status = os.waitpid(pid, 0)  # retried after a signal's handler (PEP 475)
            return status
        except ChildProcessError:
            return 0


class _Forwarder:
    """While the child runs: SIGINT/SIGTERM go to it.  The third ends it at once (SIGKILL),
    as the run's own guard would end an unsupervised run (an FMU call that never returns
    cannot run the child's handler)."""

    def __init__(self, pid: int, guard: SignalGuard) -> None:
        self.pid, self.guard = pid, guard
        self.killed: int | None = None

    def handle(self, signum: int, frame: object) -> None:
        if self.guard.signum is None:
            self.guard.signum = signum
        self.guard.count += 1
        with contextlib.suppress(ProcessLookupError):
            if self.guard.count >= 3:
                self.killed = self.guard.signum
                os.kill(self.pid, signal.SIGKILL)
            else:
                os.kill(self.pid, signum)

    @contextlib.contextmanager
    def installed(self, signals_before: int):  # noqa: ANN201 - a context manager
        previous = {}
        for sig in SIGNALS:
            current = signal.getsignal(sig)
            if current is signal.SIG_IGN:
                continue
            previous[sig] = current
            signal.signal(sig, self.handle)
        # A signal between the fork and here reached only this process: pass it on.
        for _ in range(self.guard.count - signals_before):
            with contextlib.suppress(ProcessLookupError):
                os.kill(self.pid, self.guard.signum or signal.SIGTERM)
        try:
            yield
        finally:
            for sig, handler in previous.items():
                signal.signal(sig, handler)


class _Relay:
    """A standard stream that is not its file descriptor (a test's capture, an embedding
    program's): the child's writes come back through a pipe.  A real one is inherited."""

    def __init__(self, stream: TextIO, fd: int) -> None:
        self.stream = stream
        try:
            direct = stream.fileno() == fd
        except (AttributeError, OSError, ValueError):
            direct = False
        self.pipe = None if direct else os.pipe()
        self.thread: threading.Thread | None = None

    def child(self) -> None:
        if self.pipe is None:
            return
        os.close(self.pipe[0])
        wrapper = io.TextIOWrapper(
            open(self.pipe[1], "wb", buffering=0),  # noqa: SIM115 - the child's stream
            encoding="utf-8",
            errors="replace",
            write_through=True,
        )
        if self.stream is sys.stdout:
            sys.stdout = wrapper
        else:
            sys.stderr = wrapper

    def parent(self) -> None:
        if self.pipe is None:
            return
        os.close(self.pipe[1])
        self.thread = threading.Thread(target=self._copy, daemon=True)
        self.thread.start()

    def _copy(self) -> None:
        decoder = codecs.getincrementaldecoder("utf-8")("replace")
        with open(self.pipe[0], "rb", buffering=0) as pipe:
            while chunk := pipe.read(1 << 16):
                self.stream.write(decoder.decode(chunk))
                with contextlib.suppress(Exception):
                    self.stream.flush()

    def join(self) -> None:
        if self.thread is not None:
            self.thread.join()


def crash_cause(status: int) -> str:
    """What ended a process, from its wait status."""
    if os.WIFSIGNALED(status):
        sig = os.WTERMSIG(status)
        return f"killed by {signal_name(sig)} (signal {sig})"
    if os.WIFEXITED(status):
        return f"exit code {os.WEXITSTATUS(status)} (an exit() before the run had ended)"
    return f"wait status {status}"


def _report_crash(record: flight.Flight, status: int, wall_time: float) -> int:
    cause = crash_cause(status)
    under_way = record.call_under_way()
    t = record.time
    run = record.announcement()
    if under_way is not None:
        fmu, call = under_way
        where = f"FMU {fmu!r} crashed in {call}"
    elif record.last_instance() is not None:
        fmu, call = record.last_instance(), None
        where = f"the run crashed outside any FMI call (last FMU called: {fmu!r})"
    else:
        fmu, call = None, None
        where = "the run crashed before any FMU was loaded"
    time_reached = t
    if run is None:  # before the run began (loading the scene, building its FMUs)
        print(f"error: the command crashed before its run began: {cause}", file=sys.stderr)
        return 1
    message = f"{where} at t = {time_reached:.9g} s: {cause}"
    out = Path(run["output_dir"])
    summary = {
        "scene": run.get("scene"),
        "status": CRASHED,
        "message": message,
        "time_reached": time_reached,
        "crash": {
            "cause": cause,
            "signal": os.WTERMSIG(status) if os.WIFSIGNALED(status) else None,
            "exit_code": os.WEXITSTATUS(status) if os.WIFEXITED(status) else None,
            "fmu": fmu,
            "call": call,
        },
        "headline": {},
        "accuracy": {},
        "notes": [
            "the run's process crashed: the series hold every step completed before it; "
            "no headline quantities, analyses or reference comparison"
        ],
        "stats": {"wall_time": wall_time},
        "metadata": {k: run[k] for k in ("scene_file", "fmus") if k in run},
    }
    written = _write_summary(out, summary)
    print(f"scene {run.get('scene')}: {CRASHED} — {message}")
    print(f"  results in {out}" if written else f"  could not write {out / 'summary.json'}")
    return 1


def _write_summary(out: Path, summary: dict[str, Any]) -> bool:
    """``summary.json`` written whole (temporary file, then renamed), under the lock of the
    results directory the dead run held."""
    from orchestrator.output_lock import OutputLock

    try:
        with OutputLock(out):
            write_summary(out, summary)
    except Exception as exc:  # noqa: BLE001 - the crash is reported even so
        print(f"error: cannot write {out / 'summary.json'}: {exc}", file=sys.stderr)
        return False
    return True
