"""A foreign FMU that crashes the process (segfault, abort(), exit()) in doStep does not take
the run's data along: summary.json says "crashed" with the FMU, the FMI call, the signal or
exit code and the time reached, and timeseries.csv holds every step completed before."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import foreign_fmus
import numpy as np
import pytest
from foreign_fmus import TORSION_BODY_SCENE

from orchestrator.cli import main

if foreign_fmus.c_compiler() is None:
    pytest.skip("no C compiler to build the foreign test FMUs", allow_module_level=True)

PROJECT_DIR = Path(__file__).resolve().parents[2]
FAULT_TIME = 0.01  # s: the eleventh doStep (1 ms steps) crashes
CRASHES = {"segfault": ("signal", 11), "abort": ("signal", 6), "exit": ("exit_code", 3)}


def scene_with(directory: Path, fault: str | None, name: str) -> Path:
    fmu = foreign_fmus.build_torsion_body(directory, fault=fault, fault_time=FAULT_TIME)
    path = directory / f"{name}.toml"
    text = TORSION_BODY_SCENE.format(fmu=fmu, phi0=0.1).replace(
        'name = "deg_parameter"', f'name = "{name}"'
    )
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def scenes(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    d = tmp_path_factory.mktemp("crashing")
    try:
        return {f: scene_with(d, f, f) for f in (*CRASHES, None)}
    except foreign_fmus.ForeignFmuError as exc:
        pytest.skip(str(exc))


@pytest.fixture(scope="module")
def healthy_rows(scenes: dict[str, Path], tmp_path_factory: pytest.TempPathFactory) -> np.ndarray:
    out = tmp_path_factory.mktemp("healthy")
    assert main(["run", str(scenes[None]), "--no-progress", "--output", str(out)]) == 0
    return np.loadtxt(out / "timeseries.csv", delimiter=",", skiprows=1)


def assert_crashed(out: Path, fault: str, healthy: np.ndarray) -> dict:
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "crashed"
    assert summary["crash"]["fmu"] == "c" and summary["crash"]["call"] == "fmi2DoStep"
    key, value = CRASHES[fault]
    assert summary["crash"][key] == value
    assert summary["time_reached"] == pytest.approx(FAULT_TIME)
    assert "FMU 'c' crashed in fmi2DoStep at t = 0.01 s" in summary["message"]
    rows = np.loadtxt(out / "timeseries.csv", delimiter=",", skiprows=1)
    # every completed step, to the last bit: t = 0, 1 ms, ..., 10 ms
    assert rows.shape[0] == 11
    np.testing.assert_array_equal(rows, healthy[:11])
    assert (out / "events.csv").read_text().startswith("time,subsystem,from,to")
    return summary


@pytest.mark.parametrize("fault", list(CRASHES))
def test_a_crash_in_do_step_ends_the_run_with_its_data(
    fault: str,
    scenes: dict[str, Path],
    healthy_rows: np.ndarray,
    tmp_path: Path,
    capsys: pytest.CaptureFixture,
) -> None:
    code = main(["run", str(scenes[fault]), "--no-progress", "--output", str(tmp_path)])
    assert code == 1
    out = capsys.readouterr().out
    assert f"scene {fault}: crashed — FMU 'c' crashed in fmi2DoStep at t = 0.01 s" in out
    assert_crashed(tmp_path, fault, healthy_rows)


def test_the_command_survives_a_segfault(
    scenes: dict[str, Path], healthy_rows: np.ndarray, tmp_path: Path
) -> None:
    """The installed command, in its own process (nothing in this test's process to help)."""
    proc = subprocess.run(
        [sys.executable, "-m", "orchestrator", "run", str(scenes["segfault"]), "--no-progress"]
        + ["--output", str(tmp_path)],
        cwd=PROJECT_DIR,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 1, proc.stderr
    assert "killed by SIGSEGV (signal 11)" in proc.stdout
    assert_crashed(tmp_path, "segfault", healthy_rows)
    assert not (tmp_path / "summary.json.part").exists()


def test_in_process_runs_are_unchanged(scenes: dict[str, Path], tmp_path: Path) -> None:
    """--in-process: no supervisor; a healthy run is the same run."""
    code = main(
        ["run", str(scenes[None]), "--in-process", "--no-progress"] + ["--output", str(tmp_path)]
    )
    assert code == 0
    assert json.loads((tmp_path / "summary.json").read_text())["status"] == "completed"
