"""The conversions ``orchestrator.units.to_si`` has made, kept beside the FMUs
(``fmus.disk_memo``) so that a later process converts the same texts without importing
pint.  The memo's name hashes the conversion code and pint's version: a change of either
starts an empty memo.  Numbers are stored by their ``repr``, which reads back to the
same bits."""

from __future__ import annotations

import hashlib
from functools import cache
from pathlib import Path

from fmus.disk_memo import DiskMemo, installed_version

_CODE = (
    Path(__file__).resolve().with_name("units.py"),
    Path(__file__).resolve().parent.parent / "components" / "units.py",
)


@cache
def _memo() -> DiskMemo | None:
    """This code's and this pint's memo; None where pint is not installed."""
    version = installed_version("pint")
    if version is None:
        return None
    h = hashlib.sha256()
    for path in _CODE:
        h.update(path.read_bytes())
    h.update(version.encode())
    return DiskMemo(f"units-{h.hexdigest()[:16]}")


def _key(value: str, unit: str, exact: bool) -> str:
    return f"{int(exact)}\x1f{unit}\x1f{value}"


def recall(value: str, unit: str, exact: bool) -> float | None:
    """The float ``value`` converted to ``unit`` earlier, or None."""
    memo = _memo()
    found = None if memo is None else memo.get(_key(value, unit, exact))
    return found if isinstance(found, float) else None


def remember(value: str, unit: str, exact: bool, converted: float) -> None:
    memo = _memo()
    if memo is not None:
        memo.put(_key(value, unit, exact), float(converted))
