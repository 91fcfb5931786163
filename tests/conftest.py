"""Shared fixtures: one FMU cache per test session, results in temporary directories."""

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
