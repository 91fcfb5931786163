"""``summary.json`` of a run that ended before its recorder could write one: a run whose
FMUs could not be instantiated, a run whose process crashed."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any


def write_summary(directory: Path, summary: dict[str, Any]) -> None:
    """Write ``summary.json`` whole: a temporary file, then renamed over the old one."""
    directory = Path(directory)
    partial = directory / "summary.json.part"
    partial.write_text(json.dumps(summary, indent=2, default=str))
    os.replace(partial, directory / "summary.json")


def not_started_summary(scene: Any, message: str) -> dict[str, Any]:
    """The summary of a run that failed before its first step (its FMUs not loaded)."""
    return {
        "scene": scene.name,
        "status": "failed",
        "message": message,
        "time_reached": scene.start,
        "headline": {},
        "accuracy": {},
        "notes": ["the run failed before its first step: nothing was recorded"],
        "stats": {},
        "metadata": {"scene_file": str(scene.path)},
    }
