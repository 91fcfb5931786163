"""What ``mechcosim run`` can leave out or reuse: ``--no-plot``, ``--no-reference``, the
reference kept in the FMU cache (hit for the same physics, missed for another parameter or
other physics code), and ``--debug``'s phase list."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from orchestrator import reference_cache
from orchestrator.cli import main
from orchestrator.reference_cache import cached_reference, reference_key
from orchestrator.run import reference_of
from orchestrator.scenario import load_scene

M739 = Path(__file__).resolve().parents[2] / "scenarios" / "m739.toml"
#: 4 ms of the M739: a few teeth, well before arming (the run completes at its stop)
SHORT = {"scene.stop": "4 ms"}


def _run(out: Path, *extra: str) -> int:
    args = ["run", str(M739), "--output", str(out), "--no-progress", "--in-process"]
    return main([*args, "--set", "scene.stop=4 ms", *extra])


def test_no_plot_and_no_reference_leave_them_out(tmp_path: Path, capsys) -> None:
    assert _run(tmp_path / "all") == 0
    assert (tmp_path / "all" / "m739.png").is_file()
    assert (
        "trajectory_error"
        in json.loads((tmp_path / "all" / "summary.json").read_text())["accuracy"]
    )
    assert _run(tmp_path / "bare", "--no-plot", "--no-reference") == 0
    assert not (tmp_path / "bare" / "m739.png").exists()
    summary = json.loads((tmp_path / "bare" / "summary.json").read_text())
    assert summary["accuracy"] == {}
    for name in ("timeseries.csv", "events.csv"):  # the run itself is the same
        assert (tmp_path / "all" / name).read_bytes() == (tmp_path / "bare" / name).read_bytes()
    assert (
        json.loads((tmp_path / "all" / "summary.json").read_text())["headline"]
        == (summary["headline"])
    )


def test_debug_prints_one_line_a_phase_after_the_summary(tmp_path: Path, capsys) -> None:
    assert main(["--debug", *_args(tmp_path)]) == 0
    captured = capsys.readouterr()
    assert captured.out.splitlines()[-1] == f"  results in {tmp_path}"
    lines = captured.err.splitlines()
    start = lines.index("phases (wall time):")
    names = [line.split("  ")[1].strip() for line in lines[start + 1 :]]
    for phase in ("imports", "scene load", "co-simulation (initialize, step)", "total"):
        assert phase in names
    assert any(name.startswith("reference") for name in names)
    assert any(name.startswith("plot") for name in names)


def _args(out: Path) -> list[str]:
    return ["run", str(M739), "--output", str(out), "--no-progress", "--in-process",
            "--set", "scene.stop=4 ms"]  # fmt: skip


def test_the_same_scene_reads_the_reference_back(tmp_path: Path) -> None:
    scene = load_scene(M739, SHORT)
    computed: list[int] = []

    def compute(s):  # noqa: ANN001, ANN202 - a Scene, a Reference
        computed.append(1)
        return reference_of(s)

    first, hit_first = cached_reference(scene, compute, tmp_path)
    second, hit_second = cached_reference(load_scene(M739, SHORT), compute, tmp_path)
    assert (hit_first, hit_second, len(computed)) == (False, True, 1)
    assert second.headline == first.headline
    assert second.events == first.events
    assert second.t_range == first.t_range
    times = np.linspace(0.0, 4e-3, 17)
    for name, values in first.signals(times).items():
        assert np.array_equal(second.signals(times)[name], values)
    stored = list((tmp_path / "references" / "m739").glob("*.pickle"))
    assert len(stored) == 1


@pytest.mark.parametrize(
    "change",
    [
        {"fmus.verge.parameters.mu1": 0.12},
        {"parameters.mu": 0.11},
        {"scene.stop": "5 ms"},
    ],
)
def test_another_parameter_or_stop_misses(change: dict) -> None:
    assert reference_key(load_scene(M739, {**SHORT, **change})) != reference_key(
        load_scene(M739, SHORT)
    )


@pytest.mark.parametrize(
    ("edited", "misses"),
    [
        ("components/verge_escapement.py", True),
        ("orchestrator/scenes/m739/monolithic.py", True),
        ("orchestrator/scenes/family.py", True),
        ("orchestrator/scenes/press_feed/report.py", False),  # not the M739's code
    ],
)
def test_changed_physics_code_misses(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, edited: str, misses: bool
) -> None:
    root = reference_cache._ROOT
    shutil.copytree(root / "components", tmp_path / "components")
    shutil.copytree(root / "orchestrator" / "scenes", tmp_path / "orchestrator" / "scenes")
    monkeypatch.setattr(reference_cache, "_ROOT", tmp_path)
    monkeypatch.setattr(reference_cache, "_SCENES", tmp_path / "orchestrator" / "scenes")
    scene = load_scene(M739, SHORT)
    reference_cache.code_hash.cache_clear()
    before = reference_key(scene)
    with open(tmp_path / edited, "a") as f:
        f.write("\n# edited\n")
    reference_cache.code_hash.cache_clear()
    after = reference_key(scene)
    reference_cache.code_hash.cache_clear()
    assert (after != before) is misses


def test_an_unreadable_entry_is_computed_again(tmp_path: Path) -> None:
    scene = load_scene(M739, SHORT)
    path = tmp_path / "references" / "m739" / f"{reference_key(scene)}.pickle"
    path.parent.mkdir(parents=True)
    path.write_bytes(b"not a pickle")
    ref, hit = cached_reference(scene, reference_of, tmp_path)
    assert not hit
    assert ref.headline == reference_of(scene).headline
    assert cached_reference(scene, reference_of, tmp_path)[1]
