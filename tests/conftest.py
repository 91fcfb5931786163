"""Shared fixtures: one FMU cache per test session, results in temporary directories.

Tests are grouped by layer, one folder each, and marked with its name so that a layer can be
selected: ``components`` (the physics in plain Python), ``fmus`` (the FMUs through fmpy and
other tools), ``orchestrator`` (scene loading, masters, studies, SSP, reliability) and
``scenes`` (whole scenes against their references and sources), e.g. ``pytest -m scenes``.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

# Every worker imports the project and the test modules, and the tests start many Python
# processes that import the project again: with bytecode caches switched off in the
# environment (PYTHONDONTWRITEBYTECODE), each compiled every source again and pytest
# rewrote every test module again (collection 12.8 s a process, 4.2 s with the caches).
# The caches go to __pycache__, as Python writes them by default.
sys.dont_write_bytecode = False

PROJECT_DIR = Path(__file__).resolve().parent.parent
SCENARIOS = PROJECT_DIR / "scenarios"


@pytest.fixture(scope="session", autouse=True)
def fmu_cache(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The FMU cache of the session: $MECHCOSIM_FMU_CACHE if set, else a fresh one.  Set in
    the environment, so that loading a scene (which builds its FMUs) and spawned workers
    use it too."""
    if os.environ.get("MECHCOSIM_FMU_CACHE"):
        return Path(os.environ["MECHCOSIM_FMU_CACHE"])
    path = tmp_path_factory.mktemp("fmu_cache")
    os.environ["MECHCOSIM_FMU_CACHE"] = str(path)
    return path


LAYERS = ("components", "fmus", "orchestrator", "scenes")


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """Mark each test with its layer, the folder it lives in."""
    for item in items:
        layer = item.path.parent.name
        if layer in LAYERS:
            item.add_marker(getattr(pytest.mark, layer))


@pytest.fixture(scope="session")
def scene_runs(tmp_path_factory: pytest.TempPathFactory, fmu_cache: Path):
    """``scene_runs(name, overrides=None, plots=False)``: the run of a scene file (under
    scenarios/, or a path) with its reference, made once per test process for the same
    arguments, so that the tests reading one run share it."""
    from orchestrator.run import run_scene
    from orchestrator.scenario import load_scene

    done = {}

    def get(name: str | Path, overrides: dict | None = None, plots: bool = False):
        key = (str(name), repr(sorted((overrides or {}).items())), plots)
        if key not in done:
            scene = load_scene(SCENARIOS / name, overrides)
            out = tmp_path_factory.mktemp(scene.name)
            done[key] = run_scene(scene, out, cache_dir=fmu_cache, show_progress=False, plots=plots)
        return done[key]

    return get
