"""Study inputs are checked: --samples is bounded like [study], --workers is capped at the
samples to run, a samples.csv that is no samples file is refused naming file and line, and
a study whose first samples all fail alike stops and says so."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from study_scene import scene_file

from orchestrator.cli import main
from orchestrator.errors import ScenarioError
from orchestrator.studies import jobs
from orchestrator.studies.study_table import MAX_SAMPLES
from orchestrator.studies.tolerance_study import EARLY_FAILURES, FAILED, run_study


@pytest.fixture(scope="module")
def done(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """A scene with a [study] and the output of 3 of its samples."""
    d = tmp_path_factory.mktemp("study_inputs")
    path = scene_file(d)
    out = d / "out"
    run_study(path, samples=3, workers=1, output_dir=out, show_progress=False)
    return path, out


def resumed(done: tuple[Path, Path], tmp_path: Path, edit) -> str:  # noqa: ANN001
    """The error of resuming the study from its samples.csv ``edit``ed (bytes -> bytes)."""
    path, out = done
    copy = tmp_path / "out"
    shutil.copytree(out, copy)
    csv = copy / "samples.csv"
    csv.write_bytes(edit(csv.read_bytes()))
    with pytest.raises(ScenarioError) as info:
        run_study(path, samples=3, workers=1, output_dir=copy, resume=True, show_progress=False)
    message = str(info.value)
    assert message.startswith(f"{csv}: ")
    return message


def test_samples_on_the_command_line_are_bounded(done, capsys: pytest.CaptureFixture) -> None:
    path, _ = done
    assert main(["study", str(path), "--samples", "200000000", "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert f"--samples: 200000000 is more than {MAX_SAMPLES}" in err


def test_workers_are_capped_at_the_samples_and_the_cap_is_said(done, tmp_path: Path) -> None:
    path, _ = done
    result = run_study(path, samples=2, workers=200, output_dir=tmp_path, show_progress=False)
    assert result.notes == ["--workers 200 capped at 2: no more workers than samples to run"]
    assert len(result.samples) == 2


def test_a_non_numeric_cell_names_file_line_and_column(done, tmp_path: Path) -> None:
    def edit(data: bytes) -> bytes:
        lines = data.split(b"\n")
        cells = lines[2].split(b",")
        cells[1] = b"fast"
        lines[2] = b",".join(cells)
        return b"\n".join(lines)

    message = resumed(done, tmp_path, edit)
    assert "[line 3]" in message and "is 'fast', not a number" in message


def test_a_huge_sample_index_is_refused(done, tmp_path: Path) -> None:
    def edit(data: bytes) -> bytes:
        lines = data.split(b"\n")
        lines[2] = b"99999999999" + lines[2][lines[2].index(b",") :]
        return b"\n".join(lines)

    message = resumed(done, tmp_path, edit)
    assert "[line 3] sample index 99999999999 is beyond any study" in message


@pytest.mark.parametrize("junk", [b"\x89PNG\r\n\x1a\n\xff\xfe", b"\x00\x00\x00"])
def test_binary_content_is_refused(done, tmp_path: Path, junk: bytes) -> None:
    message = resumed(done, tmp_path, lambda data: data + junk)
    assert "not a text file" in message or "binary content" in message


def test_a_study_whose_first_samples_fail_alike_stops(
    done, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture
) -> None:
    path, _ = done

    def broken(job: jobs.Job) -> jobs.JobResult:
        raise ImportError("No module named 'orchestrator'")

    monkeypatch.setattr(jobs, "run_job", broken)
    argv = ["study", str(path), "--samples", "12", "--workers", "1", "--no-progress"]
    assert main([*argv, "--output", str(tmp_path / "a")]) == 1
    err = capsys.readouterr().err
    assert (
        f"the first {EARLY_FAILURES} samples all failed with the same error "
        "(ImportError: No module named 'orchestrator'): stopped; give --keep-going" in err
    )
    lines = (tmp_path / "a" / "samples.csv").read_text().splitlines()
    assert len(lines) == 1 + EARLY_FAILURES
    result = run_study(
        path, samples=12, workers=1, output_dir=tmp_path / "b", show_progress=False, keep_going=True
    )
    assert result.stopped is None and len(result.samples) == 12
    assert all(s.status == FAILED for s in result.samples)
