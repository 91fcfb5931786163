"""The unit registry's parsed definitions and the conversions made are cached beside the
FMUs (``fmus.disk_memo``); a cache that is half-written or unwritable is passed over and
the conversions stay the same, and a process whose conversions are all known does not
import pint."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.orchestrator

_CONVERT = (
    "import sys, orchestrator.units as u;"
    "print(repr(u.to_si('0.4701 in', 'm')), repr(u.to_si('1 lbf*in*s^2', 'kg.m2', exact=True)),"
    " 'dask' in sys.modules, 'pint' in sys.modules)"
)


def _convert(cache: Path) -> str:
    env = {**os.environ, "MECHCOSIM_FMU_CACHE": str(cache)}
    done = subprocess.run(
        [sys.executable, "-c", _CONVERT], env=env, capture_output=True, text=True, check=True
    )
    return done.stdout.strip()


def test_cached_registry_converts_as_built_one(tmp_path: Path) -> None:
    first = _convert(tmp_path)  # builds the registry and writes the cache
    assert list((tmp_path / "units").glob("*.pickle")), "no cache written"
    (memo,) = (tmp_path / "memo").glob("units-*.json")
    # the conversions are remembered: pint is not even imported
    assert _convert(tmp_path) == first.replace("True", "False")
    memo.write_text(memo.read_text()[:20])  # a writer that died mid-write: converted again
    assert _convert(tmp_path) == first
    for pickled in (tmp_path / "units").glob("*.pickle"):
        pickled.write_bytes(pickled.read_bytes()[:100])  # a writer that died mid-write
    memo.unlink()
    assert _convert(tmp_path) == first
    # ... and the cache is written again, whole
    for pickled in (tmp_path / "units").glob("*.pickle"):
        assert len(pickled.read_bytes()) > 100
    # 0.4701 in, and 1 lbf*in*s^2 with the exact pound-force 4.4482216152605 N; dask is not
    # imported by the unit conversions
    assert first == f"0.01194054 {4.4482216152605 * 0.0254!r} False True"
