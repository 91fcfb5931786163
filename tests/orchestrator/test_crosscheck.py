"""The exported systems run in libcosim and in FMPy at our fixed step agree with our
Jacobi master (mechcosim crosscheck)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from orchestrator.cli import main
from orchestrator.run import RunResult
from orchestrator.scenario import load_scene
from orchestrator.ssp_export import libcosim_step
from orchestrator.studies.crosscheck import REQUIRED, ToolRun, agreement, cannot_run, crosscheck

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
M739_FIRST_IMPACT = 4.74e-4  # s, our Jacobi master at 1 us


def _assert_agrees(check, tools: tuple[str, ...]) -> None:
    assert [o.tool for o in check.outcomes] == list(tools)
    recorded = {f"{i}.{v}" for i, v in check.scene.record}
    types = {f"{i}.{v}": check.scene.fmus[i].model.variables[v].type for i, v in check.scene.record}
    for o in check.outcomes:
        assert o.cannot_run is None, o.cannot_run
        assert o.agreement.points == check.steps == len(o.run.data)
        skipped = {s for s in recorded if o.tool == "libcosim" and types[s] == "Enumeration"}
        assert set(o.agreement.per_signal) == recorded - skipped
        assert set(o.run.not_compared) == skipped
        name, worst = o.agreement.worst
        assert worst <= REQUIRED, (o.tool, name, worst)
    assert check.ok


@pytest.mark.slow  # in the slow suite (CI runs it): the default stays under 2 minutes
def test_m739_with_its_integer_impact_connection_in_libcosim_and_fmpy() -> None:
    """Past the first impact: a train that never sees the verge's impact count would be
    off by the impact's change of speed."""
    stop = 6e-4
    assert stop > M739_FIRST_IMPACT
    check = crosscheck(SCENARIOS / "m739.toml", stop=stop)
    _assert_agrees(check, ("libcosim", "fmpy"))
    for o in check.outcomes:
        impacts = o.run.data[:, o.run.header.index("verge.impact_count")]
        assert impacts[-1] >= 1 and impacts[0] == 0


def test_two_inertias_in_libcosim_and_fmpy() -> None:
    """The exported archive alone (parameter bindings, connections, the OSP step
    annotation) makes libcosim reproduce our fixed-step Jacobi run."""
    _assert_agrees(crosscheck(SCENARIOS / "two_inertias.toml", stop=0.01), ("libcosim", "fmpy"))


@pytest.mark.slow  # in the slow suite (CI runs it): the default stays under 2 minutes
def test_press_feed_run1_in_libcosim_from_the_osp_file_and_in_fmpy() -> None:
    check = crosscheck(SCENARIOS / "press_feed_run1.toml", stop=0.02, via="osp")
    _assert_agrees(check, ("libcosim", "fmpy"))
    assert [o.run.via for o in check.outcomes] == ["OSP-IS file", "SSP archive"]


@pytest.mark.slow
@pytest.mark.parametrize("via", ["ssp", "osp"])
@pytest.mark.parametrize("scene_file", ["two_inertias.toml", "m739.toml", "press_feed_run1.toml"])
def test_default_crosscheck_of_the_three_scenes(scene_file: str, via: str, capsys) -> None:
    """The command as docs/fmus_in_other_tools.md shows it: every tool, the default span."""
    assert main(["crosscheck", str(SCENARIOS / scene_file), "--via", via]) == 0
    out = capsys.readouterr().out
    assert out.count(": ok") == 2 and "NOT MET" not in out


def test_a_disagreement_is_measured_relative_to_the_signal_scale() -> None:
    scene = load_scene(SCENARIOS / "two_inertias.toml", {"scene.stop": 0.001})
    t = np.arange(0, 11) * scene.master.step
    ours_data = np.column_stack([t, 2.0 + 0 * t, 0 * t])
    ours = RunResult(
        scene=scene,
        status="completed",
        message="",
        header=["time", "a.w", "b.w"],
        data=ours_data,
        events=[],
        stats=None,
        headline={},
        output_dir=Path(),
    )
    theirs_rows = ours_data[1:].copy()
    theirs_rows[4, 1] += 3e-9  # 1.5e-9 of a.w's scale 2
    run = ToolRun("x", "SSP archive", ["time", "a.w", "b.w"], theirs_rows, 0.0)
    result = agreement(ours, run, scene)
    assert result.points == 10
    assert result.per_signal["b.w"] == 0.0  # zero throughout on both sides
    assert result.per_signal["a.w"] == pytest.approx(1.5e-9, rel=1e-6)
    assert result.worst[0] == "a.w" and result.worst[1] > REQUIRED


def test_a_tool_that_cannot_run_the_scene_says_why_in_one_line(capsys) -> None:
    scene = load_scene(SCENARIOS / "two_inertias.toml", {"master.step": 1.00000000001e-4})
    assert "whole nanoseconds" in cannot_run(scene, "libcosim")
    code = main(
        [
            "crosscheck",
            str(SCENARIOS / "two_inertias.toml"),
            "--tool",
            "libcosim",
            "--set",
            "master.step=1.00000000001e-4",
            "--stop",
            "1 ms",
        ]
    )
    out = capsys.readouterr().out
    assert code == 1
    lines = [line for line in out.splitlines() if "cannot run" in line]
    assert lines == [
        "  libcosim cannot run two_inertias: libcosim steps in whole nanoseconds; "
        "0.000100000000001 s is not one"
    ]


def test_a_step_converted_from_microseconds_is_written_in_whole_nanoseconds() -> None:
    """'50 us' is 4.9999999999999996e-05 s, which libcosim would truncate to 49999 ns and
    so disagree by 5e-5; written as 5e-05 it steps 50000 ns."""
    assert libcosim_step(4.9999999999999996e-05) == "5e-05"
    assert libcosim_step(1e-6) == "1e-06"
    assert libcosim_step(1.5e-10) == "1.5e-10"  # no whole nanosecond: left as it is
    check = crosscheck(
        SCENARIOS / "two_inertias.toml",
        {"master.step": "50 us"},
        stop=0.002,
        tools=("libcosim",),
    )
    assert check.scene.master.step == 4.9999999999999996e-05
    _assert_agrees(check, ("libcosim",))
