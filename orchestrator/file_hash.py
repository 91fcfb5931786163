"""The SHA-256 of a file, kept per file version in the process: a run hashes each FMU for
its unpacked folder, its model-description memo and its summary, and reads it once."""

from __future__ import annotations

import hashlib
from functools import cache
from pathlib import Path


def file_sha256(path: Path) -> str:
    """The file's SHA-256 (kept per file version in the process: a run hashes its FMUs for
    its folders and again for its summary)."""
    stat = Path(path).stat()
    return _sha256(Path(path), stat.st_mtime_ns, stat.st_size)


@cache
def _sha256(path: Path, mtime_ns: int, size: int) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()
