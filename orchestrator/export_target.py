"""Where an export may write: never over its own input or a scene, over an existing file
only when asked."""

from __future__ import annotations

import tomllib
from pathlib import Path

from orchestrator.errors import ScenarioError

#: Tables that make a TOML file a scene (``[scene]`` and ``[fmus]`` are required in one).
SCENE_TABLES = ("scene", "fmus")


def is_scene_file(path: Path) -> bool:
    """A TOML file with a [scene] or [fmus] table: a scene (or most of one)."""
    try:
        with open(path, "rb") as f:
            raw = tomllib.load(f)
    except (OSError, tomllib.TOMLDecodeError, UnicodeDecodeError):
        return False
    return any(isinstance(raw.get(t), dict) for t in SCENE_TABLES)


def check_export_target(scene: Path, out: Path, force: bool) -> None:
    """Refuse to write ``out`` over ``scene`` itself or any other scene file, and over an
    existing file unless ``force``; ``out`` must not be a directory."""
    scene, out = Path(scene), Path(out)
    if not out.exists():
        return
    if out.is_dir():
        raise ScenarioError(out, "", "is a directory; expected the .ssp file to write")
    if scene.exists() and out.samefile(scene):
        raise ScenarioError(out, "", "is the scene being exported; choose another output file")
    if is_scene_file(out):
        raise ScenarioError(out, "", "is a scene file; an export never replaces a scene")
    if not force:
        raise ScenarioError(out, "", "exists; give --force to replace it")
