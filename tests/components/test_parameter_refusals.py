"""Parameters that mean nothing physical are refused when initialization ends, by name: a
zero where only a positive value is physical (Young's modulus, a length, an inertia), a
NaN or infinite spin or restitution; and a doStep too long to finish ends within its
internal step budget, with a message."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from components.base import ComponentError
from components.crank_coupler_drive import CrankCouplerDrive
from components.rotational import Inertia
from components.verge_escapement import VergeEscapement
from fmus.build import build_fmu
from orchestrator.errors import RunError
from orchestrator.fmu_instance import FmuInstance
from orchestrator.run import run_scene
from orchestrator.scenario import load_scene

PRESS = Path(__file__).resolve().parents[2] / "scenarios" / "press_feed_run1.toml"


def test_zero_where_only_positive_is_physical_is_named() -> None:
    with pytest.raises(ComponentError, match=r"CrankCouplerDrive: parameter youngs = 0.0 Pa; "):
        CrankCouplerDrive(youngs=0.0).check_parameters()
    assert Inertia(J=0.0).parameter_problem() == (
        "parameter J = 0.0 kg.m2; expected more than 0 (moment of inertia)"
    )
    assert Inertia(J=1e-9).parameter_problem() is None


def test_youngs_modulus_zero_fails_the_press_feed_at_initialization(tmp_path: Path) -> None:
    scene = load_scene(PRESS, {"fmus.drive.parameters.youngs": 0.0, "scene.stop": "10 ms"})
    result = run_scene(scene, output_dir=tmp_path, show_progress=False, plots=False)
    assert result.status == "failed"
    assert "FMU 'drive'" in result.message
    assert "parameter youngs = 0.0 Pa; expected more than 0 (coupler Young's modulus [Xu: E])" in (
        result.message
    )


@pytest.mark.parametrize("name, value", [("spin", math.nan), ("e_rest", math.inf)])
def test_verge_names_a_non_finite_parameter(name: str, value: float) -> None:
    with pytest.raises(ComponentError, match=rf"VergeEscapement: parameter {name} is {value!r}"):
        VergeEscapement(**{name: value}).initialize(0.0)


def test_a_do_step_ends_within_its_internal_step_budget() -> None:
    fmu = FmuInstance("verge", build_fmu("VergeEscapement"))
    try:
        fmu.initialize(0.0, 2e6, {"max_internal_steps": 2000, "phi_dot": 50.0})
        with pytest.raises(RunError) as info:
            fmu.do_step(0.0, 1e6)  # at h_max = 0.1 ms: 1e10 internal steps, never ending
    finally:
        fmu.close()
    message = str(info.value)
    assert "FMU 'verge'" in message
    assert "spent its budget of 2000 internal steps (max_internal_steps)" in message
