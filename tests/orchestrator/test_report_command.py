"""``mechcosim report RUN_DIR`` prints what ``mechcosim run`` printed as it ended, from the
run's summary.json, for a completed, failed, interrupted or crashed run; ``--json`` the
summary itself."""

from __future__ import annotations

import json
import os
import signal
from pathlib import Path

import pytest

from orchestrator.cli import main
from orchestrator.system import CoupledSystem

TWO = Path(__file__).resolve().parents[2] / "scenarios" / "two_inertias.toml"
#: 20 ms at the scene's fixed 0.1 ms step: 200 macro steps, two doSteps each
SHORT = ["--set", "scene.stop=20 ms"]


def _run(out: Path, capsys: pytest.CaptureFixture, *extra: str) -> tuple[int, str]:
    code = main(["run", str(TWO), "--output", str(out), "--no-progress", "--in-process", *extra])
    return code, capsys.readouterr().out


def _report(out: Path, capsys: pytest.CaptureFixture, *extra: str) -> str:
    assert main(["report", str(out), *extra]) == 0
    return capsys.readouterr().out


def test_report_of_a_completed_run_is_what_the_run_printed(tmp_path: Path, capsys) -> None:
    code, printed = _run(tmp_path, capsys, *SHORT)
    assert code == 0
    text = _report(tmp_path, capsys)
    assert text == printed
    lines = text.splitlines()
    assert lines[0] == "scene two_inertias: completed"
    assert lines[-2].startswith("  steps 200, doSteps 400, rejections 0, rollbacks 0, events 0")
    assert lines[-1] == f"  results in {tmp_path}"
    units = {line.split()[0]: line.split()[2:] for line in lines[1:-2]}
    assert units["final_angle_a"] == ["rad"] and units["peak_coupling_torque"] == ["N.m"]
    assert "trajectory_error" in units  # the error against the closed form
    raw = json.loads(_report(tmp_path, capsys, "--json"))
    assert raw == json.loads((tmp_path / "summary.json").read_text())


def test_report_of_a_failed_run_says_why_first(tmp_path: Path, capsys) -> None:
    code, printed = _run(tmp_path, capsys, *SHORT, "--set", "fmus.b.parameters.max_twist=0.03 rad")
    assert code == 1
    text = _report(tmp_path, capsys)
    assert text == printed
    first = text.splitlines()[0]
    assert first.startswith("scene two_inertias: failed — FMU 'b'") and "t = " in first
    assert json.loads(_report(tmp_path, capsys, "--json"))["status"] == "failed"


def test_report_of_an_interrupted_run_says_where_it_stopped(
    tmp_path: Path, capsys, monkeypatch: pytest.MonkeyPatch
) -> None:
    original = CoupledSystem.record_row
    sent = []

    def interrupting(self: CoupledSystem, t: float) -> list[float]:
        if t >= 5e-3 and not sent:  # a Ctrl-C during the run: it stops at the next step
            sent.append(t)
            os.kill(os.getpid(), signal.SIGINT)
        return original(self, t)

    monkeypatch.setattr(CoupledSystem, "record_row", interrupting)
    code, printed = _run(tmp_path, capsys, *SHORT)
    assert code == 128 + signal.SIGINT
    text = _report(tmp_path, capsys)
    assert text == printed
    lines = text.splitlines()
    assert lines[0].startswith("scene two_inertias: interrupted — interrupted by SIGINT")
    summary = json.loads((tmp_path / "summary.json").read_text())
    reached = summary["time_reached"]
    assert 5e-3 <= reached < 20e-3
    assert f"  interrupted at t = {reached:.9g} s (simulated)" in lines
    assert json.loads(_report(tmp_path, capsys, "--json"))["status"] == "interrupted"


def test_report_of_a_crashed_run(tmp_path: Path, capsys) -> None:
    # summary.json as the supervisor writes it for a child that died in an FMU
    # (orchestrator/supervisor.py): no headline, the wall time its only statistic.
    message = "FMU 'b' crashed in fmi2DoStep at t = 0.01 s: killed by SIGSEGV (signal 11)"
    summary = {
        "scene": "two_inertias",
        "status": "crashed",
        "message": message,
        "time_reached": 0.01,
        "crash": {"cause": "killed by SIGSEGV (signal 11)", "signal": 11, "exit_code": None},
        "headline": {},
        "accuracy": {},
        "notes": ["the run's process crashed: the series hold every step completed before it"],
        "stats": {"wall_time": 0.25},
        "metadata": {},
    }
    (tmp_path / "summary.json").write_text(json.dumps(summary))
    assert _report(tmp_path, capsys).splitlines() == [
        f"scene two_inertias: crashed — {message}",
        "  note: the run's process crashed: the series hold every step completed before it",
        "  wall time 0.250 s",
        f"  results in {tmp_path}",
    ]
    assert json.loads(_report(tmp_path, capsys, "--json")) == summary


def test_report_of_a_run_that_never_started(tmp_path: Path, capsys) -> None:
    (tmp_path / "summary.json").write_text(
        json.dumps({"scene": "s", "status": "failed", "message": "cannot load FMU 'a'\nmore"})
    )
    assert _report(tmp_path, capsys).splitlines() == [
        "scene s: failed — cannot load FMU 'a' (full message in summary.json)",
        "  no steps taken",
        f"  results in {tmp_path}",
    ]
