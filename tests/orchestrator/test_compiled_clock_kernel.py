"""The clock-train kernel (components/clock_train_kernel.pyx) gives the same bits as the
Python code: the clock-train scene, its monolithic reference and the train's model under
each wrapper the train component integrates it in are run with each path, in processes of
their own (the kernels are bound at import), and compared byte for byte."""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

import pytest
from kernel_paths import needs_kernels, printed_by, spent_budgets_alike

from fmus.build import build_fmu

# One process per path: argv = scene stop ("-": no scene run), output folder, then the
# monolithic runs as JSON keyword dictionaries.
_RUN = """
import hashlib, json, sys
from pathlib import Path
from components import event_integration as ei
from components.clock_gear_train import ClockTrainPhysics, _ClockModel
from components.early_return import UntilFirstEvent
from components.kernels import load_kernel
from components.m739_data import M739, rpm_to_rad_s
from components.train_component import STATE_SCALES, RampedLoad
from orchestrator.run import run_scene
from orchestrator.scenario import load_scene
from components.verge_escapement import STATE_SCALES as VERGE_SCALES
from components.verge_escapement import StepBudgetSpent as VergeBudgetSpent
from components.verge_escapement import VergeConstants, escapement_data
from orchestrator.scenes.clock_train.monolithic import _ClockMonolithic, arming_phi
from orchestrator.scenes.clock_train.monolithic import run_clock_train

def digest(r):
    h = hashlib.sha256(repr((r.armed, r.reason, r.turns, r.f23_max, r.f12_max, r.ff23_max,
                             r.ff12_max, r.pn_max, r.impacts, r.events, r.train_log,
                             r.handovers)).encode())
    for v in r.series.values():
        h.update(v.tobytes())
    return h.hexdigest()

out = {"compiled": load_kernel("clock_train_kernel") is not None}
out["monolithic"] = [digest(run_clock_train(**json.loads(a))) for a in sys.argv[3:]]

# The train's model alone, under each wrapper, from rest against a held escapement torque:
# the state, the counts, the memos the friction branches read and the force peaks.
def model(loss_model, t_esc):
    p = ClockTrainPhysics(omega=rpm_to_rad_s(M739.rpm), loss_model=loss_model)
    m = _ClockModel(p)
    m.t_esc = t_esc
    m.try_unstick(0.0)
    return p, m

out["model"], out["events"] = [], []
for loss_model in (0, 1, 2):
    for wrap in ("bare", "ramped", "first event", "budget"):
        p, m = model(loss_model, -2e-4)
        control = ei.IntegrationStepControl(1e-7, STATE_SCALES, 1e-4,
                                            5 if wrap == "budget" else None)
        y = [0.0, 0.0, 0.0]
        wrapped = m
        if wrap == "ramped":
            wrapped, y = RampedLoad(m, 1e-2), [*y, m.t_esc]
            control = ei.IntegrationStepControl(1e-7, (*STATE_SCALES, 1.0), 1e-4)
        elif wrap == "first event":
            wrapped = UntilFirstEvent(m, 0.0)
        try:
            done = [tuple(ei.advance(wrapped, y, 2e-3, control))]
            out["events"].append(done[0][3])
        except ei.StepBudgetSpent as exc:
            done = [str(exc)]
        out["model"].append(repr((done, p.memos(), p.evaluate_phi, m.peaks, m.stuck,
                                  p.mode_key(), p.handovers, m.t_esc)))

# The physics' methods one by one: on a grid of positions, each direction, normal-force
# signs and loss model, on the piece entered there and on pieces beyond their reach (no
# contact): the values, or the exception and its message.
def outcome(f, *args):
    try:
        return repr(f(*args))
    except (ArithmeticError, ValueError) as exc:
        return repr(exc)

twins = hashlib.sha256()
out["twin errors"] = 0
for loss_model in (0, 1, 2):
    p = ClockTrainPhysics(omega=rpm_to_rad_s(M739.rpm), loss_model=loss_model)
    for j in range(25):
        phi = -0.9 + 0.075 * j
        for direction in (1, -1):
            p.set_mode(phi, direction)
            entered = p.pieces
            for shift in (0, 2):
                p.pieces = tuple((k + shift, ph, sg) for k, ph, sg in entered)
                for sigma in ((1, 1), (-1, 1), (1, -1)):
                    p.sigma = sigma
                    rows = [outcome(p.evaluate, phi), outcome(p.response, phi, 300.0 * j - 50.0),
                            outcome(p.forces, phi, 120.0, 3.0e4 - 2.0e3 * j),
                            outcome(p.power_terms, phi), outcome(p.piece_distances, phi)]
                    if not rows[0].startswith("ValueError"):
                        rows.append(outcome(p.point_efficiency, 1, p.evaluate(phi)[9]))
                    out["twin errors"] += sum(r.startswith("ValueError") for r in rows)
                    twins.update(repr(rows).encode())
out["twins"] = twins.hexdigest()

# The monolithic model's own loop with the integration's budget (steps), the verge's
# (indicator evaluations), then neither.
def start():
    omega = rpm_to_rad_s(M739.rpm)
    data = escapement_data(M739.a, pallet_inertia=M739.ip)
    train = ClockTrainPhysics(omega=omega)
    k = VergeConstants(data, M739.mu1, M739.mu, omega, M739.e_rest)
    core = _ClockMonolithic(k, train, data.phi_start, phi_stop=arming_phi(train))
    return core, core.decide_direction(core._sync_kinematics([0.0] * 5), 0.0, 1)

out["budgets"] = []
for steps, evaluations in ((7, None), (None, 40), (None, 100_000)):
    core, y = start()
    core.budget = evaluations
    try:
        control = ei.IntegrationStepControl(1e-9, VERGE_SCALES, max_steps=steps)
        done = ei.advance(core, y, 2e-3, control)
        out["budgets"].append(["done", *done[1:], core.budget, repr(done.y),
                               repr(core.train.memos()), repr(core.__dict__.get("_memo"))])
    except (ei.StepBudgetSpent, VergeBudgetSpent) as exc:
        out["budgets"].append([type(exc).__module__, str(exc), core.budget])

def run(overrides, folder):
    scene = load_scene(Path("scenarios/clock_train_sa.toml"), overrides)
    run_scene(scene, output_dir=Path(folder), show_progress=False,
              compare_reference=False, plots=False)

if sys.argv[1] == "full":
    run({}, sys.argv[2])
elif sys.argv[1] != "-":  # and the cycle efficiencies' train, undamped by the verge
    run({"scene.stop": sys.argv[1]}, sys.argv[2])
    run({"scene.stop": "4 ms", "fmus.train.parameters.loss_model": 2,
         "fmus.verge.parameters.e_rest": 0.3}, Path(sys.argv[2]) / "cycle")
print(json.dumps(out))
"""

#: the monolithic runs compared: the scene's physics, each loss model, no friction, a looser
#: tolerance and another train
SHORT_MONOLITHIC = (
    {"t_stop": 0.006},
    {"t_stop": 0.004, "loss_model": 0},
    {"t_stop": 0.004, "loss_model": 2},
    {"t_stop": 0.003, "mu": 0.0},
    {"t_stop": 0.006, "tolerance": 1e-6},
    # another geometry: phased cluster, other round offsets, the train started mid-piece
    {
        "t_stop": 0.004,
        "mesh_phase": 0.2,
        "pivot_loads": False,
        "design": {"cluster_phasing": 0.1, "gear1_round_offset": 0.12, "pinion3_teeth": 9},
    },
)


def _run(pure: bool, stop: str, out: Path, *monolithic: dict) -> dict:
    """The outputs of one path: the compiled flag, the monolithic digests, the model runs
    and the scene's CSVs (stop '-': no scene run).  The Python path runs in a process of
    its own; the compiled one here, where the kernels are loaded."""
    argv = [stop, str(out), *(json.dumps(kw) for kw in monolithic)]
    printed = printed_by(_RUN, argv, pure, "<clock kernel run>")
    result = json.loads(printed.strip().splitlines()[-1])
    if stop != "-":
        files = ("timeseries.csv", "events.csv")
        result["csv"] = {f: (out / f).read_bytes() for f in files}
        if stop != "full":
            result["cycle csv"] = {f: (out / "cycle" / f).read_bytes() for f in files}
    return result


@pytest.fixture(scope="module")
def short_runs(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict, dict]:
    """Both paths on the first 10 ms of clock_train_sa.toml, the short monolithic runs, the
    model runs and the budgets."""
    folder = tmp_path_factory.mktemp("clock_kernel")
    compiled = _run(False, "10 ms", folder / "compiled", *SHORT_MONOLITHIC)
    python = _run(True, "10 ms", folder / "python", *SHORT_MONOLITHIC)
    return compiled, python


@needs_kernels
def test_the_clock_train_fmu_ships_the_kernel() -> None:
    with zipfile.ZipFile(build_fmu("ClockGearTrain")) as z:
        assert any(n.endswith("/components/clock_train_kernel.so") for n in z.namelist())


@needs_kernels
def test_both_paths_agree_on_a_short_clock_train_run(short_runs: tuple[dict, dict]) -> None:
    compiled, python = short_runs
    assert (compiled["compiled"], python["compiled"]) == (True, False)
    assert compiled["csv"] == python["csv"]
    events = compiled["csv"]["events.csv"].decode()
    assert events.count("\n") > 10  # the run did move: impacts and tooth handovers
    assert compiled["cycle csv"] == python["cycle csv"]
    assert compiled["cycle csv"]["timeseries.csv"].count(b"\n") > 10


@needs_kernels
def test_both_paths_agree_on_the_short_monolithic_runs(short_runs: tuple[dict, dict]) -> None:
    compiled, python = short_runs
    assert len(compiled["monolithic"]) == len(SHORT_MONOLITHIC)
    assert compiled["monolithic"] == python["monolithic"]


@needs_kernels
def test_both_paths_agree_on_the_train_model_in_every_wrapper(
    short_runs: tuple[dict, dict],
) -> None:
    compiled, python = short_runs
    assert compiled["model"] == python["model"]
    # Each loss model: three runs that end and one whose budget of 5 steps is spent.
    spent = [r for r in compiled["model"] if "spent its budget of 5 internal steps" in r]
    assert len(spent) == 3 and len(compiled["model"]) == 12
    # Bare and ramped the runaway train crosses pieces and pitch points; to its first
    # event it ends at one.
    assert compiled["events"] == python["events"]
    assert [n > 20 for n in compiled["events"]] == [True, True, False] * 3


@needs_kernels
def test_both_paths_agree_on_the_physics_methods(short_runs: tuple[dict, dict]) -> None:
    compiled, python = short_runs
    assert compiled["twins"] == python["twins"]
    # Pieces beyond their reach (two pitches on) fail alike: no contact.
    assert compiled["twin errors"] == python["twin errors"] > 100


@needs_kernels
def test_a_spent_step_budget_ends_both_paths_alike(short_runs: tuple[dict, dict]) -> None:
    compiled, python = short_runs
    unbounded = spent_budgets_alike(compiled["budgets"], python["budgets"])
    # Without a budget the 2 ms run ends, past several events, having counted the same.
    assert unbounded[0] == "done" and unbounded[3] > 5 and 0 < unbounded[7] < 100_000


@pytest.mark.slow
@needs_kernels
def test_both_paths_agree_on_the_clock_train_scene(tmp_path: Path) -> None:
    compiled = _run(False, "full", tmp_path / "c")
    assert compiled["csv"] == _run(True, "full", tmp_path / "py")["csv"]


@pytest.mark.slow
@needs_kernels
def test_both_paths_agree_on_the_clock_train_monolithic_model(tmp_path: Path) -> None:
    full = ({"t_stop": 0.2}, {"t_stop": 0.2, "loss_model": 2})
    assert (
        _run(False, "-", tmp_path, *full)["monolithic"]
        == (_run(True, "-", tmp_path, *full)["monolithic"])
    )
