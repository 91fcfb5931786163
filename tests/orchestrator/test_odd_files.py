"""Files a command reads are read only if they are regular files below a size limit: a
named pipe or a link to /dev/zero ends in one line naming the file, never a hang or a
MemoryError; ``export --force`` never replaces a file the scene reads."""

from __future__ import annotations

import os
import signal
from collections.abc import Iterator
from pathlib import Path

import pytest

from orchestrator.cli import main
from orchestrator.regular_files import NotARegularFile, read_regular

SCENE = """
[scene]
name = "odd"
start = "0 s"
stop = "1 ms"

[fmus.a]
{fmu}
inputs = {{ tau = {{ file = "torque.csv" }} }}

[master]
algorithm = "jacobi"
step = "0.1 ms"
"""


@pytest.fixture(autouse=True)
def no_hang() -> Iterator[None]:
    """A read that blocks fails the test instead of hanging the suite."""

    def fail(signum: int, frame: object) -> None:
        raise TimeoutError("blocked reading a file")

    previous = signal.signal(signal.SIGALRM, fail)
    signal.alarm(20)
    try:
        yield
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)


def _scene(tmp_path: Path, fmu: str = 'component = "Inertia"') -> Path:
    path = tmp_path / "odd.toml"
    path.write_text(SCENE.format(fmu=fmu))
    return path


def _one_line(capsys: pytest.CaptureFixture, argv: list[str]) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    return err


def test_a_named_pipe_as_a_signal_file_is_refused(tmp_path: Path, capsys) -> None:
    scene = _scene(tmp_path)
    os.mkfifo(tmp_path / "torque.csv")
    err = _one_line(capsys, ["check", str(scene)])
    assert f"{tmp_path / 'torque.csv'} is a named pipe, not a regular file" in err
    assert "[fmus.a.inputs.tau.file]" in err


def test_a_link_to_dev_zero_as_a_signal_file_is_refused(tmp_path: Path, capsys) -> None:
    scene = _scene(tmp_path)
    (tmp_path / "torque.csv").symlink_to("/dev/zero")
    err = _one_line(capsys, ["check", str(scene)])
    assert "torque.csv is a character device, not a regular file" in err


def test_a_named_pipe_as_the_scene_or_its_design_is_refused(tmp_path: Path, capsys) -> None:
    os.mkfifo(tmp_path / "pipe.toml")
    err = _one_line(capsys, ["check", str(tmp_path / "pipe.toml")])
    assert err == f"error: {tmp_path / 'pipe.toml'}: is a named pipe, not a regular file; " \
        "expected a file\n"  # fmt: skip
    (tmp_path / "design.toml").symlink_to("/dev/zero")
    text = (Path(__file__).parents[2] / "scenarios" / "m739.toml").read_text()
    scene = tmp_path / "m739.toml"
    scene.write_text(text.replace("[scene]\n", '[scene]\ndesign = "design.toml"\n', 1))
    err = _one_line(capsys, ["check", str(scene)])
    assert "design.toml: is a character device, not a regular file" in err


def test_a_named_pipe_or_a_device_as_summary_is_refused(tmp_path: Path, capsys) -> None:
    run = tmp_path / "run"
    run.mkdir()
    os.mkfifo(run / "summary.json")
    err = _one_line(capsys, ["report", str(run)])
    assert err == f"error: {run / 'summary.json'} is a named pipe, not a regular file; " \
        "expected a file\n"  # fmt: skip
    (run / "summary.json").unlink()
    (run / "summary.json").symlink_to("/dev/zero")
    err = _one_line(capsys, ["report", str(run)])
    assert "summary.json is a character device" in err


def test_a_file_over_the_limit_is_refused_without_reading_it(tmp_path: Path) -> None:
    big = tmp_path / "big.csv"
    with open(big, "wb") as f:
        f.truncate(3 << 20)  # sparse: 3 MB that cost nothing
    with pytest.raises(NotARegularFile) as err:
        read_regular(big, 2 << 20)
    assert err.value.strerror == "is 3.0 MB, more than the limit of 2 MB"
    assert len(read_regular(big, 3 << 20)) == 3 << 20


def test_export_force_never_replaces_a_file_the_scene_reads(tmp_path: Path, capsys) -> None:
    from fmus.build import build_fmu

    fmu = tmp_path / "Model.fmu"
    fmu.write_bytes(build_fmu("Inertia").read_bytes())
    (tmp_path / "torque.csv").write_text("time [s],tau [N*m]\n0,0\n1,1\n")
    scene = _scene(tmp_path, 'fmu = "Model.fmu"')
    before = fmu.read_bytes()
    err = _one_line(capsys, ["export", str(scene), str(fmu), "--force"])
    assert err == (
        f"error: {fmu}: is the FMU of fmus.a; an export never replaces a file the scene reads\n"
    )
    assert fmu.read_bytes() == before
    err = _one_line(capsys, ["export", str(scene), str(tmp_path / "torque.csv"), "--force"])
    assert "is the signal file of fmus.a.tau; an export never replaces" in err
    assert (tmp_path / "torque.csv").read_text().startswith("time [s],tau [N*m]")


@pytest.mark.parametrize("kind", ["pipe", "directory"])
def test_an_fmu_that_is_no_regular_file_is_refused_by_name(tmp_path, capsys, kind) -> None:
    odd = tmp_path / "Model.fmu"
    if kind == "pipe":
        os.mkfifo(odd)
    else:
        odd.mkdir()
    (tmp_path / "torque.csv").write_text("time [s],tau [N.m]\n0,0\n")
    err = _one_line(capsys, ["check", str(_scene(tmp_path, 'fmu = "Model.fmu"'))])
    expected = "is a named pipe, not a regular file" if kind == "pipe" else "is a directory"
    assert "[fmus.a.fmu]" in err and str(odd) in err and expected in err, err
