"""Where an FMU file is unzipped for its instances.

fmpy unzips an FMU into a new temporary folder, removed when the process ends: 0.03 s an FMU
a run, and the M739's two FMUs hold 3.5 MB.  Our own FMUs (those that carry our vendor
annotation) are named by their content and never change, so each is unzipped once into the
FMU cache, ``unpacked/<hash of the file>/``, and every later process loads it from there
(read only: the FMUs write nothing into their folders).  The folder appears whole or not at
all: it is unzipped beside it and renamed.  An FMU from another tool may write into its
folder, and its file may change in place: it is unzipped afresh into a temporary folder,
removed at the end as before.
"""

from __future__ import annotations

import atexit
import contextlib
import os
import shutil
import tempfile
from pathlib import Path
from typing import Any

from fmpy import extract, read_model_description

from fmus.cache_dir import default_cache_dir
from orchestrator.file_hash import file_sha256

#: FMU file -> (model description, unzip folder), once per process
_UNPACKED: dict[str, tuple[Any, str]] = {}
#: the FMU files whose folders are kept in the FMU cache (never removed here)
_KEPT: set[str] = set()


def unpacked(fmu_path: str) -> tuple[Any, str]:
    """Model description and unzip folder of an FMU file, once per file and process."""
    if fmu_path not in _UNPACKED:
        md = read_model_description(fmu_path)
        folder = _kept_folder(Path(fmu_path))
        if folder is None:
            folder = extract(fmu_path)
        else:
            _KEPT.add(fmu_path)
        _UNPACKED[fmu_path] = (md, folder)
    return _UNPACKED[fmu_path]


def _kept_folder(path: Path) -> str | None:
    """Our FMU's folder in the FMU cache, unzipped there if it is not yet; None for an FMU
    of another tool or where the cache cannot take it."""
    from orchestrator.model_info import ModelInfoError, model_info

    try:
        if not model_info(path).annotated:
            return None
        target = default_cache_dir() / "unpacked" / file_sha256(path)[:32]
        if target.is_dir():
            return str(target)
        target.parent.mkdir(parents=True, exist_ok=True)
        partial = tempfile.mkdtemp(prefix=".unpacking-", dir=target.parent)
    except (OSError, ModelInfoError):
        return None
    try:
        extract(str(path), unzipdir=partial)
        os.rename(partial, target)
    except OSError:  # another process put it there first, or the cache is full
        shutil.rmtree(partial, ignore_errors=True)
        return str(target) if target.is_dir() else None
    except Exception:  # noqa: BLE001 - fmpy's zip errors: unzipped the usual way instead
        shutil.rmtree(partial, ignore_errors=True)
        return None
    return str(target)


@atexit.register
def remove_unpacked(keep: frozenset[str] = frozenset()) -> None:
    """Remove the temporary unzip folders, but those of the FMU files in ``keep``."""
    for fmu_path, (_, folder) in _UNPACKED.items():
        if fmu_path not in keep and fmu_path not in _KEPT:
            with contextlib.suppress(OSError):
                shutil.rmtree(folder, ignore_errors=True)


def unpacked_files() -> frozenset[str]:
    """FMU files unpacked by this process so far (a forked child shares their folders)."""
    return frozenset(_UNPACKED)
