"""The command ends its process at once once it has answered (orchestrator.entry.command),
after what the interpreter's shutdown would have run first: its output all written, its exit
code kept, and the FMUs it extracted removed, supervised or not."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.orchestrator
PROJECT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("supervised", [True, False])
def test_a_run_answers_whole_and_leaves_no_extracted_fmu(tmp_path: Path, supervised: bool) -> None:
    temp = tmp_path / "temp"
    temp.mkdir()
    env = {**os.environ, "TMPDIR": str(temp), "PYTHONPATH": str(PROJECT)}
    command = [sys.executable, "-m", "orchestrator", "run", "scenarios/two_inertias.toml"]
    command += ["--output", str(tmp_path / "run"), "--no-progress", "--set", "scene.stop=5 ms"]
    if not supervised:
        command.append("--in-process")
    done = subprocess.run(command, env=env, cwd=PROJECT, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("scene two_inertias: completed")
    assert done.stdout.rstrip().endswith(f"results in {tmp_path / 'run'}")
    assert list(temp.iterdir()) == []  # the FMUs extracted for the run are gone


def test_a_refused_scene_keeps_its_exit_code(tmp_path: Path) -> None:
    bad = tmp_path / "bad.toml"
    bad.write_text("[scene]\nname = 'x'\n")
    done = subprocess.run(
        [sys.executable, "-m", "orchestrator", "check", str(bad)],
        env={**os.environ, "PYTHONPATH": str(PROJECT)},
        cwd=PROJECT,
        capture_output=True,
        text=True,
    )
    assert done.returncode == 2
    assert str(bad) in done.stderr
