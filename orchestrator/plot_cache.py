"""Run plots kept on disk, keyed by everything they are drawn from.

A run's plot is a function of its recorded data and located events, of the scene it ran
(name, FMU instances and parameters, report options, start and stop) and of the code that
draws it (``orchestrator/plotting.py``, the family's package and what ``code_hash`` follows)
and matplotlib.  Importing matplotlib and drawing the M739 plot cost 1.4-2 s, four times
the co-simulation, so a run whose data and scene were drawn before copies that PNG from
``<FMU cache>/plots/<family>/<key>.png`` instead.  Deleting the folder clears the cache.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import shutil
from collections.abc import Callable
from pathlib import Path

import numpy as np

from fmus.atomic_file import write_whole
from fmus.disk_memo import installed_version
from orchestrator.reference_cache import code_hash, scene_content
from orchestrator.scene_model import Scene

_PLOTTING = Path(__file__).resolve().with_name("plotting.py")
#: Bumped when the key's content changes.
_FORMAT = 1


def plot_dir(cache_dir: Path) -> Path:
    """Where the plots are kept under the FMU cache ``cache_dir``."""
    return Path(cache_dir) / "plots"


def cached_plot(
    scene: Scene,
    header: list[str],
    data: np.ndarray,
    path: Path,
    draw: Callable[[], None],
    cache_dir: Path,
) -> bool:
    """Write the run's plot at ``path``: a copy of the one drawn before from the same
    content, else ``draw()`` (which writes ``path``), then kept.  True if it was copied."""
    kept = plot_dir(cache_dir) / str(scene.family) / f"{plot_key(scene, header, data, path)}.png"
    if kept.is_file():
        try:
            shutil.copyfile(kept, path)
            return True
        except OSError:
            pass  # unreadable: drawn again
    draw()
    _keep(path, kept)
    return False


def plot_key(scene: Scene, header: list[str], data: np.ndarray, path: Path) -> str:
    """A hash of what the plot at ``path`` is drawn from (its run's ``events.csv`` beside
    it included)."""
    h = hashlib.sha256()
    h.update(str(data.dtype).encode() + repr(data.shape).encode())
    h.update(np.ascontiguousarray(data).tobytes())
    events = Path(path).with_name("events.csv")
    h.update(events.read_bytes() if events.is_file() else b"no events")
    content = {
        "format": _FORMAT,
        "family": scene.family,
        "name": scene.name,
        "file": Path(path).name,
        **scene_content(scene),
        "header": header,
        "data": h.hexdigest(),
        "code": code_hash(str(scene.family)),
        "plotting": hashlib.sha256(_PLOTTING.read_bytes()).hexdigest(),
        "matplotlib": installed_version("matplotlib"),
    }
    text = json.dumps(content, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:32]


def _keep(drawn: Path, kept: Path) -> None:
    """Copy the drawn plot into the cache (whole, then renamed); not kept if it cannot be."""
    with contextlib.suppress(OSError):  # none drawn, or a cache that cannot take it
        write_whole(kept, drawn.read_bytes())
