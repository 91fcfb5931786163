"""Every failure ends in a clear message with the data kept; nothing nonsensical runs.

Non-finite outputs and NaN-aware metrics, the results-directory lock, analyses that cannot
be computed, nonsense refused at load, and one-line command-line errors.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from orchestrator.accuracy import compare, nan_max
from orchestrator.cli import main
from orchestrator.errors import RunError, ScenarioError
from orchestrator.output_lock import LOCK_NAME, OutputInUseError, OutputLock
from orchestrator.recorder import Recorder
from orchestrator.run import run_scene
from orchestrator.scenario import load_scene
from orchestrator.scenes.family import Reference
from orchestrator.system import CoupledSystem

PROJECT_DIR = Path(__file__).resolve().parents[2]
SCENARIOS = PROJECT_DIR / "scenarios"
TWO = SCENARIOS / "two_inertias.toml"
M739 = SCENARIOS / "m739.toml"
PRESS = SCENARIOS / "press_feed_run1.toml"
LEVER = SCENARIOS / "lever_unit_decay.toml"
SHORT = {"scene.stop": "10 ms"}


# -- 2. non-finite values --------------------------------------------------------------------
def test_recorder_refuses_a_non_finite_value_after_keeping_it(tmp_path: Path) -> None:
    rec = Recorder(tmp_path, ["a.x", "a.y"])
    rec.row([0.0, 1.0, 2.0])
    rec.row([0.0, 1e308, 1e308])  # a sum that overflows is not a non-finite value
    with pytest.raises(RunError, match=r"t = 0\.5 s: a\.y is nan, not finite"):
        rec.row([0.5, 1.0, math.nan])
    assert len(rec.rows) == 3


def test_a_non_finite_output_fails_the_run_naming_variable_and_time(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    original = CoupledSystem.record_row

    def overflowing(self: CoupledSystem, t: float) -> list[float]:
        row = original(self, t)
        if t >= 5e-3 - 1e-12:
            row[self.record_header.index("a.w") + 1] = math.inf
        return row

    monkeypatch.setattr(CoupledSystem, "record_row", overflowing)
    result = run_scene(
        load_scene(TWO, SHORT), output_dir=tmp_path, show_progress=False, plots=False
    )
    assert result.status == "failed"
    assert "a.w is inf, not finite" in result.message and "t = 0.005 s" in result.message
    summary = json.loads((tmp_path / "summary.json").read_text())  # strict JSON: no inf
    assert summary["status"] == "failed" and summary["time_reached"] == pytest.approx(5e-3)
    assert len(np.loadtxt(tmp_path / "timeseries.csv", delimiter=",", skiprows=1)) == 51


def _reference(headline, t_range=None, phi=None) -> Reference:
    def signals(times):
        return {} if phi is None else {"a.phi": phi(times)}

    return Reference(headline=headline, signals=signals, t_range=t_range)


def test_metrics_are_nan_aware() -> None:
    assert math.isnan(nan_max([1.0, math.nan])) and math.isnan(nan_max([math.nan, 1.0]))
    header = ["time", "a.phi"]
    data = np.array([[0.0, 0.0], [1.0, math.nan], [2.0, 2.0]])
    q = {"x": {"value": math.nan, "unit": "1"}, "y": {"value": 1.0, "unit": "1"}}
    ref = _reference({"x": 1.0, "y": 2.0}, phi=lambda t: t)
    acc = compare(header, data, [], q, ref)
    assert math.isnan(acc["headline_error"])  # max() would have given 0.5 or NaN by order
    assert math.isnan(acc["trajectory_error"])


def test_trajectory_error_only_where_run_and_reference_overlap() -> None:
    header = ["time", "a.phi"]
    data = np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 5.0]])
    notes: list[str] = []
    acc = compare(header, data, [], {}, _reference({}, (0.0, 1.0), lambda t: t), notes)
    assert acc["trajectory_error"] == 0.0  # t = 2 lies beyond the reference: not compared
    assert "only" in notes[0] and "0 .. 1 s" in notes[0]
    notes = []
    acc = compare(header, data, [], {}, _reference({}, (0.0, 0.0), lambda t: 0 * t), notes)
    assert math.isnan(acc["trajectory_error"]) and "no common time range" in notes[0]


def test_stalled_m739_reports_no_trajectory_error_instead_of_extrapolating(
    tmp_path: Path,
) -> None:
    stall = {"parameters.mu": 0.18, "fmus.verge.parameters.mu1": 0.18, "scene.stop": "20 ms"}
    result = run_scene(
        load_scene(M739, stall), output_dir=tmp_path, show_progress=False, plots=False
    )
    assert result.status == "completed"
    assert "stalled" in result.headline["not_armed_reason"]["value"]
    assert math.isnan(result.accuracy["trajectory_error"])  # was 1.1e+294
    assert any("no common time range" in n for n in result.notes), result.notes


# -- 3. the results directory is locked ------------------------------------------------------
def test_second_run_into_a_locked_directory_is_refused(tmp_path: Path, capsys) -> None:
    with OutputLock(tmp_path):
        with pytest.raises(OutputInUseError):
            OutputLock(tmp_path).acquire()
        code = main(["run", str(TWO), "--no-progress", "--output", str(tmp_path)])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and "in use by another run" in err and f"pid {os.getpid()}" in err
    assert not (tmp_path / "summary.json").exists()


def test_stale_lock_of_a_dead_process_is_taken_over(tmp_path: Path) -> None:
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    (tmp_path / LOCK_NAME).write_text(json.dumps({"pid": dead.pid, "host": "here"}))
    result = run_scene(
        load_scene(TWO, SHORT), output_dir=tmp_path, show_progress=False, plots=False
    )
    assert result.status == "completed"
    assert not (tmp_path / LOCK_NAME).exists()


# -- 4. analyses never crash after a run -----------------------------------------------------
def test_press_feed_shorter_than_a_cycle_says_what_is_missing(tmp_path: Path) -> None:
    scene = load_scene(PRESS, {"scene.stop": "5 ms"})
    result = run_scene(scene, output_dir=tmp_path, show_progress=False, plots=False)
    assert result.status == "completed"
    assert any("less than one crank cycle" in n for n in result.notes), result.notes
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert "energy_residual" in summary["headline"] and summary["notes"] == result.notes
    assert "warnings" not in summary["stats"]  # the notes once, not again as the master's


def test_m739_without_spin_has_no_reference_trajectory_but_ends(tmp_path: Path) -> None:
    scene = load_scene(M739, {"parameters.spin": "0 rpm", "scene.stop": "5 ms"})
    result = run_scene(scene, output_dir=tmp_path, show_progress=False, plots=False)
    assert result.status == "completed"
    assert "trajectory_error" in result.accuracy  # KeyError 't' before
    assert (tmp_path / "summary.json").exists()


@pytest.mark.parametrize(
    ("column", "expected"),
    [
        ("load.not_recorded", "it needs load.not_recorded recorded"),
        (None, "IndexError"),
    ],
)
def test_an_analysis_that_fails_leaves_a_note(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, column: str | None, expected: str
) -> None:
    import orchestrator.scenes.press_feed.report as pf

    def broken(scene, header, data, options):
        col = {name: data[:, i] for i, name in enumerate(header)}
        return {"y": col[column]} if column else {"y": data[len(data) + 5]}

    monkeypatch.setattr(pf, "analyse", broken)
    scene = load_scene(PRESS, {"scene.stop": "5 ms"})
    result = run_scene(scene, output_dir=tmp_path, show_progress=False, compare_reference=False)
    assert result.status == "completed"
    note = next(n for n in result.notes if "analysis 'press_feed' not computed" in n)
    assert expected in note and "\n" not in note
    assert "energy_residual" in json.loads((tmp_path / "summary.json").read_text())["headline"]


def test_missing_record_signal_and_bogus_option_caught_at_load() -> None:
    with pytest.raises(ScenarioError, match=r"\[output.record\].*train\.F12"):
        load_scene(M739, {"output.record": ["train.phi", "verge.regime"]})
    with pytest.raises(ScenarioError, match=r"\[report.options.bogus\] unknown key"):
        load_scene(M739, {"report.options.bogus": 1})
    with pytest.raises(ScenarioError, match=r"\[report.options.train\]"):
        load_scene(M739, {"report.options.train": "nobody"})
    with pytest.raises(ScenarioError, match=r"\[report.headline.x.signal\].*not recorded"):
        load_scene(TWO, {"report.headline.x": {"signal": "a.tau"}})


@pytest.mark.parametrize(
    ("scene", "key", "value", "fragment"),
    [
        (LEVER, "nominal_period", "-1 s", "positive quantity in s"),
        (LEVER, "load_step", "2 m", "N.m"),
        (LEVER, "lever", "nobody", "FMU instance"),
        (PRESS, "startup_cycles", 1.5, "whole number"),
        (PRESS, "decay_ratios", "yes", "true or false"),
    ],
)
def test_option_values_checked_at_load(scene: Path, key: str, value, fragment: str) -> None:
    """Each family declares the kind of its options; a wrong value never reaches a run."""
    with pytest.raises(ScenarioError, match=rf"\[report.options.{key}\]") as info:
        load_scene(scene, {f"report.options.{key}": value})
    assert fragment in str(info.value)


# -- 5. nonsense refused at load -------------------------------------------------------------
@pytest.mark.parametrize(
    ("scene", "overrides", "key", "fragment"),
    [
        (TWO, {"scene.stop": "inf s"}, "scene.stop", "finite"),
        (TWO, {"scene.start": "nan s"}, "scene.start", "finite"),
        (M739, {"master.tolerance": math.inf}, "master.tolerance", "finite"),
        (
            M739,
            {"master.min_step": "1 ms", "master.max_step": "1 us"},
            "master.max_step",
            "less than master.min_step",
        ),
        (TWO, {"output.directory": ""}, "output.directory", "expected a directory"),
        (TWO, {"master.step": "1e-12 s"}, "master.step", "--force"),
        (M739, {"master.first_step": "1e-15 s"}, "master.first_step", "--force"),
        # a shared parameter is stated once: the old per-FMU key names the new one
        (
            M739,
            {"fmus.verge.parameters.spin": "2e4 rpm"},
            "fmus.verge.parameters.spin",
            "spin rate",
        ),
        (M739, {"fmus.train.parameters.mu": 0.2}, "fmus.train.parameters.mu", "as parameters.mu"),
        # A design quantity is stated once: for the scene, or for the FMU that takes it.
        (M739, {"parameters.mu1": 0.2}, "fmus.verge.parameters.mu1", "state it once"),
        (M739, {"parameters.v_capture": 0.2}, "parameters.v_capture", "expected one of"),
        (TWO, {"parameters.spin": "0 rpm"}, "parameters.spin", "no FMU of the scene shares"),
        (M739, {"parameters.spin": "-1 rpm"}, "parameters.spin", "outside the valid range"),
    ],
)
def test_nonsense_refused_at_load(scene: Path, overrides: dict, key: str, fragment: str) -> None:
    with pytest.raises(ScenarioError) as info:
        load_scene(scene, overrides)
    assert str(scene) in str(info.value) and f"[{key}]" in str(info.value), info.value
    assert fragment in str(info.value)


def test_force_accepts_a_long_run() -> None:
    scene = load_scene(TWO, {"master.step": "1e-12 s"}, force=True)
    assert scene.master.step == 1e-12


# -- 6. one-line command-line errors ---------------------------------------------------------
def _one_line_error(capsys, argv: list[str], *fragments: str, code: int = 2) -> str:
    assert main(argv) == code
    err = capsys.readouterr().err
    assert err.startswith("error: ") and err.count("\n") == 1, err
    assert "Traceback" not in err
    for fragment in fragments:
        assert fragment in err, err
    return err


def test_cli_errors_are_one_line(tmp_path: Path, capsys, monkeypatch) -> None:
    binary = tmp_path / "binary.toml"
    binary.write_bytes(b"\x89PNG\r\n\x1a\n\x00\xff\xfe")
    _one_line_error(capsys, ["check", str(binary)], "not UTF-8")
    nested = tmp_path / "nested.toml"
    nested.write_text("a = " + "[" * 5000 + "]" * 5000)
    _one_line_error(capsys, ["check", str(nested)], "nested too deeply")
    _one_line_error(capsys, ["run", str(TWO), "--set", "scene.stop.x=1"], "not a table")
    _one_line_error(capsys, ["check", str(SCENARIOS)], "is a directory")
    a_file = tmp_path / "file"
    a_file.write_text("")
    _one_line_error(
        capsys, ["run", str(TWO), "--no-progress", "--output", str(a_file)], "is a file"
    )
    _one_line_error(
        capsys,
        ["run", str(TWO), "--no-progress", "--output", str(a_file / "sub")],
        "cannot create the results directory",
    )
    summary = tmp_path / "run"
    summary.mkdir()
    (summary / "summary.json").write_text('{"status": "compl')
    _one_line_error(capsys, ["report", str(summary)], "not a readable summary")
    monkeypatch.setenv("MECHCOSIM_FMU_CACHE", str(a_file))
    _one_line_error(capsys, ["check", str(TWO)], "FMU cache", "is a file")
    _one_line_error(capsys, ["run", str(TWO)], "FMU cache", "is a file")


@pytest.mark.parametrize(
    "argv, fragment",
    [
        (["check", "x.toml", "--set", "-x=1"], "--set: expected one argument"),
        (["frobnicate"], "invalid choice"),
        (["run"], "required: scene"),
        (["bench", "nonsense"], "invalid choice"),
    ],
)
def test_bad_arguments_are_one_line_too(capsys, argv: list[str], fragment: str) -> None:
    """argparse's own refusals end like every bad input: one line, exit 2."""
    with pytest.raises(SystemExit) as stop:
        main(argv)
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and err.count("\n") == 1, err
    assert fragment in err and "--help" in err, err


def test_debug_shows_the_traceback(tmp_path: Path) -> None:
    with pytest.raises(ScenarioError):
        main(["--debug", "check", str(tmp_path / "missing.toml")])


def test_report_of_an_interrupted_run(tmp_path: Path, capsys) -> None:
    (tmp_path / "summary.json").write_text(
        json.dumps({"scene": "s", "status": "interrupted", "time_reached": 0.1})
    )
    assert main(["report", str(tmp_path)]) == 0
    assert capsys.readouterr().out.splitlines()[:2] == [
        "scene s: interrupted",
        "  interrupted at t = 0.1 s (simulated)",
    ]
    assert main(["report", str(tmp_path), "--json"]) == 0
    assert '"time_reached": 0.1' in capsys.readouterr().out
