"""The compiled kernels (components.kernels) give the same bits as the Python code: the
M739 scenes and monolithic model are run with each path, in processes of their own (the
kernels are bound at import), and their outputs compared byte for byte; a spent step budget
ends both paths with the same error at the same point."""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import pytest
from kernel_paths import PROJECT, needs_kernels, printed_by, spent_budgets_alike

from fmus.build import build_fmu

# One process per path: argv = scene (or -), its output folder, monolithic stop times.
_RUN = """
import hashlib, json, sys
from pathlib import Path
from components import event_integration as ei
from components.gear_train import TrainPhysics
from components.kernels import load_kernel
from components.m739_data import M739, rpm_to_rad_s
from components.verge_escapement import STATE_SCALES, StepBudgetSpent, VergeConstants
from orchestrator.run import run_scene
from orchestrator.scenario import load_scene
from orchestrator.scenes.m739.monolithic import VergeTrainMonolithic, run_m739

def digest(r):
    h = hashlib.sha256(repr((r.armed, r.turns, r.f23_max, r.f12_max, r.ff23_max, r.ff12_max,
                             r.pn_max, r.impacts, r.events, r.train_log)).encode())
    for v in r.series.values():
        h.update(v.tobytes())
    return h.hexdigest()

out = {"compiled": load_kernel("m739_kernel") is not None}
out["monolithic"] = [digest(run_m739(t_stop=float(t))) for t in sys.argv[3:]]
if sys.argv[1] != "-":
    overrides = {} if sys.argv[1].endswith("full") else {"scene.stop": "5 ms"}
    scene = load_scene(Path("scenarios") / sys.argv[1].split(":")[0], overrides)
    run_scene(scene, output_dir=Path(sys.argv[2]), show_progress=False,
              compare_reference=False, plots=False)

def start():
    omega = rpm_to_rad_s(M739.rpm)
    core = VergeTrainMonolithic(
        VergeConstants(M739, M739.mu1, M739.mu, omega, M739.e_rest),
        TrainPhysics(M739, mu=M739.mu, omega=omega), M739.phi_start, phi_stop=M739.phi_cut)
    return core, core.decide_direction(core._sync_kinematics([0.0] * 5), 0.0, 1)

# The integration's budget (steps) and the verge's (indicator evaluations), then neither.
out["budgets"] = []
for steps, evaluations in ((7, None), (None, 40), (None, 100_000)):
    core, y = start()
    core.budget = evaluations
    try:
        control = ei.IntegrationStepControl(1e-9, STATE_SCALES, max_steps=steps)
        done = ei.advance(core, y, 2e-3, control)
        result = ["done", done.steps, done.rejected, done.events, core.budget, repr(done.y)]
        out["budgets"].append(result)
    except (ei.StepBudgetSpent, StepBudgetSpent) as exc:
        out["budgets"].append([type(exc).__module__, str(exc), core.budget])
print(json.dumps(out))
"""


def _run(pure: bool, scene: str, out: Path, *t_stops: float) -> dict:
    """The outputs of one path: the compiled flag, the monolithic digests, the step budgets'
    outcomes and the scene's CSVs (scene '-': none; 'name.toml:full': to its end).  The
    Python path runs in a process of its own; the compiled one here, where the kernels are
    loaded (a process costs more than the runs)."""
    argv = [scene, str(out), *map(str, t_stops)]
    printed = printed_by(_RUN, argv, pure, "<compiled kernel run>")
    result = json.loads(printed.strip().splitlines()[-1])
    if scene != "-":
        result["csv"] = {f: (out / f).read_bytes() for f in ("timeseries.csv", "events.csv")}
    return result


@pytest.fixture(scope="module")
def short_runs(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, dict]:
    """Both paths on the first 5 ms of m739.toml and of its monolithic model."""
    folder = tmp_path_factory.mktemp("kernels")
    compiled = _run(False, "m739.toml", folder / "compiled", 0.005)
    python = _run(True, "m739.toml", folder / "python", 0.005)
    return compiled, python


@needs_kernels
def test_the_verge_and_train_fmus_ship_the_kernel() -> None:
    for name in ("VergeEscapement", "GearTrain"):
        with zipfile.ZipFile(build_fmu(name)) as z:
            assert any(n.endswith("/components/m739_kernel.so") for n in z.namelist()), name


@needs_kernels
def test_both_paths_agree_on_a_short_m739_run(short_runs: tuple[dict, dict]) -> None:
    compiled, python = short_runs
    assert (compiled["compiled"], python["compiled"]) == (True, False)
    assert compiled["monolithic"] == python["monolithic"]
    assert compiled["csv"] == python["csv"]
    assert compiled["csv"]["timeseries.csv"].count(b"\n") > 10  # the run did move


@needs_kernels
def test_a_spent_step_budget_ends_both_paths_alike(short_runs: tuple[dict, dict]) -> None:
    compiled, python = short_runs
    unbounded = spent_budgets_alike(compiled["budgets"], python["budgets"])
    # Without a budget the 2 ms run ends, some of the 100,000 evaluations spent.
    assert unbounded[0] == "done" and 0 < unbounded[4] < 100_000


@pytest.mark.slow
@needs_kernels
# The clock-train S&A: the M739 verge component (its compiled outputs, input take and event
# resync) held against a train of another kind.
@pytest.mark.parametrize("scene", ["m739.toml", "m739_from_deck.toml", "clock_train_sa.toml"])
def test_both_paths_agree_on_the_m739_scenes(scene: str, tmp_path: Path) -> None:
    compiled = _run(False, f"{scene}:full", tmp_path / "c")
    assert compiled["csv"] == _run(True, f"{scene}:full", tmp_path / "py")["csv"]


@pytest.mark.slow
@needs_kernels
def test_both_paths_agree_on_the_m739_monolithic_model(tmp_path: Path) -> None:
    assert (
        _run(False, "-", tmp_path, 0.2)["monolithic"]
        == _run(True, "-", tmp_path, 0.2)["monolithic"]
    )


def test_an_fmu_ships_only_the_kernels_its_code_loads() -> None:
    from fmus.build import _kernels
    from fmus.registry import FMU_RECORDS

    def shipped(name: str) -> list[str]:
        return _kernels(FMU_RECORDS[name].modules())

    assert shipped("GearTrain") == ["m739_kernel"]
    assert shipped("ClockGearTrain") == ["clock_train_kernel", "m739_kernel"]
    assert shipped("Inertia") == []


@needs_kernels
def test_both_paths_give_every_output_of_the_m739_fmus_alike(tmp_path: Path) -> None:
    """Every output of the verge and the train, not only those the scene records: the
    compiled outputs set them all (5 ms of M739: contacts, impacts, free flights)."""
    from components.gear_train import GearTrain
    from components.verge_escapement import VergeEscapement

    record = [
        f"{fmu}.{v.name}"
        for fmu, component in (("train", GearTrain), ("verge", VergeEscapement))
        for v in component.VARIABLES
        if v.causality == "output"
    ]
    text = (PROJECT / "scenarios" / "m739.toml").read_text()
    scene, rest = text.split("[output]")
    scene += f"[output]\nrecord = {json.dumps(record)}\n\n" + rest[rest.index("[report]") :]
    path = tmp_path / "m739_every_output.toml"
    path.write_text(scene)
    compiled = _run(False, str(path), tmp_path / "c")
    python = _run(True, str(path), tmp_path / "py")
    assert compiled["csv"]["timeseries.csv"].splitlines()[0].count(b",") == len(record)
    assert compiled["csv"]["timeseries.csv"].count(b"\n") > 10  # the run did move
    assert compiled["csv"] == python["csv"]
