"""A controller from another tool whose initialization needs a zero set point, driven by a
set-point step: it runs under every master from a scene file and agrees with FMPy's
simulate_fmu given the same input signal."""

from __future__ import annotations

from pathlib import Path

import foreign_fmus
import numpy as np
import pytest
from fmpy import simulate_fmu
from scene_run import run_file

from orchestrator.errors import ScenarioError
from orchestrator.run import run_scene
from orchestrator.scenario import load_scene

if foreign_fmus.c_compiler() is None:
    pytest.skip("no C compiler to build the foreign test FMUs", allow_module_level=True)

MASTERS = ("jacobi", "gauss-seidel", "regime-aware")
KP, KI, U_M = 2e-3, 1e-2, 0.25


@pytest.fixture(scope="module")
def controller(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return foreign_fmus.build_pi_controller(tmp_path_factory.mktemp("pi"))


def scene(tmp_path: Path, fmu: Path, u_s: str, extra: str = "", stop: str = "10 ms") -> Path:
    path = tmp_path / "pi.toml"
    path.write_text(
        f"""
[scene]
name = "pi"
stop = "{stop}"

[fmus.c]
fmu = "{fmu}"
parameters = {{ kp = {KP}, ki = {KI} }}
inputs = {{ u_s = {u_s}, u_m = {U_M} }}
{extra}
[master]
algorithm = "jacobi"
step = "1 ms"
"""
    )
    return path


def run(path: Path, tmp_path: Path, algorithm: str):
    return run_file(path, tmp_path / algorithm, {"master.algorithm": algorithm})


@pytest.mark.parametrize("algorithm", MASTERS)
def test_a_step_at_the_start_runs_where_the_constant_cannot(
    controller: Path, tmp_path: Path, algorithm: str
) -> None:
    """u_s = 1 throughout fails in the FMU's initialization (as in FMPy); a step from 0 to
    1 at t = 0 initializes with 0 and drives the controller with 1 from the first step."""
    failed = run(scene(tmp_path, controller, "1.0"), tmp_path, algorithm)
    assert failed.status == "failed" and "must be 0 during initialization" in failed.message
    with pytest.raises(Exception, match="fmi2ExitInitializationMode failed"):
        simulate_fmu(str(controller), stop_time=0.01, start_values={"u_s": 1.0})

    result = run(
        scene(tmp_path, controller, '{ step = "0 s", from = 0, to = 1 }'), tmp_path, algorithm
    )
    assert result.status == "completed", result.message
    t, x, y = result.signal("time"), result.signal("c.x"), result.signal("c.y")
    assert y[0] == pytest.approx(KP * (0.0 - U_M), abs=1e-18)  # initialized at u_s = 0
    np.testing.assert_allclose(x, (1.0 - U_M) * t, rtol=1e-12, atol=1e-16)
    np.testing.assert_allclose(y[1:], KP * (1.0 - U_M) + KI * x[1:], rtol=1e-12)


@pytest.mark.parametrize("algorithm", MASTERS)
def test_agrees_with_fmpy_simulate_fmu_given_the_same_input(
    controller: Path, tmp_path: Path, algorithm: str
) -> None:
    """Set point 0, stepping to 1 at 1.5 ms (between communication points) and to -0.5 at
    6 ms; FMPy is given the signal as its input table (the jumps as repeated times)."""
    table = '{ table = [[0, 0], ["1.5 ms", 0], ["1.5 ms", 1], ["6 ms", 1], ["6 ms", -0.5]] }'
    path = scene(tmp_path, controller, table)
    ours = run(path, tmp_path, algorithm)
    assert ours.status == "completed", ours.message
    signal = load_scene(path).fmus["c"].signals["u_s"]
    times, values = signal.as_linear_table()
    given = np.array(list(zip(times, values, strict=True)), dtype=[("time", float), ("u_s", float)])
    theirs = simulate_fmu(
        str(controller),
        stop_time=0.01,
        output_interval=1e-3,
        input=given,
        start_values={"kp": KP, "ki": KI, "u_m": U_M},
        output=["x", "y"],
    )
    t = ours.signal("time")
    for jump in signal.jumps:
        assert np.any(t == jump)  # our master ended a step there
    # FMPy records no row at a jump on its output grid (6 ms), nor at one between (1.5 ms).
    keep = ~np.isin(theirs["time"], signal.jumps)
    their_t = theirs["time"][keep]
    np.testing.assert_allclose(their_t, np.delete(np.arange(11) * 1e-3, 6), rtol=1e-12)
    if algorithm == "regime-aware":  # its own steps: x is linear between the jumps
        left = np.r_[np.diff(t) > 0, True]  # the right value at each instant
        ours_x = np.interp(their_t, t[left], ours.signal("c.x")[left])
        ours_y = np.interp(their_t, t[left], ours.signal("c.y")[left])
    else:
        on = np.isin(t, their_t)
        ours_x, ours_y = ours.signal("c.x")[on], ours.signal("c.y")[on]
    np.testing.assert_allclose(ours_x, theirs["x"][keep], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(ours_y, theirs["y"][keep], rtol=1e-12, atol=1e-15)
    assert ours.signal("c.x")[-1] == pytest.approx(
        (1 - U_M) * 4.5e-3 + (-0.5 - U_M) * 4e-3 - U_M * 1.5e-3, rel=1e-12
    )


@pytest.mark.parametrize("algorithm", ("jacobi", "gauss-seidel"))
def test_a_ramp_is_recorded_as_fmpy_records_it(
    controller: Path, tmp_path: Path, algorithm: str
) -> None:
    """A set-point ramp into the controller, whose output follows the set point directly
    (y = kp (u_s - u_m) + ki x): every row, y and x, equals FMPy's given the same ramp (the
    input held over each step, the row after it showing what the step used; before, y read
    the ramp one step ahead)."""
    ramp = '{ ramp = ["1 ms", "8 ms"], from = 0, to = 1 }'
    path = scene(tmp_path, controller, ramp)
    ours = run(path, tmp_path, algorithm)
    assert ours.status == "completed", ours.message
    given = np.array([(0.0, 0.0), (1e-3, 0.0), (8e-3, 1.0), (1e-2, 1.0)],
                     dtype=[("time", float), ("u_s", float)])  # fmt: skip
    theirs = simulate_fmu(
        str(controller),
        stop_time=0.01,
        output_interval=1e-3,
        input=given,
        start_values={"kp": KP, "ki": KI, "u_m": U_M},
        output=["x", "y", "u_s"],
    )
    assert len(theirs) == len(ours.data) == 11
    for name in ("x", "y", "u_s"):
        np.testing.assert_allclose(
            ours.signal(f"c.{name}"), theirs[name], rtol=1e-12, atol=1e-15, err_msg=name
        )
    # the row at 2 ms holds the set point the step from 1 ms used: 0
    assert ours.signal("c.u_s")[2] == 0.0 and ours.signal("c.u_s")[3] == pytest.approx(1 / 7)


@pytest.mark.parametrize("algorithm", MASTERS)
def test_the_pair_runs_from_a_scene_file(controller: Path, tmp_path: Path, algorithm: str) -> None:
    """Controller and drivetrain (our Inertia, J = 2e-4 kg m^2) coupled y -> tau, w -> u_m,
    set point 0 stepping to 1 rad/s at t = 0+: the closed loop J w'' + kp w' + ki w = ki
    with w(0) = 0 and w'(0+) = kp/J gives w = 1 - exp(-5t) (cos 5t - sin 5t).  Measured
    largest deviation over 3 s: Jacobi at 1 ms 0.0100, regime-aware at tolerance 1e-2
    0.0041 (first-order coupling errors); the speed ends on the set point."""
    extra = """
[fmus.d]
component = "Inertia"
parameters = { J = "2e-4 kg*m^2" }

[[connections]]
from = "c.y"
to = "d.tau"
[[connections]]
from = "d.w"
to = "c.u_m"
"""
    path = scene(tmp_path, controller, '{ step = "0 s", from = 0, to = "1 rad/s" }', extra, "3 s")
    path.write_text(path.read_text().replace(", u_m = 0.25", ""))
    result = run_scene(
        load_scene(path, {"master.algorithm": algorithm, "master.tolerance": 1e-2}),
        output_dir=tmp_path / "pair",
        show_progress=False,
    )
    assert result.status == "completed", result.message
    t, w = result.signal("time"), result.signal("d.w")
    exact = 1.0 - np.exp(-5.0 * t) * (np.cos(5.0 * t) - np.sin(5.0 * t))
    assert w[0] == 0.0 and abs(w[-1] - 1.0) < 2e-5
    assert np.max(np.abs(w - exact)) < 1.1e-2
    assert result.signal("c.u_s")[-1] == 1.0  # recorded like the outputs


def test_a_set_point_beyond_the_inputs_range_is_refused(controller: Path, tmp_path: Path) -> None:
    path = scene(tmp_path, controller, '{ table = [[0, 0], ["1 ms", "200 rad/s"]] }')
    with pytest.raises(
        ScenarioError, match=r"\[fmus.c.inputs.u_s.table\[1\]\] 200 rad/s is outside"
    ):
        load_scene(path)


@pytest.mark.slow  # in the slow suite (CI runs it): the default stays under 2 minutes
def test_crosscheck_gives_fmpy_simulate_fmu_the_same_input(controller: Path, tmp_path: Path):
    """``mechcosim crosscheck`` runs a one-FMU scene with held signals through FMPy's
    simulate_fmu with the signals as its input table, and libcosim (--via osp) with them
    as a scenario file where every jump is on its grid."""
    from orchestrator.cli import main
    from orchestrator.studies.crosscheck import crosscheck

    table = '{ table = [[0, 0], ["1.5 ms", 0], ["1.5 ms", 1], ["6 ms", 1], ["6 ms", -0.5]] }'
    path = scene(tmp_path, controller, table)
    check = crosscheck(path, tools=("fmpy",))
    (outcome,) = check.outcomes
    assert outcome.cannot_run is None and outcome.run.via == "simulate_fmu with the input signals"
    assert outcome.agreement.points == 9  # not at the jump at 6 ms (FMPy: values before it)
    assert outcome.agreement.worst[1] <= 1e-12, outcome.agreement.per_signal
    assert main(["crosscheck", str(path), "--tool", "fmpy"]) == 0

    check = crosscheck(path, tools=("libcosim",), via="osp")  # the jump at 1.5 ms is off grid
    assert "not on libcosim's base step grid" in check.outcomes[0].cannot_run
    path = scene(tmp_path, controller, '{ step = "2 ms", from = 0, to = 1 }')
    check = crosscheck(path, tools=("libcosim", "fmpy"), via="osp")
    assert all(o.agreement.worst[1] <= 1e-12 for o in check.outcomes), check.outcomes
    # Neither tool shows the values after the jump at its instant (2 ms): 9 of 10 points.
    assert [o.agreement.points for o in check.outcomes] == [9, 9]

    path = scene(tmp_path, controller, '{ step = "0 s", from = 0, to = 1 }')
    check = crosscheck(path, tools=("fmpy",))
    assert "holds a table's first value over the first step" in check.outcomes[0].cannot_run
