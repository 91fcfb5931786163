"""What is read from an FMU file is kept between processes by the file's hash: read back
equal to a fresh reading, read afresh when the file's bytes differ or the entry is broken."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from fmus.build import build_fmu
from orchestrator import model_info as mi
from orchestrator import model_info_memo

pytestmark = pytest.mark.orchestrator


def test_kept_reading_equals_a_fresh_one(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    fmu = tmp_path / "a.fmu"
    shutil.copyfile(build_fmu("Inertia"), fmu)
    monkeypatch.setenv("MECHCOSIM_FMU_CACHE", str(tmp_path / "cache"))
    fresh = mi._read_model_info(fmu)
    assert model_info_memo.recall(fmu) is None
    model_info_memo.remember(fmu, fresh)
    moved = tmp_path / "b.fmu"
    shutil.copyfile(fmu, moved)
    kept = model_info_memo.recall(moved)
    assert kept == mi._read_model_info(moved)  # the same bytes elsewhere: its own path
    assert kept.path == moved and kept.variables == fresh.variables
    with open(moved, "ab") as f:
        f.write(b"\0")  # other bytes: not the kept reading
    assert model_info_memo.recall(moved) is None
    (entry,) = (tmp_path / "cache" / "memo" / "model-info").glob("*.pickle")
    entry.write_bytes(entry.read_bytes()[:10])  # half-written
    assert model_info_memo.recall(fmu) is None
