"""Reading the files a command is given only when they are regular files of a sane size.

A named pipe given as a signal file would block the read for ever, a link to /dev/zero
would be read until the memory runs out: both are refused in one line naming the file
(docs/cli.md, "Limits").  The file is opened without blocking, its kind and size taken
from the open descriptor (so a file swapped after the check is still the one judged), and
at most the limit read.
"""

from __future__ import annotations

import errno
import os
import stat
from pathlib import Path

MB = 1 << 20
#: Largest scene or design file read [bytes]: scenes are a few kB.
TOML_LIMIT = 16 * MB
#: Largest signal CSV read [bytes]: some million rows.
CSV_LIMIT = 256 * MB
#: Largest summary.json read [bytes]: a summary keeps its FMU messages bounded.
SUMMARY_LIMIT = 64 * MB
#: Largest SSP archive read [bytes]: its FMUs, zipped.
ARCHIVE_LIMIT = 1024 * MB


class NotARegularFile(OSError):
    """A path that is no regular file (a pipe, a device, a socket) or is too large; its
    ``strerror`` says which, in words."""

    def __init__(self, path: Path, why: str) -> None:
        super().__init__(errno.EINVAL, why, str(path))


def _kind(mode: int) -> str:
    for test, name in (
        (stat.S_ISFIFO, "a named pipe"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISSOCK, "a socket"),
    ):
        if test(mode):
            return name
    return "not a regular file"


def read_regular(path: Path | str, limit: int) -> bytes:
    """The bytes of ``path``, a regular file of at most ``limit`` bytes (links followed).

    Raises FileNotFoundError, IsADirectoryError, PermissionError as ``open`` does, and
    NotARegularFile for anything else or a file over the limit."""
    path = Path(path)
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    try:
        info = os.fstat(fd)
        if stat.S_ISDIR(info.st_mode):
            raise IsADirectoryError(errno.EISDIR, "Is a directory", str(path))
        if not stat.S_ISREG(info.st_mode):
            what = _kind(info.st_mode)
            raise NotARegularFile(path, f"is {what}, not a regular file; expected a file")
        if info.st_size > limit:
            raise NotARegularFile(path, _too_large(info.st_size, limit))
        chunks, size = [], 0
        while chunk := os.read(fd, min(limit + 1 - size, 1 << 20)):
            chunks.append(chunk)
            size += len(chunk)
            if size > limit:  # it grew while being read
                raise NotARegularFile(path, _too_large(size, limit))
        return b"".join(chunks)
    finally:
        os.close(fd)


def check_regular(path: Path | str, limit: int) -> None:
    """Raise as ``read_regular`` would, without reading (for a file another library
    opens, such as an FMU or an archive)."""
    path = Path(path)
    info = os.stat(path)
    if stat.S_ISDIR(info.st_mode):
        raise IsADirectoryError(errno.EISDIR, "Is a directory", str(path))
    if not stat.S_ISREG(info.st_mode):
        raise NotARegularFile(path, f"is {_kind(info.st_mode)}, not a regular file")
    if info.st_size > limit:
        raise NotARegularFile(path, _too_large(info.st_size, limit))


def _too_large(size: int, limit: int) -> str:
    return f"is {size / MB:.1f} MB, more than the limit of {limit / MB:.0f} MB"
