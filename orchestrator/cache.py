"""The FMU cache directory, checked once before anything is built into it."""

from __future__ import annotations

import os
from pathlib import Path

from fmus.build import BuildError, default_cache_dir


def check_cache_dir(path: Path | None = None) -> Path:
    """The cache directory (``path`` or the default), or a one-line BuildError saying why it
    cannot hold FMUs: a file in its place, or not writable."""
    path = Path(path) if path is not None else default_cache_dir()
    where = (
        ""
        if path != default_cache_dir() or not os.environ.get("MECHCOSIM_FMU_CACHE")
        else (" ($MECHCOSIM_FMU_CACHE)")
    )
    for parent in (path, *path.parents):
        if parent.exists():
            if not parent.is_dir():
                raise BuildError(f"FMU cache {path}{where}: {parent} is a file, not a directory")
            if not os.access(parent, os.W_OK | os.X_OK):
                if parent == path and os.access(parent, os.R_OK | os.X_OK):
                    return path  # read-only but usable for what is already built
                raise BuildError(f"FMU cache {path}{where}: {parent} is not writable")
            break
    return path
