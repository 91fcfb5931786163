"""The supervised child of ``mechcosim run``: its exit code and output pass through
unchanged, and a death before it finished its work is reported, with or without a run."""

from __future__ import annotations

import json
import os
import signal
from pathlib import Path
from types import SimpleNamespace

import pytest

from orchestrator import flight
from orchestrator.interrupt import catching_signals
from orchestrator.supervisor import supervised


def test_exit_code_and_output_pass_through(capsys: pytest.CaptureFixture) -> None:
    def work() -> int:
        print("from the child")
        return 7

    with catching_signals() as guard:
        assert supervised(work, guard) == 7
    assert capsys.readouterr().out == "from the child\n"


def test_a_crash_before_the_run_began(capsys: pytest.CaptureFixture) -> None:
    def work() -> int:
        os.kill(os.getpid(), signal.SIGSEGV)
        return 0

    with catching_signals() as guard:
        assert supervised(work, guard) == 1
    assert capsys.readouterr().err == (
        "error: the command crashed before its run began: killed by SIGSEGV (signal 11)\n"
    )


def test_an_exit_outside_any_fmi_call_names_the_last_fmu(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    scene = SimpleNamespace(name="s", path=tmp_path / "s.toml", start=0.5, fmus={})

    def work() -> int:
        flight.announce_run(scene, tmp_path)
        flight.current().register("gear")
        os._exit(9)  # as an exit() would, after the call returned

    with catching_signals() as guard:
        assert supervised(work, guard) == 1
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["status"] == "crashed" and summary["time_reached"] == 0.5
    assert summary["crash"] == {
        "cause": "exit code 9 (an exit() before the run had ended)",
        "signal": None,
        "exit_code": 9,
        "fmu": "gear",
        "call": None,
    }
    assert "outside any FMI call (last FMU called: 'gear')" in capsys.readouterr().out


CRASH_UNDER_A_FAULT_HANDLER = """
import os, signal
from orchestrator.interrupt import catching_signals
from orchestrator.supervisor import supervised

def work():
    os.kill(os.getpid(), signal.SIGSEGV)
    return 0

with catching_signals() as guard:
    raise SystemExit(supervised(work, guard))
"""


def test_a_crash_under_a_fault_handler_is_reported_once() -> None:
    """A fault handler the command inherits (``-X faulthandler``, pytest's) does not dump the
    child's stack: the parent's one-line report is the whole of stderr."""
    import subprocess
    import sys

    proc = subprocess.run(
        [sys.executable, "-X", "faulthandler", "-c", CRASH_UNDER_A_FAULT_HANDLER],
        cwd=Path(__file__).resolve().parents[2],
        env={**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2])},
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert proc.returncode == 1
    assert proc.stderr == (
        "error: the command crashed before its run began: killed by SIGSEGV (signal 11)\n"
    )
