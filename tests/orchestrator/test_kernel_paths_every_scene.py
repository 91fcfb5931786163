"""Every example scene gives the same bytes with the compiled kernels and with the Python
code (``MECHCOSIM_PURE_PYTHON=1``): each path runs the scene as a user would, a ``mechcosim
run`` of its own (the kernels are bound when the physics is imported), and the two runs'
``timeseries.csv`` and ``events.csv`` are compared byte for byte.  The default suite runs the
first moments of two of them; the whole scenes run under ``slow``."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from kernel_paths import PROJECT, needs_kernels, path_env

SCENES = sorted(p.name for p in (PROJECT / "scenarios").glob("*.toml"))
#: One scene per family with compiled physics, cut short: (scene, stop).
#: (M739's own are in test_compiled_kernels.py; the lever's and the sprag's under slow)
SHORT = [("clock_train_sa.toml", "4 ms"), ("press_feed_run1.toml", "0.1 s")]


def _run(scene: str, out: Path, pure: bool, stop: str | None) -> dict[str, bytes]:
    command = [sys.executable, "-m", "orchestrator", "run", f"scenarios/{scene}"]
    command += ["--output", str(out), "--no-progress", "--no-plot", "--no-reference"]
    command += ["--force", "--in-process"]
    if stop is not None:
        command += ["--set", f"scene.stop={stop}"]
    done = subprocess.run(command, env=path_env(pure), cwd=PROJECT, capture_output=True, text=True)
    assert done.returncode == 0, f"{scene} ({'Python' if pure else 'compiled'}): {done.stderr}"
    return {f: (out / f).read_bytes() for f in ("timeseries.csv", "events.csv")}


def _both(scene: str, tmp_path: Path, stop: str | None = None) -> None:
    compiled = _run(scene, tmp_path / "compiled", False, stop)
    python = _run(scene, tmp_path / "python", True, stop)
    assert compiled["timeseries.csv"].count(b"\n") > 10  # the run did move
    for name in compiled:
        assert compiled[name] == python[name], f"{scene}: {name} differs between the paths"


@needs_kernels
@pytest.mark.parametrize(("scene", "stop"), SHORT)
def test_both_paths_agree_on_the_first_moments(scene: str, stop: str, tmp_path: Path) -> None:
    _both(scene, tmp_path, stop)


@pytest.mark.slow
@needs_kernels
@pytest.mark.parametrize("scene", SCENES)
def test_both_paths_agree_on_every_example_scene(scene: str, tmp_path: Path) -> None:
    _both(scene, tmp_path)
