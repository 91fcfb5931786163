"""FMI 2.0 input derivatives (canInterpolateInputs, fmi2SetRealInputDerivatives).

A foreign FMU that declares it takes them gets the slope of its held inputs from the
regime-aware master (the midpoint hold: towards the predicted end value; the single pass:
of the extrapolation): its inputs then ramp through the step (second order) instead of
sitting at their step-start values (first order).  Measured against the closed form of
the two-inertia scene (our Inertia and the C TorsionBody)."""

from __future__ import annotations

from pathlib import Path

import foreign_fmus
import numpy as np
import pytest
from foreign_fmus import foreign_scene, write_scene

from orchestrator import capabilities
from orchestrator.model_info import model_info
from orchestrator.run import run_scene
from orchestrator.scenario import load_scene
from orchestrator.scenes.two_inertias.report import two_inertias_exact

needs_cc = pytest.mark.skipif(foreign_fmus.c_compiler() is None, reason="no C compiler")


@pytest.fixture(scope="module")
def bodies(tmp_path_factory) -> dict[str, Path]:
    if foreign_fmus.c_compiler() is None:
        pytest.skip("no C compiler")
    d = tmp_path_factory.mktemp("derivatives")
    return {
        "held": foreign_fmus.build_torsion_body(d),
        "ramped": foreign_fmus.build_torsion_body(d, input_derivatives=True),
    }


def error(fmu: Path, hold: str, step: str, directory: Path) -> tuple[float, object]:
    """Largest error of body a's angle against the closed form, the regime-aware master
    with ``hold`` taking steps of ``step`` (the largest tolerance: no step is rejected)."""
    directory.mkdir(parents=True)
    path = write_scene(directory, foreign_scene(str(fmu), "regime-aware"))
    overrides = {
        "master.tolerance": 1.0,
        "master.first_step": step,
        "master.max_step": step,
        "master.input_hold": hold,
    }
    r = run_scene(load_scene(path, overrides), output_dir=directory / "run", show_progress=False)
    assert r.status == "completed", r.message
    t = r.signal("time")
    exact = two_inertias_exact(t, 2e-4, 1e-4, 2.0, 2e-3, 0.0, 10.0, 0.0, 0.0)
    return float(np.abs(r.signal("a.phi") - exact["phi_a"]).max()), r


@needs_cc
def test_which_inputs_take_derivatives(bodies) -> None:
    held, ramped = model_info(bodies["held"]), model_info(bodies["ramped"])
    assert not held.can_interpolate_inputs and ramped.can_interpolate_inputs
    assert capabilities.takes_input_derivative(ramped, "flange.w")
    assert not capabilities.takes_input_derivative(held, "flange.w")
    assert not capabilities.takes_input_derivative(ramped, "body.J")  # a parameter


@needs_cc
@pytest.mark.parametrize("hold", ["midpoint", "extrapolated"])
def test_input_derivatives_make_the_black_box_second_order(tmp_path, bodies, hold) -> None:
    errors = {}
    for kind, fmu in bodies.items():
        for step in ("1 ms", "0.5 ms"):
            where = tmp_path / f"{kind}-{step[:-3]}"
            errors[kind, step], r = error(fmu, hold, step, where)
            # Every step is the one asked but the second (shortened at the start's jolt).
            steps = np.diff(r.signal("time"))
            h = float(step.split()[0]) * 1e-3
            assert r.stats.rejections == 0 and np.sum(np.abs(steps - h) > 1e-12) <= 2
        if hold == "midpoint":
            # Held at its step start, the black box is said to be first order; ramped, not.
            warnings = r.stats.warnings
            said = any("'c' declares no sampled inputs" in w for w in warnings)
            assert said == (kind == "held")
    # Measured, midpoint: held 4.0e-3 and 1.5e-3 rad, ramped 1.2e-3 and 2.9e-4 rad;
    # single pass: held 4.0e-3 and 1.5e-3 rad, ramped 1.0e-3 and 2.6e-4 rad.
    for step in ("1 ms", "0.5 ms"):
        assert errors["ramped", step] < errors["held", step] / 3.0
    # Halving the step: the held inputs' error falls by less than 3 (first order in the
    # hold), the ramped ones' by about 4 (second order).
    assert errors["held", "1 ms"] / errors["held", "0.5 ms"] < 3.0
    assert errors["ramped", "1 ms"] / errors["ramped", "0.5 ms"] > 3.5
