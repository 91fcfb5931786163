"""Parameter sweeps from a scene's [sweep] table: one run per value and series, tables, plot."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from orchestrator.errors import ScenarioError
from orchestrator.scenario import load_scene
from orchestrator.studies.parameter_sweep import run_sweep, sweep_jobs

SCENE = (Path(__file__).resolve().parents[2] / "scenarios" / "two_inertias.toml").read_text()
SWEEP = """
[sweep]
parameter = "fmus.b.parameters.k"
values = ["0.5 N*m/rad", "2 N*m/rad", "8 N*m/rad"]
label = "coupling stiffness"
quantities = ["peak_coupling_torque"]

[[sweep.series]]
label = "undamped"
set = { "fmus.b.parameters.d" = 0.0 }

[[sweep.series]]
label = "damped"
set = { "fmus.b.parameters.d" = "2e-3 N*m*s/rad" }
"""


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "swept.toml"
    text = text.replace('stop = "0.5 s"', 'stop = "0.02 s"')
    path.write_text(text.replace('step = "0.1 ms"', 'step = "0.02 ms"'))
    return path


def test_sweep_runs_every_value_of_every_series(tmp_path: Path, fmu_cache, monkeypatch) -> None:
    monkeypatch.setenv("MECHCOSIM_FMU_CACHE", str(fmu_cache))
    path = write(tmp_path, SCENE + SWEEP)
    result = run_sweep(path, output_dir=tmp_path / "out", workers=2)
    assert [r["series"] for r in result.rows] == ["undamped"] * 3 + ["damped"] * 3
    assert [r["value"] for r in result.rows[:3]] == [0.5, 2.0, 8.0]
    assert all(r["status"] == "completed" for r in result.rows)
    # Undamped: the peak spring torque is w_rel sqrt(J_r k) (energy of the relative motion),
    # so it doubles when k is four times larger; 20 us steps leave a coupling error < 0.5 %.
    j_r = 2e-4 * 1e-4 / 3e-4
    for k, peak in zip(*result.column("peak_coupling_torque", "undamped"), strict=True):
        assert peak == pytest.approx(10.0 * math.sqrt(j_r * k), rel=5e-3)
    damped = result.column("peak_coupling_torque", "damped")[1]
    undamped = result.column("peak_coupling_torque", "undamped")[1]
    assert all(d != u for d, u in zip(damped, undamped, strict=True))
    for name in ("sweep.csv", "sweep.png", "sweep.md"):
        assert (tmp_path / "out" / name).stat().st_size > 0
    assert "coupling stiffness" in (tmp_path / "out" / "sweep.md").read_text()
    # Each run keeps its data; its plot is drawn only when asked for (--run-plots).
    runs = sorted(p for p in (tmp_path / "out").iterdir() if p.is_dir())
    assert len(runs) == 6
    assert all((run / "summary.json").is_file() for run in runs)
    assert not [png for run in runs for png in run.glob("*.png")]


def test_run_plots_are_asked_for_per_job(tmp_path: Path) -> None:
    path = write(tmp_path, SCENE + SWEEP)
    scene = load_scene(path)
    assert {j.plots for j in sweep_jobs(path, scene, tmp_path)} == {False}
    assert {j.plots for j in sweep_jobs(path, scene, tmp_path, run_plots=True)} == {True}


def test_unknown_swept_key_is_named(tmp_path: Path) -> None:
    bad = SWEEP.replace("fmus.b.parameters.k", "fmus.b.parameters.stiffness")
    with pytest.raises(ScenarioError, match=r"sweep.parameter.*no parameter 'stiffness'"):
        load_scene(write(tmp_path, SCENE + bad))


def test_value_in_wrong_unit_is_named(tmp_path: Path) -> None:
    bad = SWEEP.replace('"8 N*m/rad"', '"8 kg"')
    with pytest.raises(ScenarioError, match=r"sweep.values\[2\]"):
        load_scene(write(tmp_path, SCENE + bad))


def test_series_override_must_exist(tmp_path: Path) -> None:
    bad = SWEEP.replace("fmus.b.parameters.d", "fmus.c.parameters.d")
    with pytest.raises(ScenarioError, match=r"sweep.series\[0\].set.*unknown FMU instance 'c'"):
        load_scene(write(tmp_path, SCENE + bad))


def test_unknown_quantity_is_named(tmp_path: Path, fmu_cache, monkeypatch) -> None:
    monkeypatch.setenv("MECHCOSIM_FMU_CACHE", str(fmu_cache))
    text = SCENE + SWEEP.replace('["peak_coupling_torque"]', '["turns"]')
    text = text.replace('"0.5 N*m/rad", "2 N*m/rad", ', "")
    with pytest.raises(ScenarioError, match=r"sweep.quantities.*'turns'"):
        run_sweep(write(tmp_path, text), output_dir=tmp_path / "out", workers=1)


def test_scene_without_sweep_is_refused(tmp_path: Path) -> None:
    with pytest.raises(ScenarioError, match=r"sweep.*no \[sweep\] table"):
        run_sweep(write(tmp_path, SCENE), output_dir=tmp_path / "out")
