"""Where built FMUs, compiled kernels and the memos beside them live."""

from __future__ import annotations

import os
from pathlib import Path


def default_cache_dir() -> Path:
    """Where built FMUs live: $MECHCOSIM_FMU_CACHE, else the user cache directory."""
    env = os.environ.get("MECHCOSIM_FMU_CACHE")
    if env:
        return Path(env)
    base = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache"))
    return base / "mechcosim" / "fmus"
