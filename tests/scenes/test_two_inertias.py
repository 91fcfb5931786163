"""The plumbing scene: two inertias on a spring–damper split across two FMUs."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pytest
from scene_run import run_file

from components.rotational import Inertia, SpringDamperInertia
from orchestrator.scenes.two_inertias.report import two_inertias_exact

SCENE = Path(__file__).resolve().parents[2] / "scenarios" / "two_inertias.toml"


def run(tmp_path, fmu_cache, **overrides):
    return run_file(SCENE, tmp_path / "run", overrides)


def test_closed_form_conserves_momentum_and_oscillates() -> None:
    t = np.linspace(0.0, 0.5, 2001)
    x = two_inertias_exact(t, 2e-4, 1e-4, 2.0, 0.0, w_a0=10.0)
    momentum = 2e-4 * x["w_a"] + 1e-4 * x["w_b"]
    assert np.allclose(momentum, 2e-3, rtol=0, atol=1e-15)
    energy = (
        0.5 * 2e-4 * x["w_a"] ** 2 + 0.5 * 1e-4 * x["w_b"] ** 2 + (x["phi_a"] - x["phi_b"]) ** 2
    )
    assert np.allclose(energy, 0.5 * 2e-4 * 100.0, rtol=1e-12)
    # twist frequency sqrt(k / J_reduced)
    period = 2 * math.pi / math.sqrt(2.0 / (2e-4 * 1e-4 / 3e-4))
    twist = x["phi_a"] - x["phi_b"]
    crossings = t[1:][np.diff(np.sign(twist)) < 0]
    assert np.diff(crossings).mean() == pytest.approx(period, rel=2e-3)


def test_component_steps_are_exact_for_held_inputs() -> None:
    body = Inertia(J=2.0, w0=1.0)
    body.initialize(0.0)
    body.tau = 4.0
    for _ in range(10):
        body.step(0.0, 0.1)
    assert body.phi == pytest.approx(1.0 + 0.5 * 2.0 * 1.0**2, rel=1e-13)
    assert body.w == pytest.approx(3.0, rel=1e-13)
    # A spring–damper body whose port is held fixed is a free damped oscillator.
    sd = SpringDamperInertia(J=1e-4, k=2.0, d=2e-3, w0=1.0)
    sd.initialize(0.0)
    for _ in range(50):
        sd.step(0.0, 1e-3)
    exact = two_inertias_exact(np.array([0.05]), 1e30, 1e-4, 2.0, 2e-3, w_b0=1.0)
    assert sd.phi == pytest.approx(exact["phi_b"][0], rel=1e-9)
    assert sd.stored_energy + sd.dissipated_work == pytest.approx(0.5e-4, rel=1e-12)


@pytest.mark.parametrize(
    "algorithm", ["jacobi", pytest.param("gauss-seidel", marks=pytest.mark.slow)]
)
def test_coupling_error_is_first_order_in_the_macro_step(scene_runs, algorithm) -> None:
    steps = [4e-4, 2e-4, 1e-4, 5e-5]
    errors = []
    for h in steps:
        result = scene_runs(SCENE, {"master.algorithm": algorithm, "master.step": h})
        assert result.status == "completed"
        errors.append(result.accuracy["trajectory_error"])
    orders = np.diff(np.log(errors)) / np.diff(np.log(steps))
    # Zero-order hold of the coupling torque: first order for both masters.
    assert orders[-1] == pytest.approx(1.0, abs=0.1), orders
    assert all(e2 < e1 for e1, e2 in zip(errors, errors[1:], strict=False)), errors


def test_energy_balance_tightens_with_the_step(scene_runs) -> None:
    # The Jacobi runs of the first-order test (the scene's own master), made once.
    jacobi = {"master.algorithm": "jacobi"}
    coarse = scene_runs(SCENE, {**jacobi, "master.step": 2e-4}).value("energy_residual")
    fine = scene_runs(SCENE, {**jacobi, "master.step": 5e-5}).value("energy_residual")
    assert fine < coarse / 3.0
    assert fine < 5e-3


def test_outputs_written_and_metadata_complete(tmp_path, fmu_cache) -> None:
    result = run(tmp_path, fmu_cache, **{"scene.stop": "0.01 s"})
    out = result.output_dir
    with open(out / "timeseries.csv") as f:
        rows = list(csv.reader(f))
    assert rows[0][:3] == ["time", "a.phi", "a.w"]
    assert len(rows) == 1 + 101  # start row + 100 steps of 0.1 ms
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "completed"
    assert summary["stats"]["steps"] == 100 and summary["stats"]["do_steps"] == 200
    meta = summary["metadata"]
    assert {k: f["model"] for k, f in meta["fmus"].items()} == {
        "a": "Inertia",
        "b": "SpringDamperInertia",
    }
    assert all(len(f["sha256"]) == 64 for f in meta["fmus"].values())
    assert meta["versions"]["fmpy"] and meta["master"]["step"] == pytest.approx(1e-4)


def test_failed_run_keeps_what_it_recorded(tmp_path, fmu_cache) -> None:
    result = run(tmp_path, fmu_cache, **{"fmus.b.parameters.max_twist": "0.03 rad"})
    assert result.status == "failed"
    assert "FMU 'b'" in result.message and "exceeds the coupling's limit" in result.message
    assert "t = " in result.message
    # Every step before the failure is on disk, and the summary says what happened.
    with open(result.output_dir / "timeseries.csv") as f:
        rows = list(csv.reader(f))
    assert len(rows) - 1 == len(result.data) > 20
    summary = json.loads((result.output_dir / "summary.json").read_text())
    assert summary["status"] == "failed" and "exceeds" in summary["message"]
    twist = np.abs(result.signal("a.phi") - result.signal("b.phi"))
    assert twist.max() <= 0.03
