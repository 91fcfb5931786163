"""One run of a scene file as the tests make it: quiet, into a directory of the test's, with
the session's FMU cache (tests/conftest.py sets it in the environment)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from orchestrator.run import RunResult, run_scene
from orchestrator.scenario import load_scene


def run_file(
    path: Path,
    out: Path,
    overrides: dict[str, Any] | None = None,
    *,
    reference: bool = True,
    plots: bool = False,
    completed: bool = False,
) -> RunResult:
    """The run of the scene at ``path`` (with ``overrides``, as --set gives them) into
    ``out``, compared with its reference unless ``reference`` is false, its plot drawn only
    with ``plots``; with ``completed``, a run that did not complete fails with its message."""
    scene = load_scene(path, overrides)
    result = run_scene(
        scene, output_dir=out, show_progress=False, compare_reference=reference, plots=plots
    )
    if completed:
        assert result.status == "completed", result.message
    return result
