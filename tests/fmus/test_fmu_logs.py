"""What an FMU says reaches the user, bounded: warnings counted per FMU and kind, shown once
per kind with their count and kept in summary.json; the log kept per instance is a ring of
its last lines; a long message is cut, its length said."""

from __future__ import annotations

import json
from pathlib import Path

import foreign_fmus
import pytest
from foreign_fmus import TORSION_BODY_SCENE

from orchestrator import fmu_log
from orchestrator.cli import main
from orchestrator.fmu_log import FmuLog

FAULT_TIME = 0.01  # s: warnings from the doStep at 10 ms on, to the stop at 20 ms
WARNED_STEPS = 10  # doSteps from 10 ms to 20 ms at 1 ms


def run(tmp_path: Path, fault: str, capsys: pytest.CaptureFixture) -> tuple[int, str, dict]:
    if foreign_fmus.c_compiler() is None:
        pytest.skip("no C compiler to build the foreign test FMUs")
    fmu = foreign_fmus.build_torsion_body(tmp_path, fault=fault, fault_time=FAULT_TIME)
    scene = tmp_path / "s.toml"
    scene.write_text(TORSION_BODY_SCENE.format(fmu=fmu, phi0=0.1).replace("deg_parameter", "s"))
    out = tmp_path / "out"
    code = main(["run", str(scene), "--no-progress", "--output", str(out)])
    return code, capsys.readouterr().out, json.loads((out / "summary.json").read_text())


def test_a_warning_status_at_every_step_is_counted_and_shown_once(tmp_path, capsys) -> None:
    code, printed, summary = run(tmp_path, "warning", capsys)
    assert code == 0 and summary["status"] == "completed"
    line = (
        "note: FMU 'c' warned 10 times (first at t = 0.01 s): step of 0.001 s larger than advised"
    )
    assert printed.count("warned") == 1 and line in printed
    assert summary["fmu_warnings"] == {
        "c": {
            "count": WARNED_STEPS,
            "kinds": 1,
            "first": [
                {
                    "message": "step of 0.001 s larger than advised",
                    "count": WARNED_STEPS,
                    "first_time": FAULT_TIME,
                }
            ],
        }
    }


def test_a_warning_logged_with_fmi2ok_is_counted_by_kind(tmp_path, capsys) -> None:
    """Each message names its own time: one kind all the same, the first one shown."""
    code, printed, summary = run(tmp_path, "log_warning", capsys)
    assert code == 0
    assert "FMU 'c' warned 10 times (first at t = 0.01 s): spring beyond its linear range at " in (
        printed
    )
    first = summary["fmu_warnings"]["c"]["first"]
    assert summary["fmu_warnings"]["c"]["count"] == WARNED_STEPS
    assert [k["message"] for k in first] == ["spring beyond its linear range at t = 0.01 s"]


def test_a_long_error_is_cut_and_its_length_said(tmp_path, capsys) -> None:
    """2000 lines, then 100000 characters, then fmi2Error: the message holds the last lines,
    says how many came before and how long the last one was (as it reached us)."""
    code, printed, summary = run(tmp_path, "long_error", capsys)
    assert code == 1 and summary["status"] == "failed"
    message = summary["message"]
    assert "(1991 earlier lines not shown) line 1991; line 1992;" in message
    # FMPy's logger proxy formats a message into 2048 bytes: 2047 characters arrive.
    assert message.endswith("; " + "x" * fmu_log.MAX_CHARS + "... [cut: 2047 characters]")
    assert len(message) < 2 * fmu_log.MAX_CHARS + 100
    assert len(printed) < 3 * fmu_log.MAX_CHARS + 1000


def test_the_log_kept_is_a_ring_and_warnings_are_counted_by_kind() -> None:
    log = FmuLog()
    for k in range(100_000):
        log.add(0, "logAll", f"line {k}", 0.0)
    assert log.count == 100_000 and len(log.lines) == fmu_log.KEPT_LINES
    assert log.since(99_998) == ["line 99998", "line 99999"]
    assert log.last(1) == "line 99999"
    for k in range(1000):
        log.add(fmu_log.WARNING, "logStatusWarning", f"slip of {k * 0.1:g} mm at t = {k} s", k)
        log.add(0, "logStatusWarning", f"limit {k} reached", k)
    log.returned_warning("fmi2DoStep", 7.0)  # the last line logged was its warning
    assert log.warnings == 2000
    log.add(0, "logAll", "fine", 8.0)
    log.returned_warning("fmi2DoStep", 8.0)  # no warning logged with it: one more
    assert log.warnings == 2001
    summary = log.summary()
    assert summary["count"] == 2001 and summary["kinds"] == 3
    assert summary["first"][0] == {"message": "slip of 0 mm at t = 0 s", "count": 1000,
                                   "first_time": 0.0}  # fmt: skip
    assert summary["first"][2] == {"message": "fmi2DoStep returned fmi2Warning", "count": 1,
                                   "first_time": 8.0}  # fmt: skip


def test_kinds_past_the_kept_ones_are_counted_together() -> None:
    log = FmuLog()
    words = [f"w{chr(97 + i)}{chr(97 + j)}" for i in range(5) for j in range(5)]  # 25 kinds
    for word in words:
        log.add(fmu_log.WARNING, "", f"{word} happened", 0.0)
    assert len(log.kinds) == fmu_log.KEPT_KINDS and log.other_warnings == 25 - fmu_log.KEPT_KINDS
    notes = log.notes("c")
    assert len(notes) == fmu_log.SHOWN_KINDS + 1
    assert notes[-1] == "FMU 'c': 20 more warnings of other kinds (summary.json)"


def test_a_line_is_cut_with_its_length() -> None:
    assert fmu_log.cut("y" * 1500) == "y" * 1000 + "... [cut: 1500 characters]"
    assert fmu_log.cut("short") == "short"
