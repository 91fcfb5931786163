"""A run in a child process, so that an FMU that crashes cannot take the run's data along.

``mechcosim run`` forks: the child runs the scene exactly as an unsupervised run would
(its own signal guard, its own messages and exit code); the parent waits, forwards
SIGINT/SIGTERM to it, and if the child dies without having finished its work (killed by
a signal, or ended by an FMU's ``exit()``) writes ``summary.json`` with status "crashed",
the signal or exit code, the FMU and FMI call under way and the time reached, read from
the flight record the child kept in shared memory (``orchestrator.flight``).  The CSV
files are written a row at a time (``Recorder``), so they hold every completed step.

The child gets its own process group: a Ctrl-C at the terminal then reaches the parent
only, which forwards it, so the run sees each signal once, as it did unsupervised.  A child
that stops, hangs in an FMI call longer than the scene's ``master.call_timeout``, or does
not end within ``child_watch.SIGNAL_GRACE`` of a forwarded signal is killed, and the run
summarized as "crashed", "timed out" or "interrupted" (``orchestrator.child_watch``).
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

from orchestrator import child_watch, flight
from orchestrator.interrupt import SIGNALS, SignalGuard, signal_name

CRASHED = child_watch.CRASHED


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
    child_watch.prepare_children()
    pid = os.fork()
    if pid == 0:  # the run
        _child(work, record, relays, parent)
    for relay in relays:
        relay.parent()
    watch = child_watch.ChildWatch(pid, record)
    forwarder = _Forwarder(watch, guard)
    with forwarder.installed(signals_before):
        status = watch.wait()
    for relay in relays:
        relay.join()
    if record.finished:
        return record.code
    return _report_ending(record, watch.ending(status), time.perf_counter() - started)


def _child(
    work: Callable[[], int], record: flight.Flight, relays: list[_Relay], parent: int
) -> None:
    from orchestrator.unpacked_fmus import remove_unpacked, unpacked_files

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
            remove_unpacked(keep=inherited)
        os._exit(code)


def _end_with_parent(parent: int) -> None:
    """SIGTERM when the parent dies (the run then stops at a step boundary and keeps its
    data), and the end soon after should an FMI call never return: no orphan."""
    child_watch.die_with_parent(parent)


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


class _Forwarder:
    """While the child runs: SIGINT/SIGTERM go to it (killed if it has not ended
    SIGNAL_GRACE later).  The third kills it at once, as the run's own guard would end an
    unsupervised run (an FMU call that never returns cannot run the child's handler)."""

    def __init__(self, watch: child_watch.ChildWatch, guard: SignalGuard) -> None:
        self.watch, self.guard = watch, guard

    def handle(self, signum: int, frame: object) -> None:
        if self.guard.signum is None:
            self.guard.signum = signum
        self.guard.count += 1
        if self.guard.count >= 3:
            self.watch.kill(interrupted_by=self.guard.signum, at_once=True)
        else:
            self.watch.ask_to_stop(signum)

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
            self.watch.ask_to_stop(self.guard.signum or signal.SIGTERM)
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


crash_cause = child_watch.crash_cause  # where it was first defined


def _report_ending(record: flight.Flight, ending: child_watch.Ending, wall_time: float) -> int:
    """Summarize and report a run whose process ended before finishing; the exit code."""
    summary = child_watch.ended_summary(record, ending, wall_time)
    signum = ending.interrupted_by
    if summary is None:  # before the run began (loading the scene, building its FMUs)
        if signum is not None:
            print(f"interrupted by {signal_name(signum)}", file=sys.stderr)
            return 128 + signum
        cause = child_watch.crash_cause(ending.status)
        if ending.stopped_by is not None:
            cause = child_watch.outcome(record, ending)[2]["cause"]
        print(f"error: the command crashed before its run began: {cause}", file=sys.stderr)
        return 1
    out = Path(summary["output_dir"])
    written = child_watch.write_ended_summary(summary)
    if record.summary_written:  # the run had ended: its report, and what happened after
        from orchestrator.run_text import summary_lines

        print("\n".join(summary_lines(summary, out)))  # its notes say what happened
        return 1
    print(f"scene {summary['scene']}: {summary['status']} — {summary['message']}")
    print(f"  results in {out}" if written else f"  could not write {out / 'summary.json'}")
    return 128 + signum if signum is not None else 1
