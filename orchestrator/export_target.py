"""Where an export may write: never over its own input, a scene or a file the scene reads
(its FMUs, signal files, design file), over an existing file only when asked."""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

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


def files_read(scene: Any) -> dict[Path, str]:
    """Every file a loaded scene reads, with what it is to the scene: the scene file, its
    design file, its FMUs and its signal files."""
    read: dict[Path, str] = {Path(scene.path): "the scene file"}
    design = _design_file(Path(scene.path))
    if design is not None:
        read[design] = "the scene's design file (scene.design)"
    for name, spec in scene.fmus.items():
        read.setdefault(Path(spec.path), f"the FMU of fmus.{name}")
        for variable, signal in spec.signals.items():
            if "file" in signal.source:
                read.setdefault(
                    Path(signal.source["file"]), f"the signal file of fmus.{name}.{variable}"
                )
    return read


def check_not_read(scene: Any, out: Path, option: str = "", copy_of: Path | None = None) -> None:
    """Refuse to write ``out`` (the archive, or a file --osp writes) over a file the scene
    reads: ``--force`` replaces an old export, never the scene's own input.  ``copy_of``:
    the file ``out`` will be a copy of (written over itself, it is left as it was)."""
    out = Path(out)
    if not out.exists():
        return
    for path, what in files_read(scene).items():
        if copy_of is not None and path == Path(copy_of):
            continue
        if path.exists() and out.samefile(path):
            where = f"{option} " if option else ""
            raise ScenarioError(
                out, "", f"{where}is {what}; an export never replaces a file the scene reads"
            )


def _design_file(scene_path: Path) -> Path | None:
    try:
        with open(scene_path, "rb") as f:
            head = tomllib.load(f).get("scene", {})
    except (OSError, tomllib.TOMLDecodeError, UnicodeDecodeError):
        return None
    design = head.get("design") if isinstance(head, dict) else None
    return (scene_path.parent / design).resolve() if isinstance(design, str) else None
