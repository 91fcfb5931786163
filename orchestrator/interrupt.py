"""SIGINT and SIGTERM during a run: stop at a step boundary, keep everything, say so.

An exception raised by a signal handler lands wherever the interpreter happens to be, and
during a run that is usually inside an FMU call (the pythonfmu slaves run their Python in
this interpreter): the FMU is left half-stepped, and freeing it may crash the process.  So
while FMUs are alive a signal only sets a flag; the run checks it between macro steps
(``SignalGuard.check``) and ends there with status "interrupted".  Once the FMUs are
closed (analyses, references, plots) the guard may be put in raising mode, where a signal
raises ``Interrupted`` at once.

A third signal while the first is still pending ends the process at once (exit 128 + signal
number), for an FMU call that never returns.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager

SIGNALS = (signal.SIGINT, signal.SIGTERM)


class Interrupted(BaseException):
    """A run was asked to stop by a signal.  A BaseException, like KeyboardInterrupt, so
    that no ``except Exception`` on the way swallows it."""

    def __init__(self, signum: int) -> None:
        self.signum = signum
        super().__init__(f"interrupted by {signal_name(signum)}")

    @property
    def exit_code(self) -> int:
        return 128 + self.signum


def signal_name(signum: int) -> str:
    try:
        return signal.Signals(signum).name
    except ValueError:
        return f"signal {signum}"


def signum_of(exc: KeyboardInterrupt | Interrupted) -> int:
    """The signal behind an interruption: KeyboardInterrupt is Python's SIGINT."""
    return exc.signum if isinstance(exc, Interrupted) else signal.SIGINT


def report_interrupted(signum: int) -> int:
    """Say on standard error that the command was interrupted; its exit code."""
    print(f"interrupted by {signal_name(signum)}", file=sys.stderr)
    return 128 + signum


class SignalGuard:
    """Turns SIGINT/SIGTERM into a flag (or, in raising mode, into ``Interrupted``)."""

    def __init__(self) -> None:
        self.signum: int | None = None
        self.count = 0
        self.raising = False

    def handle(self, signum: int, frame: object) -> None:
        if self.signum is None:
            self.signum = signum
        self.count += 1
        if self.raising:
            raise Interrupted(self.signum)
        if self.count == 2:
            print(
                f"{signal_name(signum)}: stopping at the next step boundary "
                "(once more to end at once, without results)",
                file=sys.stderr,
                flush=True,
            )
        elif self.count >= 3:
            os._exit(128 + self.signum)

    def check(self) -> None:
        """Raise ``Interrupted`` if a signal has come (call only between FMU calls)."""
        if self.signum is not None:
            raise Interrupted(self.signum)

    @contextmanager
    def raise_at_once(self) -> Iterator[None]:
        """Within: a signal (or one already pending) raises ``Interrupted`` where it lands.
        Only for code that holds no FMU."""
        self.check()
        self.raising = True
        try:
            yield
        finally:
            self.raising = False


_ACTIVE: SignalGuard | None = None


@contextmanager
def catching_signals() -> Iterator[SignalGuard]:
    """Install the flag handlers for the duration (re-entrant: an inner use shares the
    outer guard).  Outside the main thread signals cannot be caught: the guard then never
    fires.  A SIGINT the process was started to ignore (a background job) stays ignored."""
    global _ACTIVE
    if _ACTIVE is not None:
        yield _ACTIVE
        return
    guard = SignalGuard()
    if threading.current_thread() is not threading.main_thread():
        yield guard
        return
    previous = {}
    for sig in SIGNALS:
        current = signal.getsignal(sig)
        if sig == signal.SIGINT and current is signal.SIG_IGN:
            continue
        previous[sig] = current
        signal.signal(sig, guard.handle)
    _ACTIVE = guard
    try:
        yield guard
    finally:
        _ACTIVE = None
        for sig, handler in previous.items():
            signal.signal(sig, handler)
