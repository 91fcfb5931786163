"""A run owns its results directory: a lock file, so two runs never write into one.

The lock is an advisory ``flock`` on ``<directory>/.mechcosim.lock``, which also holds the
owner's process id and host for the message, and what the run is (its scene).  The
operating system drops the lock when its process ends, however it ends, so a lock file
left by a dead run is simply taken over.
"""

from __future__ import annotations

import errno
import fcntl
import json
import os
import socket
import time
from pathlib import Path

from orchestrator.errors import RunError

LOCK_NAME = ".mechcosim.lock"


class OutputInUseError(RunError):
    """Another live run holds the results directory."""


class OutputLock:
    """Hold ``directory`` for one run: ``acquire`` (creates the directory) and ``release``."""

    def __init__(self, directory: Path, about: dict | None = None) -> None:
        self.directory = Path(directory)
        # What the run is (its scene): kept in the lock file, which a killed run leaves
        # behind, for ``mechcosim report`` (orchestrator.run_state).
        self.about = dict(about or {})
        self.path = self.directory / LOCK_NAME
        self._fd: int | None = None

    def acquire(self) -> None:
        prepare_directory(self.directory)
        for _ in range(10):
            try:
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
            except OSError as exc:
                raise RunError(
                    f"cannot write in the results directory {self.directory}: {exc.strerror or exc}"
                ) from None
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError as exc:
                os.close(fd)
                if exc.errno not in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                    raise RunError(f"cannot lock {self.path}: {exc.strerror or exc}") from None
                raise OutputInUseError(
                    f"results directory {self.directory} is in use by another run"
                    f"{self._owner_text()}; wait for it to end or choose another --output"
                ) from None
            # The file may have been removed by its previous owner between open and flock:
            # then this lock is on a file nobody else sees; try again.
            try:
                same = os.fstat(fd).st_ino == os.stat(self.path).st_ino
            except FileNotFoundError:
                same = False
            if not same:
                os.close(fd)
                continue
            owner = {
                "pid": os.getpid(),
                "host": socket.gethostname(),
                "since": time.time(),
                **self.about,
            }
            os.ftruncate(fd, 0)
            os.write(fd, json.dumps(owner).encode())
            self._fd = fd
            return
        raise RunError(f"cannot lock {self.path}: it keeps being replaced")

    def _owner_text(self) -> str:
        try:
            owner = json.loads(self.path.read_text())
            return f" (pid {int(owner['pid'])} on {owner.get('host', '?')}; lock {self.path})"
        except (OSError, ValueError, KeyError, TypeError):
            return f" (lock {self.path})"

    def release(self) -> None:
        if self._fd is None:
            return
        try:
            self.path.unlink()
        except OSError:
            pass
        os.close(self._fd)
        self._fd = None

    def __enter__(self) -> OutputLock:
        self.acquire()
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()


def prepare_directory(directory: Path) -> None:
    """Create ``directory`` (and parents) or say in one line why it cannot be used."""
    directory = Path(directory)
    if directory.exists() and not directory.is_dir():
        raise RunError(f"results directory {directory} is a file, not a directory")
    try:
        directory.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise RunError(
            f"cannot create the results directory {directory}: {exc.strerror or exc}"
        ) from None
    if not os.access(directory, os.W_OK | os.X_OK):
        raise RunError(f"results directory {directory} is not writable")
