"""``mechcosim report RUN_DIR`` prints what ``mechcosim run`` printed as it ended, from the
run's summary.json, for a completed, failed, interrupted or crashed run; ``--json`` the
summary itself."""

from __future__ import annotations

import json
import os
import signal
from pathlib import Path

import pytest

from orchestrator.cli import main
from orchestrator.system import CoupledSystem

TWO = Path(__file__).resolve().parents[2] / "scenarios" / "two_inertias.toml"
#: 20 ms at the scene's fixed 0.1 ms step: 200 macro steps, two doSteps each
SHORT = ["--set", "scene.stop=20 ms"]


def _run(out: Path, capsys: pytest.CaptureFixture, *extra: str) -> tuple[int, str]:
    code = main(["run", str(TWO), "--output", str(out), "--no-progress", "--in-process", *extra])
    return code, capsys.readouterr().out


def _report(out: Path, capsys: pytest.CaptureFixture, *extra: str) -> str:
    assert main(["report", str(out), *extra]) == 0
    return capsys.readouterr().out


def test_report_of_a_completed_run_is_what_the_run_printed(tmp_path: Path, capsys) -> None:
    code, printed = _run(tmp_path, capsys, *SHORT)
    assert code == 0
    text = _report(tmp_path, capsys)
    assert text == printed
    lines = text.splitlines()
    assert lines[0] == "scene two_inertias: completed"
    assert lines[-2].startswith("  steps 200, doSteps 400, rejections 0, rollbacks 0, events 0")
    assert lines[-1] == f"  results in {tmp_path}"
    units = {line.split()[0]: line.split()[2:] for line in lines[1:-2]}
    assert units["final_angle_a"] == ["rad"] and units["peak_coupling_torque"] == ["N.m"]
    assert "trajectory_error" in units  # the error against the closed form
    raw = json.loads(_report(tmp_path, capsys, "--json"))
    assert raw == json.loads((tmp_path / "summary.json").read_text())


def test_report_of_a_failed_run_says_why_first(tmp_path: Path, capsys) -> None:
    code, printed = _run(tmp_path, capsys, *SHORT, "--set", "fmus.b.parameters.max_twist=0.03 rad")
    assert code == 1
    text = _report(tmp_path, capsys)
    assert text == printed
    first = text.splitlines()[0]
    assert first.startswith("scene two_inertias: failed — FMU 'b'") and "t = " in first
    assert json.loads(_report(tmp_path, capsys, "--json"))["status"] == "failed"


def test_report_of_an_interrupted_run_says_where_it_stopped(
    tmp_path: Path, capsys, monkeypatch: pytest.MonkeyPatch
) -> None:
    original = CoupledSystem.record_row
    sent = []

    def interrupting(self: CoupledSystem, t: float) -> list[float]:
        if t >= 5e-3 and not sent:  # a Ctrl-C during the run: it stops at the next step
            sent.append(t)
            os.kill(os.getpid(), signal.SIGINT)
        return original(self, t)

    monkeypatch.setattr(CoupledSystem, "record_row", interrupting)
    code, printed = _run(tmp_path, capsys, *SHORT)
    assert code == 128 + signal.SIGINT
    text = _report(tmp_path, capsys)
    assert text == printed
    lines = text.splitlines()
    assert lines[0].startswith("scene two_inertias: interrupted — interrupted by SIGINT")
    summary = json.loads((tmp_path / "summary.json").read_text())
    reached = summary["time_reached"]
    assert 5e-3 <= reached < 20e-3
    assert f"  interrupted at t = {reached:.9g} s (simulated)" in lines
    assert json.loads(_report(tmp_path, capsys, "--json"))["status"] == "interrupted"


def test_report_of_a_crashed_run(tmp_path: Path, capsys) -> None:
    # summary.json as the supervisor writes it for a child that died in an FMU
    # (orchestrator/supervisor.py): no headline, the wall time its only statistic.
    message = "FMU 'b' crashed in fmi2DoStep at t = 0.01 s: killed by SIGSEGV (signal 11)"
    summary = {
        "scene": "two_inertias",
        "status": "crashed",
        "message": message,
        "time_reached": 0.01,
        "crash": {"cause": "killed by SIGSEGV (signal 11)", "signal": 11, "exit_code": None},
        "headline": {},
        "accuracy": {},
        "notes": ["the run's process crashed: the series hold every step completed before it"],
        "stats": {"wall_time": 0.25},
        "metadata": {},
    }
    (tmp_path / "summary.json").write_text(json.dumps(summary))
    assert _report(tmp_path, capsys).splitlines() == [
        f"scene two_inertias: crashed — {message}",
        "  note: the run's process crashed: the series hold every step completed before it",
        "  wall time 0.250 s",
        f"  results in {tmp_path}",
    ]
    assert json.loads(_report(tmp_path, capsys, "--json")) == summary


def test_report_of_a_run_that_never_started(tmp_path: Path, capsys) -> None:
    (tmp_path / "summary.json").write_text(
        json.dumps({"scene": "s", "status": "failed", "message": "cannot load FMU 'a'\nmore"})
    )
    assert _report(tmp_path, capsys).splitlines() == [
        "scene s: failed — cannot load FMU 'a' (full message in summary.json)",
        "  no steps taken",
        f"  results in {tmp_path}",
    ]


# -- run plots ---------------------------------------------------------------------------------
SCENARIOS = TWO.parent
#: one short run of each example family (plots only: no reference)
#: (the M739's is made by test_the_m739_plot_names_the_fmus_regimes; the clock train's, the
#: same figure with two panels more, takes some 10 s to load, run and draw: slow)
SHORT_RUNS = {
    "clock_train": ("clock_train_sa.toml", "1 ms"),
    "press_feed": ("press_feed_run1.toml", "0.05 s"),
    "detached_lever": ("lever_unit_decay.toml", "1 s"),
    "gear_mesh": ("mesh_efficiency.toml", "0.02 s"),
}


@pytest.mark.parametrize(
    "family",
    [pytest.param(f, marks=pytest.mark.slow) if f == "clock_train" else f for f in SHORT_RUNS],
)
def test_every_family_plots_a_short_run(family: str, tmp_path: Path) -> None:
    from orchestrator.run import run_scene
    from orchestrator.scenario import load_scene

    file, stop = SHORT_RUNS[family]
    scene = load_scene(SCENARIOS / file, {"scene.stop": stop})
    assert scene.family == family
    result = run_scene(scene, tmp_path, show_progress=False, compare_reference=False)
    assert result.status == "completed", result.message
    assert not [n for n in result.notes if n.startswith("plot")], result.notes
    assert (tmp_path / f"{scene.name}.png").stat().st_size > 10_000


def test_two_inertias_plot(tmp_path: Path) -> None:
    from orchestrator.run import run_scene
    from orchestrator.scenario import load_scene
    from orchestrator.scenes import PLOTS

    scene = load_scene(TWO, {"scene.stop": "5 ms"})
    result = run_scene(scene, tmp_path, show_progress=False, compare_reference=False)
    PLOTS["two_inertias"](scene, result.header, result.data, tmp_path / "two.png")
    assert (tmp_path / "two.png").stat().st_size > 10_000


def test_regime_spans_start_and_end_at_the_located_switches() -> None:
    from orchestrator.plotting import regime_spans

    names = {0: "free", 1: "coupled-entrance", 2: "coupled-exit"}
    t = [0.0, 1.0, 2.0, 3.0, 4.0]
    recorded = [1, 1, 0, 2, 2]
    events = [(1.25, "verge", "coupled-entrance", "free"), (2.5, "verge", "free", "coupled-exit")]
    assert regime_spans(t, recorded, names, events) == [
        (0.0, 1.25, "coupled-entrance"),
        (1.25, 2.5, "free"),
        (2.5, 4.0, "coupled-exit"),
    ]
    # without events: from the row that first records a regime to the next that records another
    assert regime_spans(t, recorded, names) == [
        (0.0, 2.0, "coupled-entrance"),
        (2.0, 3.0, "free"),
        (3.0, 4.0, "coupled-exit"),
    ]


def test_the_m739_plot_names_the_fmus_regimes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The detail's bands are labelled with the regime names the FMUs declare in their model
    descriptions (the verge's and the train's regime Enumeration)."""
    from orchestrator.run import run_scene
    from orchestrator.scenario import load_scene
    from orchestrator.scenes.m739 import report

    figures = []
    monkeypatch.setattr(report, "save_figure", lambda fig, path, **_: figures.append(fig))
    scene = load_scene(SCENARIOS / "m739.toml", {"scene.stop": "3 ms"})
    run_scene(scene, tmp_path, show_progress=False, compare_reference=False)
    (fig,) = figures
    legends = [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None]
    labels = {text.get_text() for legend in legends for text in legend.get_texts()}
    declared = {
        name
        for instance in ("verge", "train")
        for name in scene.fmus[instance].model.regime_names.values()
    }
    met = {"free", "coupled-entrance", "coupled-exit", "forward"}  # in the first 3 ms
    assert met <= declared and met <= labels
