"""Every command that runs FMUs survives one that segfaults, loops or stops: that run (or
sample) ends "crashed" or "timed out" with the FMU, the call and the time, its series kept,
and every other run completes with the same numbers as a healthy run alone.

The TorsionBody here chooses its fault from its Integer parameter n_sub at the first doStep
from 10 ms on: 101 segfaults, 102 never returns, 103 raises SIGSTOP, 10 runs healthy."""

from __future__ import annotations

import csv
import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import foreign_fmus
import numpy as np
import pytest
from foreign_fmus import TORSION_BODY_SCENE

from orchestrator.cli import main

if foreign_fmus.c_compiler() is None:
    pytest.skip("no C compiler to build the foreign test FMUs", allow_module_level=True)

PROJECT_DIR = Path(__file__).resolve().parents[2]
FAULT_TIME = 0.01  # s: the eleventh doStep (1 ms steps)
HEALTHY, SEGFAULT, HANG, STOP = 10, 101, 102, 103
CALL_TIMEOUT = 0.5  # s
# What each n_sub ends as: (status, words of the message)
ENDINGS = {
    SEGFAULT: ("crashed", "FMU 'c' crashed in fmi2DoStep at t = 0.01 s: killed by SIGSEGV"),
    HANG: (
        "timed out",
        "FMU 'c' did not return from fmi2DoStep within 0.5 s (master.call_timeout) "
        "at t = 0.01 s: killed",
    ),
    STOP: (
        "crashed",
        "FMU 'c' crashed in fmi2DoStep at t = 0.01 s: stopped by SIGSTOP (signal 19), then killed",
    ),
}
SWEEP = [HEALTHY, SEGFAULT, HEALTHY, HANG, HEALTHY, STOP, HEALTHY]


def scene_text(fmu: Path, name: str, call_timeout: str = f"{CALL_TIMEOUT} s") -> str:
    text = TORSION_BODY_SCENE.format(fmu=fmu, phi0=0.1).replace(
        'name = "deg_parameter"', f'name = "{name}"'
    )
    text = text.replace('step = "1 ms"', f'step = "1 ms"\ncall_timeout = "{call_timeout}"')
    return text + '\n[report.headline]\nfinal_phi = { signal = "c.body.phi", reduce = "final" }\n'


@pytest.fixture(scope="module")
def fmu(tmp_path_factory: pytest.TempPathFactory) -> Path:
    try:
        return foreign_fmus.build_torsion_body(
            tmp_path_factory.mktemp("chosen"), fault="by_n_sub", fault_time=FAULT_TIME
        )
    except foreign_fmus.ForeignFmuError as exc:
        pytest.skip(str(exc))


@pytest.fixture(scope="module")
def healthy(fmu: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[float, np.ndarray]:
    """(final_phi, rows) of the healthy run alone."""
    d = tmp_path_factory.mktemp("healthy")
    (d / "h.toml").write_text(scene_text(fmu, "h"))
    assert main(["run", str(d / "h.toml"), "--no-progress", "--output", str(d / "out")]) == 0
    summary = json.loads((d / "out" / "summary.json").read_text())
    rows = np.loadtxt(d / "out" / "timeseries.csv", delimiter=",", skiprows=1)
    return summary["headline"]["final_phi"]["value"], rows


@pytest.fixture(scope="module")
def unfaulted_rows(tmp_path_factory: pytest.TempPathFactory) -> dict[int, np.ndarray]:
    """The series of a TorsionBody built without faults, at each faulting n_sub."""
    d = tmp_path_factory.mktemp("unfaulted")
    (d / "u.toml").write_text(scene_text(foreign_fmus.build_torsion_body(d), "u"))
    rows = {}
    for n_sub in ENDINGS:
        out = d / str(n_sub)
        args = ["run", str(d / "u.toml"), "--no-progress", "--in-process", "--output", str(out)]
        assert main([*args, "--set", f"fmus.c.parameters.n_sub={n_sub}"]) == 0
        rows[n_sub] = np.loadtxt(out / "timeseries.csv", delimiter=",", skiprows=1)
    return rows


def assert_ended(run_dir: Path, n_sub: int, unfaulted: dict[int, np.ndarray]) -> None:
    """The summary of a run that ended in its fault, and its series up to the fault."""
    status, words = ENDINGS[n_sub]
    summary = json.loads((run_dir / "summary.json").read_text())
    assert summary["status"] == status
    assert words in summary["message"]
    assert summary["crash"]["fmu"] == "c" and summary["crash"]["call"] == "fmi2DoStep"
    assert summary["time_reached"] == FAULT_TIME
    rows = np.loadtxt(run_dir / "timeseries.csv", delimiter=",", skiprows=1)
    np.testing.assert_array_equal(rows, unfaulted[n_sub][:11])  # t = 0 .. 10 ms, to the bit


@pytest.mark.parametrize("workers", ["1", pytest.param("2", marks=pytest.mark.slow)])
def test_a_sweep_goes_on_past_a_crash_a_hang_and_a_stop(
    workers: str,
    fmu: Path,
    healthy: tuple[float, np.ndarray],
    unfaulted_rows: dict[int, np.ndarray],
    tmp_path: Path,
    capsys: pytest.CaptureFixture,
) -> None:
    scene = tmp_path / "sweep.toml"
    values = ", ".join(str(v) for v in SWEEP)
    scene.write_text(
        scene_text(fmu, "sweep")
        + f'\n[sweep]\nparameter = "fmus.c.parameters.n_sub"\nvalues = [{values}]\n'
    )
    out = tmp_path / "out"
    code = main(["sweep", str(scene), "--workers", workers, "--output", str(out)])
    assert code == 1  # not every run completed
    capsys.readouterr()
    with open(out / "sweep.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert [int(float(r["value"])) for r in rows] == SWEEP
    for k, (row, n_sub) in enumerate(zip(rows, SWEEP, strict=True)):
        if n_sub == HEALTHY:
            assert row["status"] == "completed"
            assert float(row["final_phi"]) == healthy[0]
        else:
            assert row["status"] == ENDINGS[n_sub][0]
            assert ENDINGS[n_sub][1] in row["message"]
            assert_ended(out / f"base_{k:03d}", n_sub, unfaulted_rows)


@pytest.mark.filterwarnings("ignore:Data has no positive values")  # the study's plots of
@pytest.mark.filterwarnings("ignore:Tight layout not applied")  # only five samples
def test_a_study_marks_the_bad_samples_and_completes_the_others(
    fmu: Path,
    healthy: tuple[float, np.ndarray],
    unfaulted_rows: dict[int, np.ndarray],
    tmp_path: Path,
    capsys: pytest.CaptureFixture,
) -> None:
    scene = tmp_path / "study.toml"
    scene.write_text(
        scene_text(fmu, "study")
        + '\n[study]\nsamples = 10\nseed = 3\nsampling = "monte-carlo"\n'
        + 'quantities = ["final_phi"]\n\n[[study.inputs]]\nkey = "fmus.c.parameters.n_sub"\n'
        + f"values = [{HEALTHY}, {SEGFAULT}, {HANG}, {STOP}]\n"
    )
    out = tmp_path / "out"
    main(["study", str(scene), "--workers", "2", "--no-progress", "--output", str(out)])
    printed = capsys.readouterr().out
    assert "study study: 10 of 10 samples" in printed
    with open(out / "samples.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 10
    seen = set()
    for row in rows:
        n_sub = int(float(row["n_sub [1]"]))
        seen.add(n_sub)
        if n_sub == HEALTHY:
            assert row["status"] == "ok"
            assert float(row["final_phi"]) == healthy[0]
        else:
            assert row["status"] == "failed"
            assert ENDINGS[n_sub][1] in row["reason"]
            assert_ended(out / "samples" / f"{int(row['sample']):05d}", n_sub, unfaulted_rows)
    assert seen == {HEALTHY, SEGFAULT, HANG, STOP}  # seed 3 draws every kind


def test_run_ends_a_hang_and_a_stop(
    fmu: Path, unfaulted_rows: dict[int, np.ndarray], tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    (tmp_path / "s.toml").write_text(scene_text(fmu, "s"))
    for n_sub in (HANG, STOP):
        out = tmp_path / str(n_sub)
        args = ["run", str(tmp_path / "s.toml"), "--no-progress", "--output", str(out)]
        assert main([*args, "--set", f"fmus.c.parameters.n_sub={n_sub}"]) == 1
        assert f"scene s: {ENDINGS[n_sub][0]} — {ENDINGS[n_sub][1]}" in capsys.readouterr().out
        assert_ended(out, n_sub, unfaulted_rows)
        assert not (out / ".mechcosim.lock").exists()


def _command(args: list[str]) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "orchestrator", *args],
        cwd=PROJECT_DIR,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def _wait_for_rows(timeseries: Path, rows: int, timeout: float = 120.0) -> None:
    """Until the run has recorded ``rows`` rows (and so reached its fault)."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if timeseries.exists() and timeseries.read_text().count("\n") > rows:
            return
        time.sleep(0.05)
    raise AssertionError(f"{timeseries} never reached {rows} rows")


@pytest.mark.slow
def test_sigterm_reaches_a_run_stuck_in_an_fmu(fmu: Path, tmp_path: Path) -> None:
    """No call limit: the forwarded SIGTERM cannot be acted on, the child is killed after
    the grace period and the run summarized as interrupted."""
    (tmp_path / "s.toml").write_text(scene_text(fmu, "s", call_timeout="0 s"))
    out = tmp_path / "out"
    proc = _command(
        ["run", str(tmp_path / "s.toml"), "--no-progress", "--output", str(out)]
        + ["--set", f"fmus.c.parameters.n_sub={HANG}"]
    )
    _wait_for_rows(out / "timeseries.csv", 11)
    proc.send_signal(signal.SIGTERM)
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 128 + signal.SIGTERM, stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "interrupted"
    assert summary["message"].startswith(
        "interrupted by SIGTERM: FMU 'c' was in fmi2DoStep at t = 0.01 s and it did not stop "
        "within 5 s: killed"
    )
    assert "scene s: interrupted — interrupted by SIGTERM" in stdout


@pytest.mark.slow
def test_no_orphan_when_the_command_is_killed(fmu: Path, tmp_path: Path) -> None:
    """SIGKILL of the command while its run hangs: the run's process ends too."""
    (tmp_path / "s.toml").write_text(scene_text(fmu, "s", call_timeout="0 s"))
    out = tmp_path / "out"
    proc = _command(
        ["run", str(tmp_path / "s.toml"), "--no-progress", "--output", str(out)]
        + ["--set", f"fmus.c.parameters.n_sub={HANG}"]
    )
    _wait_for_rows(out / "timeseries.csv", 11)
    child = json.loads((out / ".mechcosim.lock").read_text())["pid"]  # the run's process
    assert child != proc.pid
    proc.kill()
    proc.communicate(timeout=30)
    end = time.monotonic() + 30
    while time.monotonic() < end and _alive(child):
        time.sleep(0.1)
    assert not _alive(child)


def _alive(pid: int) -> bool:
    """Running (a zombie waiting for init to reap it has ended)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state not in ("Z", "X")


def test_a_crash_in_fmi2terminate_keeps_the_finished_run(
    healthy: tuple[float, np.ndarray], tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    """The run had ended and written its summary: its headline stays, the crash is noted."""
    fmu = foreign_fmus.build_torsion_body(tmp_path, fault="terminate_segfault")
    (tmp_path / "t.toml").write_text(scene_text(fmu, "t"))
    out = tmp_path / "out"
    assert main(["run", str(tmp_path / "t.toml"), "--no-progress", "--output", str(out)]) == 1
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "completed"
    assert summary["headline"]["final_phi"]["value"] == healthy[0]
    assert summary["crash"]["call"] == "fmi2Terminate" and summary["crash"]["signal"] == 11
    note = "after the run ended: FMU 'c' crashed in fmi2Terminate at t = 0.02 s: killed by SIGSEGV"
    assert note in summary["notes"][-1]
    assert note in capsys.readouterr().out


def test_crosscheck_reports_a_crash_in_one_line(fmu: Path, tmp_path: Path, capsys) -> None:
    (tmp_path / "s.toml").write_text(scene_text(fmu, "s"))
    args = ["crosscheck", str(tmp_path / "s.toml"), "--tool", "fmpy"]
    assert main([*args, "--set", f"fmus.c.parameters.n_sub={SEGFAULT}"]) == 2
    assert capsys.readouterr().err == (
        "error: our Jacobi run did not complete: FMU 'c' crashed in fmi2DoStep at t = 0.01 s: "
        "killed by SIGSEGV (signal 11)\n"
    )


@pytest.mark.slow  # in the slow suite (CI runs it): the default stays under 2 minutes
def test_a_tool_whose_process_crashes_is_reported() -> None:
    """ctypes.string_at(0) reads address 0: the spawned process dies of SIGSEGV."""
    import ctypes

    from orchestrator.studies.crosscheck import ToolCrashed, _in_spawned_process

    with pytest.raises(ToolCrashed, match=r"^fmpy's process ended without an answer: killed by "):
        _in_spawned_process(ctypes.string_at, 0, "fmpy")
