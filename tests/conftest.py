"""Shared fixtures: one FMU cache per test session, results in temporary directories.

Tests are grouped by layer, one folder each, and marked with its name so that a layer can be
selected: ``components`` (the physics in plain Python), ``fmus`` (the FMUs through fmpy and
other tools), ``orchestrator`` (scene loading, masters, studies, SSP, reliability) and
``scenes`` (whole scenes against their references and sources), e.g. ``pytest -m scenes``.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

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
