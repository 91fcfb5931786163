"""Press-feed scenes as designs: broken designs refused as the scene loads, a low brake
noted, a second crank radius with its own computed P1/F1 against its monolithic reference,
random nearby linkages run in agreement or refused by name, the drawing to scale."""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from components.press_feed_data import COUPLER_STANDARD, IN, LINKAGE_TABLE1
from components.rssr_kinematics import ExactRSSR, rocker_extremes
from orchestrator.errors import ScenarioError
from orchestrator.run import run_scene
from orchestrator.scenario import load_scene
from orchestrator.scenes.press_feed.design import DesignNote, scene_design, violations

matplotlib.use("Agg")

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
RUN1 = SCENARIOS / "press_feed_run1.toml"
# The tolerances of test_press_feed_scenes.py: feed length 1e-3, windup 3e-2 of its peak.
FEED_TOL = 1e-3
WINDUP_TOL = 3e-2


def _refused(cache: Path, **overrides) -> str:
    with pytest.raises(ScenarioError) as exc:
        load_scene(RUN1, overrides, cache_dir=cache)
    text = str(exc.value)
    assert "\n" not in text and "math domain" not in text
    return text


def test_broken_designs_are_refused_when_the_scene_loads(fmu_cache) -> None:
    text = _refused(fmu_cache, **{"fmus.drive.parameters.a1": "0.5 m"})
    assert "design rule 'RSSR assembly' broken: a1 = 19.685 in" in text
    text = _refused(fmu_cache, **{"fmus.drive.parameters.a3": "33 in"})
    assert "'coupler chord'" in text and "a3 = 33.00000 in" in text
    text = _refused(fmu_cache, **{"fmus.drive.parameters.d_inner": "1.1 in"})
    assert "'coupler tube'" in text and "D_i = 1.10000 in" in text
    text = _refused(
        fmu_cache,
        **{"fmus.clutch.parameters.model": 1, "fmus.clutch.parameters.sprag_offset": "0.00005 in"},
    )
    assert "'sprag geometry'" in text and "a = 0.00005 in" in text


def test_a_brake_below_the_engagement_minimum_loads_with_a_note(fmu_cache) -> None:
    with pytest.warns(DesignNote, match="'brake engagement minimum': T_b = 20.0 lbf"):
        scene = load_scene(RUN1, {"fmus.load.parameters.brake_torque": "20 lbf*in"}, fmu_cache)
    assert violations(scene_design(scene)) == []


def _agrees(result) -> None:
    assert result.status == "completed", result.message
    acc = result.accuracy
    assert acc["headline_error.feed_length_mean"] < FEED_TOL
    assert acc["trajectory_error"] < WINDUP_TOL
    assert acc["event_count_difference"] == 0


@pytest.mark.slow  # one more design point against its reference: long validation
def test_a_second_crank_radius_agrees_with_its_reference(tmp_path, fmu_cache) -> None:
    overrides = {
        "fmus.drive.parameters.a1": "1.05 in",
        "fmus.drive.parameters.coupler_inertia": 1,
        "scene.stop": "0.6 s",
    }
    scene = load_scene(RUN1, overrides, cache_dir=fmu_cache)
    result = run_scene(
        scene, output_dir=tmp_path / "r", cache_dir=fmu_cache, show_progress=False, plots=False
    )
    _agrees(result)
    # The longer crank swings the rocker further than Table 1's 25.565 deg (a1 = 0.965 in).
    d = scene_design(scene)
    hi, _, lo, _ = rocker_extremes(ExactRSSR(d.linkage, d.coupler.alpha))
    assert math.degrees(hi - lo) > 25.565


def _nearby(draw: st.DrawFn) -> dict[str, object]:
    """A linkage a few per cent from Run 1's, consistent by construction: the crank, rocker
    and frame offsets vary freely; the coupler's L and alpha vary and a3 = 2 L cos(alpha)."""
    out: dict[str, object] = {}
    lk = LINKAGE_TABLE1
    for name in ("a1", "a4", "s1", "s2", "s3"):
        out[f"fmus.drive.parameters.{name}"] = getattr(lk, name) * draw(st.floats(0.97, 1.03))
    length = COUPLER_STANDARD.length * draw(st.floats(0.98, 1.02))
    alpha = COUPLER_STANDARD.alpha * draw(st.floats(0.95, 1.05))
    out["fmus.drive.parameters.L"] = length
    out["fmus.drive.parameters.alpha"] = alpha
    out["fmus.drive.parameters.a3"] = 2.0 * length * math.cos(alpha)
    out["fmus.drive.parameters.coupler_inertia"] = 1
    out["scene.stop"] = "0.35 s"
    return out


@settings(
    max_examples=2,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)
@given(st.data())
def test_linkages_near_run1_run_in_agreement_or_are_refused(tmp_path, fmu_cache, data) -> None:
    overrides = data.draw(st.composite(_nearby)())
    try:
        scene = load_scene(RUN1, overrides, cache_dir=fmu_cache)
    except ScenarioError as exc:
        assert "design rule '" in str(exc)  # refused by a named rule, nothing else
        return
    assert violations(scene_design(scene)) == []
    result = run_scene(
        scene, output_dir=tmp_path / "p", cache_dir=fmu_cache, show_progress=False, plots=False
    )
    _agrees(result)


def test_the_drawing_is_to_scale(tmp_path, fmu_cache) -> None:
    from orchestrator.scenes.press_feed.drawing import draw, linkage_points, sprag_centres

    scene = load_scene(RUN1, cache_dir=fmu_cache)
    d = scene_design(scene)
    pts = linkage_points(d.linkage, d.coupler, 4.46)
    dist = {k: np.linalg.norm(pts[p] - pts[q]) / IN for k, (p, q) in
            {"a1": ("O1", "A"), "a3": ("A", "C"), "a4": ("O2", "C"), "L": ("A", "B"),
             "BC": ("B", "C")}.items()}  # fmt: skip
    # Table 1: a1 0.965, a3 32.523, a4 4.500, L 16.625 in (B-C is the second section).
    assert dist["a1"] == pytest.approx(0.965, abs=1e-9)
    assert dist["a3"] == pytest.approx(32.523, abs=1e-9)
    assert dist["a4"] == pytest.approx(4.5, abs=1e-9)
    assert dist["L"] == pytest.approx(16.625, abs=1e-9)
    assert dist["BC"] == pytest.approx(16.625, abs=1e-3)  # a3 = 32.523 vs 2 L cos a 32.5234
    from components.press_feed_data import TABLE4

    c_in, c_out = sprag_centres(TABLE4)
    assert np.linalg.norm(c_in - c_out) / IN == pytest.approx(0.0224, abs=1e-9)  # a, Table 4
    out = tmp_path / "feed.png"
    draw(scene, out)
    assert out.stat().st_size > 20_000
