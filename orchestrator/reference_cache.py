"""Monolithic references kept on disk, keyed by everything they depend on.

A scene's reference depends only on its physics: the reference named, the parameters of
its FMU instances as run, its report options (which instance is which), its start, stop
and stop condition, and the code that computes it (``components/`` and the reference's
family package with the families it imports).  A second run of the same scene reads the
reference from ``<FMU cache>/references/<family>/<key>.pickle`` instead of computing it
again; any change to one of those misses.  Deleting the folder clears the cache.
"""

from __future__ import annotations

import hashlib
import importlib
import json
import marshal
import pickle
import re
import sys
import types
from collections.abc import Callable
from dataclasses import replace
from functools import cache
from pathlib import Path
from typing import Any

from fmus.atomic_file import write_whole
from orchestrator.file_hash import file_sha256
from orchestrator.scene_model import Scene
from orchestrator.scenes.family import Reference

_ROOT = Path(__file__).resolve().parent.parent
_SCENES = _ROOT / "orchestrator" / "scenes"
_FAMILY_IMPORT = re.compile(r"orchestrator\.scenes\.(\w+)")
#: Bumped when the file layout below changes.
_FORMAT = 1


def reference_dir(cache_dir: Path) -> Path:
    """Where the references are kept under the FMU cache ``cache_dir``."""
    return Path(cache_dir) / "references"


def cached_reference(
    scene: Scene, compute: Callable[[Scene], Reference], cache_dir: Path
) -> tuple[Reference, bool]:
    """The scene's reference (from the cache if it holds one for ``scene``, else
    ``compute(scene)``, then kept) and whether it came from the cache."""
    path = reference_dir(cache_dir) / str(scene.reference) / f"{reference_key(scene)}.pickle"
    ref = _read(path)
    if ref is not None:
        return ref, True
    ref = compute(scene)
    _write(path, ref)
    return ref, False


def reference_key(scene: Scene) -> str:
    """A hash of what the scene's reference depends on."""
    content = {
        "format": _FORMAT,
        "python": sys.version,
        "reference": scene.reference,
        **scene_content(scene),
        "code": code_hash(str(scene.reference)),
    }
    text = json.dumps(content, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:32]


def scene_content(scene: Scene) -> dict[str, Any]:
    """What of a scene its physics depends on, as JSON: its FMU instances (component or
    file hash, parameters as run), report options, start, stop and stop condition."""
    fmus = {}
    for name, spec in sorted(scene.fmus.items()):
        fmus[name] = {
            "component": spec.component,
            # a black-box FMU: its parameter defaults are in its file
            "file": None if spec.component else _file_hash(Path(spec.path)),
            "parameters": {k: repr(v) for k, v in sorted(spec.parameters.items())},
        }
    return {
        "fmus": fmus,
        "options": repr(sorted(scene.report_options.items())),
        "start": repr(scene.start),
        "stop": repr(scene.stop),
        "stop_when": repr(scene.stop_when),
    }


@cache
def code_hash(family: str) -> str:
    """A hash of the physics code: every file of ``components/``, and the family's package
    with the families it imports (followed through their imports)."""
    files = sorted(_ROOT.joinpath("components").glob("*.py"))
    files += [_SCENES / "family.py", *_family_files(family)]
    digest = hashlib.sha256()
    for file in files:
        digest.update(str(file.relative_to(_ROOT)).encode())
        digest.update(file.read_bytes())
    return digest.hexdigest()


def _family_files(family: str) -> list[Path]:
    seen: set[str] = set()
    todo = [family]
    files: list[Path] = []
    while todo:
        name = todo.pop()
        if name in seen or not (_SCENES / name).is_dir():
            continue
        seen.add(name)
        for file in sorted((_SCENES / name).glob("*.py")):
            files.append(file)
            todo.extend(_FAMILY_IMPORT.findall(file.read_text(encoding="utf-8")))
    return sorted(files)


def _file_hash(path: Path) -> str:
    try:
        return file_sha256(path)
    except OSError:
        return "missing"


def _read(path: Path) -> Reference | None:
    """The reference kept at ``path``; None if there is none or it cannot be read."""
    try:
        with open(path, "rb") as f:
            stored = pickle.load(f)
        return replace(stored["reference"], signals=_function(stored["signals"]))
    except Exception:  # noqa: BLE001 - an unreadable entry is a miss, computed again
        return None


def _write(path: Path, ref: Reference) -> None:
    """Keep ``ref`` at ``path`` (written whole, then renamed); not kept if it cannot be
    (a read-only cache, a signal function that does not pickle)."""
    try:
        stored = {
            "reference": replace(ref, signals=None),
            "signals": _function_state(ref.signals),
        }
        write_whole(path, pickle.dumps(stored, protocol=pickle.HIGHEST_PROTOCOL))
    except Exception:  # noqa: BLE001 - the cache only saves time: the run goes on without
        pass


def _function_state(fn: Callable) -> dict[str, Any]:
    """A reference's signal function (a closure over its series) as plain data: its code
    (marshal: this Python only, which is part of the key) and the values it closes over."""
    if not isinstance(fn, types.FunctionType):
        raise TypeError("not a plain function")
    return {
        "module": fn.__module__,
        "name": fn.__name__,
        "code": marshal.dumps(fn.__code__),
        "defaults": fn.__defaults__,
        "cells": tuple(c.cell_contents for c in fn.__closure__ or ()),
    }


def _function(state: dict[str, Any]) -> Callable:
    module = importlib.import_module(state["module"])
    closure = tuple(types.CellType(v) for v in state["cells"]) or None
    return types.FunctionType(
        marshal.loads(state["code"]), module.__dict__, state["name"], state["defaults"], closure
    )
