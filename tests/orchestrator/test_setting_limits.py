"""Settings a run cannot honour are refused when the scene loads (mechcosim check), in one
line naming the key and the bound: a tolerance below 1e-12, a min_step longer than the
first step, a negative call_timeout, zero workers."""

from __future__ import annotations

from pathlib import Path

import pytest

from orchestrator.cli import main
from orchestrator.errors import ScenarioError
from orchestrator.scenario import load_scene

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
M739 = SCENARIOS / "m739.toml"  # regime-aware, first_step 1 us


@pytest.mark.parametrize(
    ("overrides", "words"),
    [
        ({"master.tolerance": 1e-13}, "[master.tolerance] must be at least 1e-12"),
        ({"master.min_step": "2 us"}, "[master.min_step] 2e-06 s is longer than the first step"),
        ({"master.call_timeout": "-1 s"}, "[master.call_timeout] must be positive (0 for none)"),
    ],
)
def test_out_of_range_settings_are_refused(overrides: dict, words: str) -> None:
    with pytest.raises(ScenarioError) as err:
        load_scene(M739, overrides)
    assert words in str(err.value)


def test_bounds_themselves_are_taken() -> None:
    scene = load_scene(
        M739, {"master.tolerance": 1e-12, "master.min_step": "1 us", "master.call_timeout": 0}
    )
    assert scene.master.settings.tolerance == 1e-12
    assert scene.master.settings.min_step == scene.master.step == 1e-6
    assert scene.master.settings.call_timeout == 0.0


def test_a_sweep_on_no_workers_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    scene = str(SCENARIOS / "clock_train_cd_sweep.toml")
    code = main(["sweep", scene, "--workers", "0", "--output", str(tmp_path)])
    assert code == 2
    assert capsys.readouterr().err == (
        "error: --workers: expected a positive number of workers, got 0\n"
    )


TWO = SCENARIOS / "two_inertias.toml"  # Jacobi, step 0.1 ms over 0.5 s, with a reference


def _refused(capsys: pytest.CaptureFixture, argv: list[str]) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    return err


def test_a_tolerance_above_one_is_refused() -> None:
    with pytest.raises(ScenarioError) as err:
        load_scene(M739, {"master.tolerance": 2.0})
    assert "[master.tolerance] must be at most 1" in str(err.value)


@pytest.mark.parametrize("option", ["--tolerances", "--start-hold-tolerances"])
def test_precision_refuses_tolerances_below_the_floor_before_any_run(
    option: str, tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    err = _refused(
        capsys, ["precision", str(TWO), option, "1e-3,1e-300", "--output", str(tmp_path)]
    )
    assert err == f"error: {option}: 1e-300 is outside 1e-12 .. 1 (the range of master.tolerance)\n"
    assert list(tmp_path.iterdir()) == []  # nothing ran


def test_step_factors_that_leave_no_step_within_the_run_are_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    argv = ["precision", str(TWO), "--step-factors", "1,1e9", "--output", str(tmp_path)]
    err = _refused(capsys, argv)
    # 0.5 s / 0.1 ms: the largest factor whose step fits in the run is 5000
    assert "--step-factors: 1e+09 times the scene's step (0.0001 s) is 100000 s" in err
    assert "the largest factor taken is 5000" in err


def test_a_study_of_one_sample_is_refused(capsys: pytest.CaptureFixture) -> None:
    with pytest.raises(ScenarioError) as err:
        load_scene(SCENARIOS / "m739_study.toml", {"study.samples": 1})
    assert "[study.samples] expected at least 2 samples, got 1" in str(err.value)
    err = _refused(capsys, ["study", str(SCENARIOS / "m739_study.toml"), "--samples", "1"])
    assert "--samples: expected at least 2 samples (a standard deviation needs two)" in err


def test_too_many_workers_are_refused(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    scene = str(SCENARIOS / "clock_train_cd_sweep.toml")
    err = _refused(capsys, ["sweep", scene, "--workers", "257", "--output", str(tmp_path)])
    assert err == "error: --workers: 257 is more than the limit of 256\n"
