"""Our FMUs are unzipped once into the FMU cache and loaded from there by every later
process; an FMU of another tool is unzipped afresh into a temporary folder, removed at the
end."""

from __future__ import annotations

import shutil
from pathlib import Path
from types import SimpleNamespace

import pytest

from fmus.build import build_fmu
from orchestrator import model_info as model_info_module
from orchestrator import unpacked_fmus

pytestmark = pytest.mark.orchestrator


@pytest.fixture
def fresh(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An Inertia FMU copied into a cache of its own, and no folder unpacked yet."""
    fmu = tmp_path / "Inertia.fmu"
    shutil.copyfile(build_fmu("Inertia"), fmu)
    monkeypatch.setenv("MECHCOSIM_FMU_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(unpacked_fmus, "_UNPACKED", {})
    monkeypatch.setattr(unpacked_fmus, "_KEPT", set())
    return fmu


def test_our_fmu_is_unpacked_once_into_the_cache(fresh: Path, tmp_path: Path) -> None:
    md, folder = unpacked_fmus.unpacked(str(fresh))
    assert md.coSimulation.modelIdentifier == "Inertia"
    assert Path(folder).parent == tmp_path / "cache" / "unpacked"
    assert (Path(folder) / "modelDescription.xml").is_file()
    assert not list(Path(folder).parent.glob(".unpacking-*"))  # renamed whole
    unpacked_fmus.remove_unpacked()
    assert Path(folder).is_dir()  # kept for the next process
    unpacked_fmus._UNPACKED.clear()  # a later process: the same folder, not unzipped again
    marker = Path(folder) / "marker"
    marker.write_text("")
    assert unpacked_fmus.unpacked(str(fresh))[1] == folder and marker.exists()


def test_an_fmu_of_another_tool_is_unpacked_apart_and_removed(
    fresh: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(
        model_info_module, "model_info", lambda path: SimpleNamespace(annotated=False)
    )
    _, folder = unpacked_fmus.unpacked(str(fresh))
    assert tmp_path / "cache" not in Path(folder).parents
    unpacked_fmus.remove_unpacked()
    assert not Path(folder).exists()
