"""The ``mechcosim`` command's first code: SIGINT and SIGTERM are answered from here on.

Importing the command and reading its arguments takes about 0.15 s on an idle machine,
several times that on a loaded one.  A Ctrl-C in that time used to print a
KeyboardInterrupt traceback, and a SIGTERM killed the process without a word.  Both now end
the command with one line and exit 130 / 143.  Once a run has started, its own guard
(``orchestrator.interrupt``) takes over: the run stops at a step boundary and keeps what it
has recorded.  Only the interpreter's own start (about 0.05 s, before any of this code
runs) is left as it was.
"""

from __future__ import annotations

import atexit
import os
import signal
import sys
import threading
from typing import NoReturn

from orchestrator.interrupt import (
    SIGNALS,
    Interrupted,
    catching_signals,
    report_interrupted,
    signum_of,
)

_COMMAND_PID = os.getpid()


def _raise_interrupted(signum: int, frame: object) -> None:
    if os.getpid() != _COMMAND_PID:
        # A forked pool worker inherits this handler: it ends as SIGTERM would end it,
        # silently, rather than raising in the middle of its pool's bookkeeping.
        signal.signal(signum, signal.SIG_DFL)
        os.kill(os.getpid(), signum)
        return
    raise Interrupted(signum)


def main(argv: list[str] | None = None) -> int:
    """Run the ``mechcosim`` command (``orchestrator.cli.main``).

    While the command's modules load, a signal only sets a flag: an exception raised inside
    the import machinery can be swallowed (the command then runs on as if nothing had come)
    or leave a module half-imported.  The flag is read once they have loaded.  From there
    on SIGTERM raises ``Interrupted`` as SIGINT raises KeyboardInterrupt, until a run
    installs its own guard.  Once the command has returned both are ignored: this is the
    process's last work."""
    with catching_signals() as guard:
        import fmus.build  # noqa: F401 - the command's other import before a run's guard
        from orchestrator.cli import main as command
    if guard.signum is not None:
        return report_interrupted(guard.signum)
    if signal.getsignal(signal.SIGTERM) is signal.SIG_DFL:
        signal.signal(signal.SIGTERM, _raise_interrupted)
    try:
        code = command(argv)
    except (KeyboardInterrupt, Interrupted) as exc:
        if "--debug" in (sys.argv[1:] if argv is None else argv):
            raise
        code = report_interrupted(signum_of(exc))
    # The work is done and the exit code decided.  The interpreter's shutdown puts the
    # signals back to their defaults, so a signal now would kill the process (exit -15 for
    # a run that completed); ignored, it changes nothing.
    for sig in SIGNALS:
        signal.signal(sig, signal.SIG_IGN)
    return code


def command() -> NoReturn:
    """The ``mechcosim`` command as a process: ``main``, then the process ends at once.

    The interpreter's own shutdown clears the 400-odd modules a run imports one by one,
    0.15-0.27 s after the answer is printed: a third of what a repeated run of the M739
    scene spends outside its co-simulation.  The exit handlers run first (logging's flush,
    the extracted FMUs' removal, temporary folders), the streams are flushed, and the
    process exits with the command's code.  With another thread still alive (one the
    command did not stop) the interpreter ends the process as usual, joining it."""
    code = main()
    if threading.active_count() > 1:
        sys.exit(code)
    atexit._run_exitfuncs()  # what the interpreter's shutdown would run first
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed pipe: the command's words are lost anyway
            pass
    os._exit(code)


if __name__ == "__main__":
    command()
