"""``mechcosim report`` on any run directory: a run in progress (its lock held: the rows
so far), a run killed with its supervisor (rebuilt from timeseries.csv and the lock file
it left, marked incomplete), and a run that left only summary.json.part."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from orchestrator.cli import main
from orchestrator.output_lock import LOCK_NAME, OutputLock

TWO = Path(__file__).resolve().parents[2] / "scenarios" / "two_inertias.toml"
HEADER = "time,a.phi,a.w\n"


def _report(run: Path, capsys: pytest.CaptureFixture, *extra: str) -> str:
    assert main(["report", str(run), *extra]) == 0
    return capsys.readouterr().out


def _series(run: Path, rows: int, cut: bool = False) -> None:
    """``rows`` whole rows at t = k * 0.1 ms, and half of one more when ``cut``."""
    lines = [f"{k * 1e-4!r},{k * 1e-3!r},10.0\n" for k in range(rows)]
    (run / "timeseries.csv").write_text(HEADER + "".join(lines) + ("0.0162,0.01" if cut else ""))
    (run / "events.csv").write_text("time,subsystem,from,to\n")


def test_a_run_in_progress_says_so_with_its_rows_so_far(tmp_path: Path, capsys) -> None:
    (tmp_path / "summary.json").write_text('{"status": "completed", "scene": "earlier"}')
    with OutputLock(tmp_path, {"scene": "two_inertias", "stop": 0.5}):
        _series(tmp_path, 40)
        lines = _report(tmp_path, capsys).splitlines()
        summary = json.loads(_report(tmp_path, capsys, "--json"))
    assert lines[0].startswith("scene two_inertias: running — in progress (pid ")
    assert lines[0].endswith("40 rows recorded so far, t = 0.0039 s of 0.5 s")
    assert "  rows recorded 40, events recorded 0" in lines
    assert summary["status"] == "running" and summary["rebuilt"] is True


def test_a_killed_run_is_rebuilt_from_its_series_and_marked_incomplete(
    tmp_path: Path, capsys
) -> None:
    # What a run killed with its supervisor leaves: the series (a row cut in the middle)
    # and its lock file, no longer held, naming the scene and the process.
    _series(tmp_path, 162, cut=True)
    owner = {"pid": 12345, "host": "h", "scene": "two_inertias", "stop": 0.5}
    (tmp_path / LOCK_NAME).write_text(json.dumps(owner))
    lines = _report(tmp_path, capsys).splitlines()
    assert lines[0] == (
        "scene two_inertias: incomplete — incomplete: the run (pid 12345 on h) ended without a "
        "summary, killed with its supervisor; 162 rows recorded, t = 0.0161 s of 0.5 s"
    )
    assert "  rows recorded 162, events recorded 0" in lines
    assert json.loads(_report(tmp_path, capsys, "--json"))["time_reached"] == 161e-4


def test_only_a_partial_summary_is_read_with_a_note(tmp_path: Path, capsys) -> None:
    code = main(["run", str(TWO), "--output", str(tmp_path), "--no-progress", "--in-process",
                 "--no-plot", "--set", "scene.stop=5 ms"])  # fmt: skip
    assert code == 0
    printed = capsys.readouterr().out
    (tmp_path / "summary.json").rename(tmp_path / "summary.json.part")
    lines = _report(tmp_path, capsys).splitlines()
    assert lines[0] == printed.splitlines()[0] == "scene two_inertias: completed"
    assert "  note: only summary.json.part was found: the run ended while writing its " \
        "summary, which is read as it stands" in lines  # fmt: skip
    # A summary.json.part cut short (a full disk): rebuilt from the series instead.
    (tmp_path / "summary.json.part").write_text("")
    lines = _report(tmp_path, capsys).splitlines()
    assert lines[0].startswith("scene t")  # no lock file: named after the directory
    assert "51 rows recorded, t = 0.005 s" in lines[0]
