"""Small results kept beside the FMUs between processes (``<FMU cache>/memo/<name>.json``):
what a later process would otherwise work out again from the same inputs, such as the
imports of a source file or the conversion of a quantity's text.

A memo is a JSON object of text keys; its name says what its entries depend on besides
their keys (a hash of the code that made them), so a change of that code starts an empty
memo.  A memo that cannot be read (half-written by a process that died) is passed over and
its entries worked out again; one that cannot be written is not kept.
"""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path
from typing import Any

from fmus.atomic_file import write_whole
from fmus.cache_dir import default_cache_dir

#: a memo grown past this many entries (sweeps of --set values) starts again
MAX_ENTRIES = 20_000


class DiskMemo:
    """One memo file, read at the first lookup, written at once after each new entry
    (a process may end any time after it)."""

    def __init__(self, name: str) -> None:
        self.name = name
        self._entries: dict[str, Any] | None = None

    def path(self) -> Path:
        return default_cache_dir() / "memo" / f"{self.name}.json"

    def _loaded(self) -> dict[str, Any]:
        if self._entries is None:
            try:
                entries = json.loads(self.path().read_text())
            except (OSError, ValueError):
                entries = {}
            self._entries = entries if isinstance(entries, dict) else {}
        return self._entries

    def get(self, key: str) -> Any:
        """The entry of ``key``, or None."""
        return self._loaded().get(key)

    def put(self, key: str, value: Any) -> None:
        entries = self._loaded()
        if len(entries) >= MAX_ENTRIES:
            entries.clear()
        entries[key] = value
        try:
            write_whole(self.path(), json.dumps(entries).encode())
        except OSError:
            pass  # an unwritable cache: worked out again next time


def installed_version(package: str) -> str | None:
    """The installed version of ``package`` (None if it is not installed), kept in a memo
    keyed by where the package is installed and when: reading it from the installed
    distributions imports ``importlib.metadata`` and scans them, 0.04-0.06 s a process."""
    spec = importlib.util.find_spec(package)  # located, not imported
    if spec is None or spec.origin is None:
        return None
    origin = Path(spec.origin)
    key = f"{package}\x1f{origin}\x1f{origin.stat().st_mtime_ns}"
    known = _VERSIONS.get(key)
    if isinstance(known, str):
        return known
    from importlib import metadata

    try:
        version = metadata.version(package)
    except metadata.PackageNotFoundError:
        return None
    _VERSIONS.put(key, version)
    return version


_VERSIONS = DiskMemo("installed-versions")
