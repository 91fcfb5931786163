"""A run that stops on ``scene.stop_when`` is compared with its reference at the same
condition, or its headline error is left out with a note; a condition that holds at the
start is refused."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from orchestrator.cli import main
from orchestrator.run import run_scene
from orchestrator.scenario import load_scene
from orchestrator.scenes.two_inertias.report import two_inertias_exact

TWO = Path(__file__).resolve().parents[2] / "scenarios" / "two_inertias.toml"


def _run(tmp_path: Path, **condition: str):
    overrides = {f"scene.stop_when.{k}": v for k, v in condition.items()}
    scene = load_scene(TWO, overrides)
    return run_scene(scene, tmp_path, show_progress=False, plots=False, reference_cache=False)


def test_stopped_at_an_angle_is_compared_with_the_closed_form_at_that_angle(
    tmp_path: Path,
) -> None:
    result = _run(tmp_path, signal="a.phi", above="1 rad")
    assert result.status == "completed" and result.time_reached < 0.5
    final = result.headline["final_angle_a"]["value"]
    # The closed form's a.phi is 1 rad at the crossing: the error is the last step's
    # overshoot, at most w h = 10 rad/s x 0.1 ms past 1 rad (it was 0.70, a.phi at 0.5 s).
    assert 1.0 <= final <= 1.0 + 10.0 * 1e-4
    assert result.accuracy["headline_error"] == pytest.approx(final - 1.0, abs=1e-12)
    assert not any("headline error" in n for n in result.notes)


def test_a_condition_the_reference_cannot_meet_leaves_the_headline_error_out(
    tmp_path: Path,
) -> None:
    # b.tau is no signal of the closed form: it cannot say where the condition is met.
    result = _run(tmp_path, signal="b.tau", above="0.05 N*m")
    assert result.status == "completed" and result.time_reached < 0.5
    assert "headline_error" not in result.accuracy
    assert "trajectory_error" in result.accuracy
    (note,) = [n for n in result.notes if n.startswith("headline error not computed")]
    assert "stopped on scene.stop_when (b.tau above 0.05)" in note
    assert "gives its headline at scene.stop = 0.5 s" in note


def test_the_crossing_is_where_the_closed_form_meets_the_condition(tmp_path: Path) -> None:
    from orchestrator.run import reference_of

    scene = load_scene(TWO, {"scene.stop_when.signal": "a.phi", "scene.stop_when.above": 1.0})
    ref = reference_of(scene)
    assert ref.at_stop_when and ref.headline["final_angle_a"] == pytest.approx(1.0, abs=1e-12)
    # just before the crossing the closed form is below 1 rad
    t = np.linspace(0.0, 0.5, 4097)
    x = two_inertias_exact(t, 2e-4, 1e-4, 2.0, 2e-3, 0.0, 10.0, 0.0, 0.0)["phi_a"]
    assert x[0] < 1.0 < x.max()


def test_a_condition_met_at_the_start_is_refused(tmp_path: Path, capsys) -> None:
    condition = ["--set", "scene.stop_when.signal=a.phi", "--set", "scene.stop_when.above=-1"]
    argv = ["run", str(TWO), "--output", str(tmp_path), "--no-progress", "--in-process", *condition]
    assert main(argv) == 1
    first = capsys.readouterr().out.splitlines()[0]
    assert first == (
        "scene two_inertias: failed — t = 0 s: scene.stop_when: a.phi above -1 already holds "
        "at the start (a.phi = 0): the run would end after its first step; expected a "
        "condition the run reaches"
    )
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["status"] == "failed" and summary["accuracy"] == {}
