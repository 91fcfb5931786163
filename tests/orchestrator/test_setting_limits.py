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
