"""Clock-train S&A scenes as designs: a broken clock train refused as the scene loads, the
drawing, and random nearby clock trains run in agreement with their monolithic reference or
refused by a named rule (kinematics of the US Army fuze report of about 1980, Task 2)."""

from __future__ import annotations

from pathlib import Path

import matplotlib
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from components.clock_gear_train import ClockGearTrain
from components.clock_train_design import clock_train, mesh_names, train_violations
from components.clock_train_kinematics import M739_MESH1, M739_MESH2
from orchestrator.errors import ScenarioError
from orchestrator.run import run_scene
from orchestrator.scenario import load_scene
from orchestrator.scenes.clock_train.design import train_values

matplotlib.use("Agg")

SCENE = Path(__file__).resolve().parents[2] / "scenarios" / "clock_train_sa.toml"
# The short run's tolerances of test_clock_gear_train.py (2.5 ms, reference sampled 10 us).
TRAJECTORY_TOL = 3e-3
EVENT_TIME_TOL = 1e-5


def test_a_broken_clock_train_is_refused_when_the_scene_loads(fmu_cache) -> None:
    with pytest.raises(ScenarioError) as exc:
        load_scene(SCENE, {"fmus.train.parameters.mesh2_center_distance": "0.3 in"},
                   cache_dir=fmu_cache)  # fmt: skip
    text = str(exc.value)
    assert "\n" not in text
    assert "design rule 'coupler L = rho_G + rho_P' broken: mesh 2:" in text
    assert "b2 (mesh2_center_distance) = 0.30000 in" in text
    # Told not to check, the scene loads (the FMU then refuses in one line as it starts).
    load_scene(SCENE, {"fmus.train.parameters.mesh2_center_distance": "0.3 in",
                       "fmus.train.parameters.check_design": 0}, cache_dir=fmu_cache)  # fmt: skip


def test_the_drawing_shows_both_meshes_and_the_escapement(tmp_path, fmu_cache) -> None:
    from orchestrator.scenes.clock_train.drawing import draw, gear_rounds, pinion_profiles

    scene = load_scene(SCENE, cache_dir=fmu_cache)
    path = tmp_path / "clock.png"
    draw(scene, path)
    assert path.stat().st_size > 20_000
    # To scale: every tip round at a_G from the gear pivot, every leaf's flank from O_P.
    m = M739_MESH1
    for gx, gy in gear_rounds(m, 0.3):
        assert (gx * gx + gy * gy) ** 0.5 == pytest.approx(m.a_g, rel=1e-12)
    assert len(pinion_profiles(m, 0.3)) == m.n_pinion == 9


def _nearby(draw: st.DrawFn) -> dict[str, object]:
    """A clock train a few per cent from the default, consistent by construction: each mesh
    scaled as a whole (every length by one factor), its phasing angles moved a little, the
    bodies' masses and inertias a few per cent off."""
    out: dict[str, object] = {}
    for i, mesh in ((1, M739_MESH1), (2, M739_MESH2)):
        scale = draw(st.floats(0.97, 1.03))
        for field, name in mesh_names(i).items():
            value = getattr(mesh, field)
            if field in ("b", "a_g", "rho_g", "f_p", "rho_p"):
                value *= scale
            elif field in ("delta_g", "alpha_p"):
                value += draw(st.floats(-0.03, 0.03))
            out[f"fmus.train.parameters.{name}"] = value
    for name in ("rotor_inertia", "gear2_inertia", "wheel_inertia", "rotor_offset"):
        start = ClockGearTrain.variable(name).start
        out[f"fmus.train.parameters.{name}"] = start * draw(st.floats(0.97, 1.03))
    out["scene.stop"] = "2.5 ms"
    return out


@settings(
    max_examples=2,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(st.data())
def test_clock_trains_near_the_default_run_in_agreement_or_are_refused(
    tmp_path, fmu_cache, data
) -> None:
    overrides = data.draw(st.composite(_nearby)())
    try:
        scene = load_scene(SCENE, overrides, cache_dir=fmu_cache)
    except ScenarioError as exc:
        assert "design rule '" in str(exc)  # refused by a named rule, nothing else
        return
    assert train_violations(clock_train(train_values(scene))) == []
    r = run_scene(
        scene, output_dir=tmp_path / "p", cache_dir=fmu_cache, show_progress=False, plots=False
    )
    assert r.status == "completed", r.message
    acc = r.accuracy
    assert acc["headline_error.impacts"] == 0.0
    assert acc["trajectory_error"] < TRAJECTORY_TOL
    assert acc["event_time_error"] < EVENT_TIME_TOL
