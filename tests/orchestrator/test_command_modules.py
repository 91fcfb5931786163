"""``python -m orchestrator`` and ``python -m orchestrator.cli`` run the same command."""

from __future__ import annotations

import subprocess
import sys

import pytest


@pytest.mark.parametrize("module", ["orchestrator", "orchestrator.cli"])
def test_both_modules_run_the_command(module: str, tmp_path) -> None:
    done = subprocess.run(
        [sys.executable, "-m", module, "report", str(tmp_path)], capture_output=True, text=True
    )
    assert done.returncode == 2
    assert done.stderr == f"error: {tmp_path / 'summary.json'} not found: not a run directory\n"
    usage = subprocess.run([sys.executable, "-m", module, "--help"], capture_output=True, text=True)
    assert usage.returncode == 0 and usage.stdout.startswith("usage: mechcosim")
