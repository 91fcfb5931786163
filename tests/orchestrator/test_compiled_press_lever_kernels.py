"""The press feed's compiled kernel (components/press_feed_kernel.pyx) gives the same bits as
the Python code: the press feed and detached lever scenes and the press feed's monolithic
references are run with each path, in processes of their own (the kernels are bound at
import), and their outputs compared byte for byte; a spent step budget of the crank drive
ends both paths with the same error."""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import pytest
from kernel_paths import needs_kernels, printed_by

from fmus.build import build_fmu

#: The short runs: (scene file, overrides); a rocker reversal (0.149 s in) in each press feed
#: run, one crank cycle where the reference is compared (it needs one).
SHORT = {
    "run1_gauss_seidel": ("press_feed_run1.toml", {"scene.stop": "0.31 s"}),
    "run1_midpoint": (
        "press_feed_run1.toml",
        {"scene.stop": "0.2 s", "master.algorithm": "regime-aware", "master.tolerance": 3e-4},
    ),
    "lever": ("lever_unit_decay.toml", {"scene.stop": "2 s"}),
}

# One process per path.  argv: output folder, then "short" and the short runs as JSON, or
# scene files run to their end.
_RUN = """
import hashlib, json, sys
from pathlib import Path
import numpy as np
from components.crank_coupler_drive import (
    STATE_SCALES, _CouplerMotion, build_drive_model)
from components.event_integration import IntegrationStepControl, StepBudgetSpent, advance
from components.kernels import load_kernel
from components.press_feed_data import LINKAGE_TABLE1
from components.rssr_kinematics import ExactRSSR
from dataclasses import replace
from orchestrator.run import run_scene
from orchestrator.scenario import load_scene
from orchestrator.scenes import REFERENCES
from orchestrator.scenes.press_feed.monolithic import (
    FeedOptions, simulate_decay_experiment, simulate_feed)

def exact(value):
    # every number by its shortest round-trip text (the same text: the same bits); a numpy
    # scalar of the Python path is the same double as the kernel's float
    return json.dumps(value, default=lambda a: np.asarray(a).tolist(), sort_keys=True)

def digest(res):
    h = hashlib.sha256(exact((res.cycles, res.regime_log, res.energy, res.events)).encode())
    for k in sorted(res.series):
        h.update(np.ascontiguousarray(res.series[k]).tobytes())
    return h.hexdigest()

def reference_digest(scene):
    ref = REFERENCES[scene.reference](scene)
    h = hashlib.sha256(exact((ref.headline, ref.events, ref.t_range)).encode())
    grid = np.linspace(scene.start, scene.stop, 2001)
    for k, v in sorted(ref.signals(grid).items()):
        h.update(np.ascontiguousarray(v).tobytes())
    return h.hexdigest()

out = {"compiled": load_kernel("press_feed_kernel") is not None, "runs": {}, "references": {}}
folder = Path(sys.argv[1])
if sys.argv[2] == "short":
    for name, (file, overrides) in json.loads(sys.argv[3]).items():
        scene = load_scene(Path("scenarios") / file, overrides)
        run_scene(scene, output_dir=folder / name, show_progress=False,
                  compare_reference=False, plots=False)
        if name != "run1_midpoint":  # the same reference as the Gauss-Seidel run's
            out["references"][name] = reference_digest(scene)
    out["references"]["linearized"] = digest(simulate_feed(FeedOptions(model="linearized")))
    out["references"]["rigid_decay"] = digest(simulate_decay_experiment(72.0, 1.8))
    # The drive's step budget: 3 internal steps, then the 4th is refused.
    m = build_drive_model(200.0)
    control = IntegrationStepControl(1e-10, STATE_SCALES, 1e-3, max_steps=3)
    try:
        advance(_CouplerMotion(m, 5.0, 1.0, 10.0, 0.1), [0.1, 0.0, 0.0, 0.0, 0.0], 0.05,
                 control, 0.0)
        out["budget"] = ["done"]
    except StepBudgetSpent as exc:
        out["budget"] = [type(exc).__module__, str(exc)]
    # Linkages that assemble over part of the turn or not at all: values, or the same error.
    out["kinematics"] = []
    for stretch in (1.0, 1.02, 1.05, 2.0):
        kin = ExactRSSR(replace(LINKAGE_TABLE1, a3=LINKAGE_TABLE1.a3 * stretch), 0.4)
        for k in range(24):
            try:
                out["kinematics"].append(exact(kin(k * 0.2618)))
            except (ArithmeticError, ValueError) as exc:
                out["kinematics"].append([type(exc).__name__, str(exc)])
    done = advance(_CouplerMotion(m, 5.0, 1.0, 10.0, 0.1), [0.1, 0.0, 0.0, 0.0, 0.0], 0.3,
                    IntegrationStepControl(1e-8, STATE_SCALES, 1e-3), 0.0)
    out["advance"] = repr(tuple(done))
else:
    for file in sys.argv[2:]:
        scene = load_scene(Path("scenarios") / file, {})
        run_scene(scene, output_dir=folder / file, show_progress=False,
                  compare_reference=False, plots=False)
        out["references"][file] = reference_digest(scene) if scene.reference else ""
print(json.dumps(out))
"""


def _csvs(folder: Path) -> dict[str, bytes]:
    return {
        f"{run.name}/{f}": (run / f).read_bytes()
        for run in sorted(p for p in folder.iterdir() if p.is_dir())
        for f in ("timeseries.csv", "events.csv")
    }


def _run(pure: bool, out: Path, *what: str) -> dict:
    """The outputs of one path: the compiled flag, the digests, the CSVs of the runs.  The
    Python path runs in a process of its own; the compiled one here, where the kernels are
    loaded (a process costs more than the runs)."""
    argv = [str(out), *what]
    printed = printed_by(_RUN, argv, pure, "<press feed kernel run>")
    result = json.loads(printed.strip().splitlines()[-1])
    result["csv"] = _csvs(out)
    return result


@pytest.fixture(scope="module")
def short_runs(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, dict]:
    """Both paths on the short runs and their references."""
    folder = tmp_path_factory.mktemp("press_lever_kernels")
    short = json.dumps(SHORT)
    compiled = _run(False, folder / "compiled", "short", short)
    python = _run(True, folder / "python", "short", short)
    return compiled, python


@needs_kernels
def test_the_press_feed_fmus_ship_the_kernel() -> None:
    with zipfile.ZipFile(build_fmu("CrankCouplerDrive")) as z:
        assert any(n.endswith("/components/press_feed_kernel.so") for n in z.namelist())


@needs_kernels
def test_both_paths_agree_on_short_press_feed_and_lever_runs(short_runs: tuple[dict, dict]) -> None:
    compiled, python = short_runs
    assert (compiled["compiled"], python["compiled"]) == (True, False)
    expected = sorted(f"{n}/{f}" for n in SHORT for f in ("timeseries.csv", "events.csv"))
    assert sorted(compiled["csv"]) == expected
    assert compiled["csv"] == python["csv"]
    # The runs did move: 0.31 s of 0.1 ms steps, and the rocker reversed (0.149 s in).
    gauss_seidel = compiled["csv"]["run1_gauss_seidel/timeseries.csv"]
    assert gauss_seidel.count(b"\n") == 3101 + 1
    for run in ("run1_gauss_seidel", "run1_midpoint"):
        assert b"drive,forward,return" in compiled["csv"][f"{run}/events.csv"]


@needs_kernels
def test_both_paths_agree_on_the_press_feed_references(short_runs: tuple[dict, dict]) -> None:
    compiled, python = short_runs
    assert compiled["references"] == python["references"]
    assert set(compiled["references"]) == {
        "run1_gauss_seidel",
        "lever",
        "linearized",
        "rigid_decay",
    }
    assert compiled["advance"] == python["advance"]


@needs_kernels
def test_both_paths_agree_where_a_linkage_does_not_assemble(short_runs: tuple[dict, dict]) -> None:
    compiled, python = short_runs
    assert compiled["kinematics"] == python["kinematics"]
    refused = [k for k in compiled["kinematics"] if isinstance(k, list)]
    assert ["ValueError", "math domain error"] in refused  # the square root of (A.8)
    assert len(refused) < len(compiled["kinematics"])  # and values where it assembles


@needs_kernels
def test_a_spent_step_budget_ends_both_drive_paths_alike(short_runs: tuple[dict, dict]) -> None:
    compiled, python = short_runs
    assert compiled["budget"] == python["budget"]
    module, message = compiled["budget"]
    assert module == "components.event_integration"
    assert message.startswith("spent its budget of 3 internal steps (max_internal_steps)")


#: The example scenes of the two families, each run to its end by both paths.
FULL_SCENES = (
    "press_feed_run1.toml",
    "press_feed_run2.toml",
    "press_feed_run3.toml",
    "sprag_decay_72rpm.toml",
    "lever_unit_decay.toml",
    "lever_asymmetric.toml",
    "lever_unit_decay_angle_switched.toml",
)


@pytest.mark.slow
@needs_kernels
@pytest.mark.parametrize("scene", FULL_SCENES)
def test_both_paths_agree_on_the_whole_scenes(scene: str, tmp_path: Path) -> None:
    compiled = _run(False, tmp_path / "c", scene)
    python = _run(True, tmp_path / "py", scene)
    assert compiled["csv"] == python["csv"]
    assert compiled["references"] == python["references"]
