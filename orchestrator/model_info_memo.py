"""What ``orchestrator.model_info`` read from an FMU file, kept beside the FMUs
(``<FMU cache>/memo/model-info/<key>.pickle``) so that a later process does not open the
archive and parse its model description again (0.03-0.1 s a scene load).

The key hashes the file's bytes and the code that reads it (``model_info.py``, the
annotation's declarations and the coupling roles), so an FMU rebuilt or replaced in place,
or a change of that code, is read afresh.  An entry that cannot be read is read afresh too;
one that cannot be written is not kept.
"""

from __future__ import annotations

import contextlib
import hashlib
import pickle
from dataclasses import replace
from functools import cache
from pathlib import Path
from typing import Any

from fmus.atomic_file import write_whole
from orchestrator.file_hash import file_sha256

_ROOT = Path(__file__).resolve().parent.parent
_CODE = (
    _ROOT / "orchestrator" / "model_info.py",
    _ROOT / "orchestrator" / "model_info_memo.py",
    _ROOT / "fmus" / "description.py",
    _ROOT / "components" / "base.py",
)


@cache
def _code_hash() -> bytes:
    h = hashlib.sha256()
    for path in _CODE:
        h.update(path.read_bytes())
    return h.digest()


def _entry(path: Path) -> Path | None:
    """The memo entry of the FMU at ``path``; None if the file cannot be read."""
    from fmus.cache_dir import default_cache_dir

    try:
        data = file_sha256(path).encode()  # hashed once a process, for the run's summary too
    except OSError:
        return None  # said by the reading itself
    key = hashlib.sha256(_code_hash() + data).hexdigest()[:32]
    return default_cache_dir() / "memo" / "model-info" / f"{key}.pickle"


def recall(path: Path) -> Any:
    """The ModelInfo read earlier from a file with these bytes (its path this one), or
    None."""
    entry = _entry(path)
    if entry is None:
        return None
    try:
        with open(entry, "rb") as f:
            info = pickle.load(f)
        return replace(info, path=path)
    except Exception:  # noqa: BLE001 - none yet, half-written or of another layout: a miss
        return None


def remember(path: Path, info: Any) -> None:
    entry = _entry(path)
    if entry is None:
        return
    with contextlib.suppress(OSError, pickle.PicklingError, TypeError, AttributeError):
        write_whole(entry, pickle.dumps(info, protocol=pickle.HIGHEST_PROTOCOL))
