"""Inputs that vary in time: the signal tables, their loading and checks, and every master
landing on their jumps and kinks, against the closed form of a body driven by a torque."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scene_run import run_file

from orchestrator.errors import ScenarioError
from orchestrator.model_info import VariableInfo
from orchestrator.scenario import load_scene
from orchestrator.signals import InputSignals, Reader, Signal, read_signal

J = 2e-4  # kg m^2, the driven body
MASTERS = ("jacobi", "gauss-seidel", "regime-aware")


def scene_text(inputs: str, stop: str = "10 ms", step: str = "1 ms", algorithm="jacobi") -> str:
    return f"""
[scene]
name = "signal"
stop = "{stop}"

[fmus.a]
component = "Inertia"
parameters = {{ J = "{J} kg*m^2" }}
inputs = {{ tau = {inputs} }}

[master]
algorithm = "{algorithm}"
step = "{step}"
"""


def write(tmp_path: Path, text: str, name: str = "scene.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def run(tmp_path: Path, path: Path, **overrides):
    return run_file(path, tmp_path / "out", overrides, completed=True)


def motion(signal: Signal, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Closed form of the body from rest under a piecewise-linear torque: w and phi."""
    times, values = signal.as_linear_table()
    knots = sorted({*times, *t.tolist(), 0.0})
    w = {0.0: 0.0}
    phi = {0.0: 0.0}
    for a, b in zip(knots, knots[1:], strict=False):
        ta, tb = signal.value(a), signal.value(b, left=True)  # linear over (a, b)
        h = b - a
        w[b] = w[a] + (ta + tb) * h / (2 * J)
        phi[b] = phi[a] + w[a] * h + (2 * ta + tb) * h * h / (6 * J)
    return np.array([w[x] for x in t]), np.array([phi[x] for x in t])


# -- the signal itself ---------------------------------------------------------------
def test_linear_table_values_jumps_and_kinks() -> None:
    s = Signal((0.0, 1.0, 2.0, 2.0, 3.0), (0.0, 2.0, 2.0, -1.0, 0.0), "linear")
    assert s.value(-1.0) == 0.0 and s.value(5.0) == 0.0  # end values held
    assert s.value(0.5) == 1.0
    assert s.value(2.0) == -1.0 and s.value(2.0, left=True) == 2.0  # a jump, as FMPy reads it
    assert s.value(2.5) == -0.5
    assert s.slope(0.25) == 2.0 and s.slope(1.5) == 0.0 and s.slope(2.0) == 1.0
    assert s.breakpoints() == [0.0, 1.0, 2.0, 3.0]
    assert s.breakpoints(0.5, 2.0) == [1.0, 2.0]
    assert s.jumps == [2.0]
    assert s.next_breakpoint(1.0) == 2.0 and s.next_breakpoint(3.0) is None
    # A time that misses the breakpoint by rounding is on it.
    assert s.value(2.0 - 1e-16) == -1.0 and s.next_breakpoint(2.0 - 1e-16) == 3.0


def test_hold_table_and_its_linear_equivalent() -> None:
    s = Signal((0.0, 1e-3, 2e-3), (0.0, 1.0, 1.0), "hold")
    assert s.value(0.9e-3) == 0.0 and s.value(1e-3) == 1.0 and s.value(1e-3, left=True) == 0.0
    assert s.breakpoints() == [1e-3] and s.jumps == [1e-3]
    assert s.as_linear_table() == ([0.0, 1e-3, 1e-3, 2e-3], [0.0, 0.0, 1.0, 1.0])


def test_input_signals_land_on_breakpoints() -> None:
    signals = InputSignals(
        {("a", "u"): Signal((0.3, 0.3), (0.0, 1.0)), ("b", "v"): Signal((0.1, 0.5), (0.0, 1.0))}
    )
    assert signals.next_breakpoint(0.0) == 0.1
    assert signals.land(0.0, 0.2) == 0.1
    assert signals.land(0.1, 0.2) == 0.2
    assert signals.land(0.2, 0.1 + 0.2) == 0.3  # 0.30000000000000004 is the breakpoint
    assert signals.clip(0.25, 1.0) == pytest.approx(0.05)
    assert signals.jump_at(0.1 + 0.2) and not signals.jump_at(0.1)
    assert not InputSignals({}).land(0.0, 0.2) != 0.2


# -- the scene forms, as users write them --------------------------------------------
def test_the_first_shape_users_write_loads_as_written(tmp_path: Path) -> None:
    text = scene_text('{ table = [["0 s", 0.0], ["1 ms", 1.0]], interpolation = "hold" }')
    scene = load_scene(write(tmp_path, text))
    signal = scene.fmus["a"].signals["tau"]
    assert signal.times == (0.0, pytest.approx(1e-3)) and signal.values == (0.0, 1.0)
    assert scene.fmus["a"].inputs["tau"] == 0.0  # the value at initialization
    assert ("a", "tau") in scene.record  # recorded like the outputs by default


def test_a_step_at_the_start_initializes_with_the_value_before_it(tmp_path: Path) -> None:
    scene = load_scene(write(tmp_path, scene_text('{ step = "0 s", from = 0.0, to = 3.0 }')))
    assert scene.fmus["a"].inputs["tau"] == 0.0
    result = run(tmp_path, scene.path)
    tau = result.signal("a.tau")
    assert tau[0] == 0.0 and np.all(tau[1:] == 3.0)  # from the first step on
    t = result.signal("time")
    np.testing.assert_allclose(result.signal("a.w"), 3.0 * t / J, rtol=1e-13)


@pytest.mark.parametrize("algorithm", MASTERS)
def test_hold_table_exact_at_breakpoints_under_every_master(tmp_path: Path, algorithm) -> None:
    """Jumps at 1.05 ms and 3.33 ms, off the 1 ms grid: every master ends a step on them,
    and the body's speed and angle there are the closed form's."""
    table = (
        '[["0 s", 0.0], ["1.05 ms", "1 N*m"], ["3.33 ms", 1.0], ["3.33 ms", -0.5], ["6 ms", 0.25]]'
    )
    path = write(tmp_path, scene_text(f'{{ table = {table}, interpolation = "hold" }}'))
    result = run(tmp_path, path, **{"master.algorithm": algorithm})
    scene = load_scene(path)
    signal = scene.fmus["a"].signals["tau"]
    t = result.signal("time")
    for jump in signal.jumps:
        assert np.any(t == jump), (algorithm, jump, t)  # a step boundary on the jump
    w, phi = motion(signal, t)
    np.testing.assert_allclose(result.signal("a.w"), w, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(result.signal("a.phi"), phi, rtol=1e-12, atol=1e-15)
    assert result.signal("a.w")[-1] == pytest.approx(
        (2.28e-3 * 1.0 - 0.5 * 2.67e-3 + 0.25 * 4e-3) / J, rel=1e-12
    )


@pytest.mark.parametrize("algorithm", MASTERS)
def test_ramp_kinks_are_landed_on_and_the_hold_is_first_order(tmp_path: Path, algorithm) -> None:
    """A ramp from 0.3 ms to 4.3 ms (off the grid) passed as the value at each step start:
    every master ends a step on both kinks, and the speed at the ramp's end is the closed
    form less slope / (2 J) * sum of the squared steps over the ramp (the zero-order hold's
    deficit, exactly); halving the step about halves it.  The regime-aware master keeps
    the held value's change per step within its tolerance (1e-3 of the peak torque): the
    deficit is then 1e-3 of the speed gained over the ramp."""
    path = write(tmp_path, scene_text('{ ramp = ["0.3 ms", "4.3 ms"], from = 0.0, to = "2 N*m" }'))
    slope, duration = 2.0 / 4e-3, 4e-3
    deficits = []
    for h in (0.5e-3, 0.25e-3):
        overrides = {"master.algorithm": algorithm, "master.step": h, "master.tolerance": 1e-3}
        result = run(tmp_path, path, **overrides)
        t = result.signal("time")
        w = result.signal("a.w")
        on = [
            int(np.flatnonzero(t == k)[0])
            for k in load_scene(path).fmus["a"].signals["tau"].breakpoints()
        ]
        first, end = on
        steps = np.diff(t[first : end + 1])
        exact = 0.5 * 2.0 * duration / J  # mean torque 1 N m over the ramp
        assert w[end] == pytest.approx(exact - slope / (2 * J) * np.sum(steps**2), rel=1e-12)
        deficits.append(exact - w[end])
        # After the ramp, the torque of 2 N m is held: exact from there on.
        assert w[-1] - w[end] == pytest.approx(2.0 * (10e-3 - t[end]) / J, rel=1e-12)
    if algorithm != "regime-aware":
        assert 1.8 < deficits[0] / deficits[1] < 2.0
    else:  # steps short enough that the held torque changes by at most 1e-3 of its peak
        assert max(deficits) <= 1e-3 * (2.0 * duration / (2 * J)) * (1 + 1e-9)
        assert max(deficits) > 0.9e-3 * (2.0 * duration / (2 * J))


def test_step_shorthand_and_csv_file(tmp_path: Path) -> None:
    (tmp_path / "torque.csv").write_text(
        "time [ms],tau [N*mm],other [rad]\n0,0,9\n2,500,9\n2,-250,9\n7.5,-250,9\n"
    )
    path = write(
        tmp_path, scene_text('{ file = "torque.csv", column = "tau", interpolation = "linear" }')
    )
    scene = load_scene(path)
    signal = scene.fmus["a"].signals["tau"]
    assert signal.times == pytest.approx((0.0, 2e-3, 2e-3, 7.5e-3))
    assert signal.values == pytest.approx((0.0, 0.5, -0.25, -0.25))
    assert signal.breakpoints() == pytest.approx([0.0, 2e-3])  # held after 2 ms: no kink
    result = run(tmp_path, path, **{"master.step": "0.25 ms"})
    t = result.signal("time")
    # Linear 0 -> 0.5 N m over 2 ms under a zero-order hold of 0.25 ms: the sum, exactly.
    k = int(np.flatnonzero(t == signal.jumps[0])[0])
    held = sum(0.5 * (j * 0.25e-3) / 2e-3 for j in range(8)) * 0.25e-3
    assert result.signal("a.w")[k] == pytest.approx(held / J, rel=1e-12)
    assert result.signal("a.w")[-1] == pytest.approx((held - 0.25 * 8e-3) / J, rel=1e-12)

    (tmp_path / "semicolons.csv").write_text("time [ms];tau [N*mm]\n0;0\n2;500\n")
    path = write(tmp_path, scene_text('{ file = "semicolons.csv" }'), "semi.toml")
    assert load_scene(path).fmus["a"].signals["tau"].values == (0.0, 0.5)

    step = write(tmp_path, scene_text('{ step = "2.5 ms", from = "1 N*m", to = 0.0 }'), "s.toml")
    result = run(tmp_path, step, **{"master.algorithm": "gauss-seidel"})
    assert 2.5e-3 in result.signal("time").tolist()
    assert result.signal("a.w")[-1] == pytest.approx(2.5e-3 / J, rel=1e-12)


def test_provenance_names_the_csv_file_and_its_hash(tmp_path: Path) -> None:
    import hashlib
    import json

    csv_text = "time [s],tau [N*m]\n0,1\n0.002,0\n"
    (tmp_path / "t.csv").write_text(csv_text)
    result = run(tmp_path, write(tmp_path, scene_text('{ file = "t.csv" }')))
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    entry = summary["metadata"]["signals"]["a.tau"]
    assert entry["sha256"] == hashlib.sha256(csv_text.encode()).hexdigest()
    assert entry["file"] == str(tmp_path / "t.csv") and entry["form"] == "file"
    assert result.metadata["signals"] == summary["metadata"]["signals"]
    # The torque the table applies does work the FMU does not report apart: no residual.
    assert "energy_residual" not in summary["headline"]
    assert any("input signals do work" in note for note in summary["notes"])


def test_the_step_height_is_a_sweep_key(tmp_path: Path) -> None:
    text = scene_text('{ step = "1 ms", from = 0.0, to = "1 N*m" }') + (
        '\n[sweep]\nparameter = "fmus.a.inputs.tau.to"\nvalues = ["1 N*m", "200 N*cm"]\n'
    )
    scene = load_scene(write(tmp_path, text))
    assert scene.sweep.si_values == (1.0, 2.0) and scene.sweep.unit == "N.m"
    swept = load_scene(scene.path, {"fmus.a.inputs.tau.to": "200 N*cm"})
    assert swept.fmus["a"].signals["tau"].values == (0.0, 2.0)
    assert swept.fmus["a"].signals["tau"].settings == {"from": 0.0, "to": 2.0, "step": 1e-3}


def test_the_step_height_is_a_study_input(tmp_path: Path) -> None:
    text = scene_text('{ step = "1 ms", from = 0.0, to = "1 N*m" }') + (
        '\n[report.headline]\nw_end = { signal = "a.w" }\n'
        '\n[study]\nsamples = 4\nquantities = ["w_end"]\n'
        '[[study.inputs]]\nkey = "fmus.a.inputs.tau.to"\nband = "±5 %"\n'
    )
    scene = load_scene(write(tmp_path, text))
    (spec,) = scene.study.inputs
    assert spec.keys == ("fmus.a.inputs.tau.to",) and spec.unit == "N.m"
    assert spec.support[0] == pytest.approx(0.95) and spec.support[1] == pytest.approx(1.05)


# -- refused at load, with the file, the key and the row -----------------------------
def expect_error(path: Path, key: str, *fragments: str, file: Path | None = None) -> None:
    with pytest.raises(ScenarioError) as info:
        load_scene(path)
    message = str(info.value)
    assert str(file or path) in message, message
    assert f"[{key}]" in message, message
    for fragment in fragments:
        assert fragment in message, message


BAD_TABLES = [
    ('{ table = [["0 s", 0.0], ["2 ms", 1.0], ["1 ms", 2.0]] }', "table[2]", "earlier"),
    (
        '{ table = [["0 s", 0.0], ["1 ms", 1.0], ["1 ms", 2.0], ["1 ms", 3.0]] }',
        "table[3]",
        "three",
    ),
    ('{ table = [["0 s", 0.0], ["1 ms", "2 rad"]] }', "table[1]", "cannot be converted to N.m"),
    ('{ table = [["0 N*m", 0.0]] }', "table[0]", "cannot be converted to s"),
    ('{ table = [["0 s", 0.0], ["1 ms"]] }', "table[1]", "expected a row [time, value]"),
    ("{ table = [] }", "table", "expected an array of rows"),
    ('{ table = [["0 s", 0.0]], interpolation = "cubic" }', "interpolation", "linear"),
    ('{ table = [["0 s", 0.0], ["5 ms", 1.0]], outside = "error" }', "outside", "goes past"),
    ('{ step = "1 ms", to = 1.0 }', "from", "missing"),
    ('{ ramp = ["2 ms", "1 ms"], from = 0.0, to = 1.0 }', "ramp", "later than"),
    ('{ step = "1 ms", from = 0.0, to = 1.0, file = "x.csv" }', "tau", "exactly one of"),
    (
        '{ step = "1 ms", from = 0.0, to = 1.0, interpolation = "hold" }',
        "interpolation",
        "unknown key",
    ),
]


@pytest.mark.parametrize(("entry", "key", "fragment"), BAD_TABLES)
def test_bad_tables_are_refused(tmp_path: Path, entry: str, key: str, fragment: str) -> None:
    full = "fmus.a.inputs.tau" if key == "tau" else f"fmus.a.inputs.tau.{key}"
    expect_error(write(tmp_path, scene_text(entry)), full, fragment)


BAD_FILES = [
    ("time [s],tau [N*m]\n0,0\n0.001,x\n", "line 3", "expected numbers"),
    ("time [s],tau\n0,0\n", "line 1", "has no unit"),
    ("t [s],tau [N*m]\n0,0\n", "line 1", "no 'time [unit]' column"),
    ("time [s],tau [rad]\n0,0\n", "line 1", "is not in N.m"),
    ("time [s],tau [N*m]\n0,0\n0.002,1\n0.001,2\n", "line 4", "earlier"),
    ("time [s],tau [N*m]\n0,0\n0.001,1,5\n", "line 3", "3 cells"),
    ("time [s],tau [N*m]\n", "", "no data rows"),
    ("time [s],tau [N*m]\n0,nan\n", "line 2", "finite"),
]


@pytest.mark.parametrize(("content", "row", "fragment"), BAD_FILES)
def test_bad_csv_files_are_refused(tmp_path: Path, content: str, row: str, fragment: str) -> None:
    csv_path = tmp_path / "torque.csv"
    csv_path.write_text(content)
    path = write(tmp_path, scene_text('{ file = "torque.csv" }'))
    expect_error(path, "fmus.a.inputs.tau.file", row, fragment, file=csv_path)


def test_missing_csv_file_and_column(tmp_path: Path) -> None:
    path = write(tmp_path, scene_text('{ file = "nowhere.csv" }'))
    expect_error(path, "fmus.a.inputs.tau.file", "no CSV file at", "nowhere.csv")
    (tmp_path / "two.csv").write_text("time [s],a [N*m],b [N*m]\n0,0,0\n")
    path = write(tmp_path, scene_text('{ file = "two.csv" }'))
    expect_error(path, "fmus.a.inputs.tau.column", "name the one to use")
    path = write(tmp_path, scene_text('{ file = "two.csv", column = "c" }'))
    expect_error(path, "fmus.a.inputs.tau.column", "no column 'c'")


def test_a_signal_driven_input_cannot_be_connected(tmp_path: Path) -> None:
    text = scene_text('{ step = "1 ms", from = 0.0, to = 1.0 }') + (
        '\n[fmus.b]\ncomponent = "SpringDamperInertia"\n'
        '\n[[connections]]\nports = ["a.flange", "b.coupling"]\n'
    )
    expect_error(write(tmp_path, text), "fmus.a.inputs.tau", "one driver")


def test_values_outside_the_inputs_range_are_refused_with_the_row(tmp_path: Path) -> None:
    var = VariableInfo("u", 1, "input", "continuous", "Real", "1", "0", 0.0, 1.0, "")

    def fail(key: str, message: str) -> ScenarioError:
        return ScenarioError(tmp_path / "scene.toml", key, message)

    def quantity(value, key, unit):
        return float(value)

    reader = Reader(tmp_path / "scene.toml", fail, quantity)
    with pytest.raises(ScenarioError, match=r"\[k.table\[2\]\] 1.5 is outside u's valid"):
        read_signal(reader, {"table": [[0, 0], [1, 1], [2, 1.5]]}, "k", var, (0.0, 1.0))
    csv_path = tmp_path / "u.csv"
    csv_path.write_text("time [s],u [1]\n0,0\n1,-0.5\n")
    with pytest.raises(ScenarioError, match=r"u.csv: \[k.file\] line 3: -0.5 is outside"):
        read_signal(reader, {"file": "u.csv"}, "k", var, (0.0, 1.0))
    integer = VariableInfo("n", 2, "input", "discrete", "Integer", None, "0", None, None, "")
    with pytest.raises(ScenarioError, match="drives a Real input"):
        read_signal(reader, {"step": 0.0, "from": 0, "to": 1}, "k", integer, (0.0, 1.0))


# -- export --------------------------------------------------------------------------
def test_osp_export_carries_a_held_signal_that_libcosim_runs_as_we_do(tmp_path: Path) -> None:
    """The jumps become libcosim scenario events; libcosim's fixed-step run of the exported
    system gives the speeds of our Jacobi run to round-off."""
    import json

    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimManipulator import CosimManipulator
    from libcosimpy.CosimObserver import CosimObserver

    from orchestrator.osp_export import SCENARIO_FILE, export_osp

    table = '[["0 s", 0.0], ["2 ms", 0.0], ["2 ms", "1 N*m"], ["6 ms", "1 N*m"], ["6 ms", -0.5]]'
    path = write(tmp_path, scene_text(f'{{ table = {table}, interpolation = "hold" }}'))
    ours = run(tmp_path, path)
    xml = export_osp(load_scene(path), tmp_path / "osp")
    scenario = json.loads((xml.parent / SCENARIO_FILE).read_text())
    assert [(e["time"], e["value"]) for e in scenario["events"]] == [(0.002, 1.0), (0.006, -0.5)]

    log_output_level(CosimLogLevel.ERROR)
    execution = CosimExecution.from_osp_config_file(str(xml))
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    manager = CosimManipulator.create_scenario_manager()
    assert execution.add_manipulator(manager)
    assert execution.load_scenario(manager, str(xml.parent / SCENARIO_FILE))
    (slave,) = execution.slave_infos()
    ref = {v.name.decode(): v.reference for v in execution.slave_variables(slave.index)}["w"]
    theirs = []
    for _ in range(10):
        assert execution.step(1)
        theirs.append(observer.last_real_values(slave.index, [ref])[0])
    np.testing.assert_allclose(theirs, ours.signal("a.w")[1:], rtol=1e-12, atol=1e-12)


def test_exports_refuse_what_they_cannot_carry(tmp_path: Path) -> None:
    from orchestrator.osp_export import export_osp
    from orchestrator.ssp_export import export_ssp

    path = write(tmp_path, scene_text('{ ramp = ["0 s", "1 ms"], from = 0.0, to = 1.0 }'))
    with pytest.raises(ScenarioError, match=r"\[fmus.a.inputs.tau\] a signal with a slope"):
        export_osp(load_scene(path), tmp_path / "osp")
    with pytest.raises(ScenarioError, match=r"\[fmus.a.inputs.tau\] a signal drives it: SSP"):
        export_ssp(load_scene(path), tmp_path / "x.ssp")
    path = write(tmp_path, scene_text('{ step = "1.5 ms", from = 0.0, to = 1.0 }'))
    with pytest.raises(ScenarioError, match=r"1.5 ms|0.0015 s is not on libcosim's base step"):
        export_osp(load_scene(path), tmp_path / "osp")


def test_fmpy_input_file_without_units_takes_the_declared_units(tmp_path: Path) -> None:
    """FMPy's own input CSV (``time,tau``, no units): time in s, tau in the input's
    declared unit (N.m), with a note; the same signal as the file with units."""

    (tmp_path / "fmpy.csv").write_text("time,tau\n0,0\n0.001,0.002\n")
    (tmp_path / "units.csv").write_text("time [ms],tau [N*m]\n0,0\n1,0.002\n")
    signals = {}
    for name in ("fmpy", "units"):
        scene = tmp_path / f"{name}.toml"
        scene.write_text(_FILE_SCENE.format(name=name, file=f"{name}.csv"))
        loaded = load_scene(scene)
        signals[name] = loaded.fmus["a"].signals["tau"]
    assert signals["fmpy"].times == signals["units"].times == (0.0, 0.001)
    assert signals["fmpy"].values == signals["units"].values == (0.0, 0.002)
    result = run_file(tmp_path / "fmpy.toml", tmp_path / "out", reference=False)
    note = (
        "signal a.tau: a header without units (FMPy's input format): time in s, values in "
        "the input's declared unit N.m"
    )
    assert note in result.notes


def test_a_header_mixing_units_and_none_is_still_refused(tmp_path: Path) -> None:
    (tmp_path / "mixed.csv").write_text("time [s],tau\n0,0\n")
    scene = tmp_path / "mixed.toml"
    scene.write_text(_FILE_SCENE.format(name="mixed", file="mixed.csv"))
    with pytest.raises(ScenarioError) as err:
        load_scene(scene)
    assert "line 1: column 'tau' has no unit; expected 'name [unit]'" in str(err.value)


_FILE_SCENE = """
[scene]
name = "{name}"
stop = "2 ms"

[fmus.a]
component = "Inertia"
parameters = {{ J = "1e-4 kg*m^2" }}
inputs = {{ tau = {{ file = "{file}" }} }}

[master]
algorithm = "jacobi"
step = "0.5 ms"
"""
