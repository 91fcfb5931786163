"""Our FMUs take FMI 2.0 input derivatives through their loader (fmus/loader/python_loader.c).

The brake load slipping under a torque that ramps, T(t) = T0 + dT t, has a closed form:
its speed is v0 + ((T0 - T_b) t + dT t^2 / 2) / j.  Set through fmi2SetRealInputDerivatives
(the torque as at each step start, its derivative) or through the rate_of input (the
torque at mid-step and its rate), the FMU gives the same steps up to the rounding of
T + dT h/2."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave

from fmus.build import build_fmu
from fmus.host_loader import loader_plan
from fmus.input_derivatives import RAMPS_FILE
from orchestrator import capabilities
from orchestrator.masters.midpoint_trial import MidpointTrials
from orchestrator.model_info import model_info
from orchestrator.run import run_scene
from orchestrator.scenario import load_scene

pytestmark = pytest.mark.skipif(
    not loader_plan().packs_loader, reason="no loader here: " + loader_plan().why_not
)

PROJECT = Path(__file__).resolve().parents[2]
J, T_B, V0, T0, DT, H, STEPS = 0.05, 18.0, 5.0, 20.0, 3000.0, 1e-3, 20


class Brake:
    """A BrakeLoad instance driven through FMPy."""

    def __init__(self, fmu, name: str) -> None:
        md = read_model_description(fmu)
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.slave = FMU2Slave(
            guid=md.guid,
            unzipDirectory=extract(fmu),
            modelIdentifier=md.coSimulation.modelIdentifier,
            instanceName=name,
        )
        self.slave.instantiate()
        self.slave.setupExperiment(startTime=0.0)
        self.slave.enterInitializationMode()
        self.set(j=J, brake_torque=T_B, speed0=V0, torque=T0)
        self.slave.exitInitializationMode()
        self.t = 0.0

    def set(self, **values: float) -> None:
        self.slave.setReal([self.vr[n] for n in values], list(values.values()))

    def get(self, *names: str) -> list[float]:
        return self.slave.getReal([self.vr[n] for n in names])

    def derivative(self, name: str, value: float, order: int = 1) -> None:
        self.slave.setRealInputDerivatives([self.vr[name]], [order], [value])

    def step(self) -> None:
        self.slave.doStep(self.t, H)
        self.t += H

    def close(self) -> None:
        self.slave.terminate()
        self.slave.freeInstance()


@pytest.fixture(scope="module")
def fmu():
    return build_fmu("BrakeLoad")


def test_only_components_that_ramp_every_held_input_declare_it(fmu) -> None:
    info = model_info(fmu)
    assert info.can_interpolate_inputs and info.role_of("torque_rate").of == "torque"
    assert not model_info(build_fmu("Inertia")).can_interpolate_inputs
    assert not model_info(build_fmu("ClockGearTrain")).can_interpolate_inputs  # J_esc


def test_the_standard_call_and_the_rate_input_give_the_same_steps(fmu) -> None:
    by_rate, by_derivative = Brake(fmu, "by_rate"), Brake(fmu, "by_derivative")
    once = Brake(fmu, "once")  # its torque set at the start only: the ramp goes on
    by_derivative.derivative("torque", DT)  # in force over every following step
    once.derivative("torque", DT)
    worst = 0.0
    for n in range(STEPS):
        t0 = n * H
        by_rate.set(torque=T0 + DT * (t0 + 0.5 * H), torque_rate=DT)
        by_derivative.set(torque=T0 + DT * t0)
        by_rate.step()
        by_derivative.step()
        once.step()
        (a, va), (b, vb) = by_rate.get("angle", "speed"), by_derivative.get("angle", "speed")
        worst = max(worst, abs(a - b) / abs(a), abs(va - vb) / abs(va))
        # The input reads as at the step end, and what depends on it directly is computed
        # with that value.
        torque, breakaway = by_derivative.get("torque", "breakaway")
        assert torque == (T0 + DT * t0) + DT * H and breakaway == abs(torque) - T_B
        t = t0 + H
        exact = V0 + ((T0 - T_B) * t + 0.5 * DT * t * t) / J
        assert once.get("speed")[0] == pytest.approx(exact, rel=1e-13)
    t = STEPS * H
    exact = V0 + ((T0 - T_B) * t + 0.5 * DT * t * t) / J
    assert by_derivative.get("speed")[0] == pytest.approx(exact, rel=1e-13)
    # T0 + dT t0 + dT h/2 against T0 + dT (t0 + h/2): one rounding of the torque at most
    # (measured: 0, the two round alike at every step here).
    assert worst < 1e-14
    by_rate.close()
    by_derivative.close()
    once.close()


def test_a_saved_state_holds_the_derivative_and_a_reset_forgets_it(fmu) -> None:
    brake = Brake(fmu, "state")
    brake.derivative("torque", DT)
    state = brake.slave.getFMUstate()
    brake.derivative("torque", -DT)
    brake.slave.setFMUstate(state)
    brake.step()
    ramped = brake.get("speed")[0]
    assert ramped == pytest.approx(V0 + ((T0 - T_B) * H + 0.5 * DT * H * H) / J, rel=1e-14)
    brake.slave.freeFMUstate(state)
    brake.close()
    held = Brake(fmu, "reset")
    held.derivative("torque", DT)
    held.slave.reset()
    held.slave.setupExperiment(startTime=0.0)
    held.slave.enterInitializationMode()
    held.set(j=J, brake_torque=T_B, speed0=V0, torque=T0)
    held.slave.exitInitializationMode()
    held.step()
    assert held.get("speed")[0] == V0 + (T0 - T_B) / J * H
    held.close()


def test_derivatives_it_cannot_take(fmu, capfd) -> None:
    brake = Brake(fmu, "accepted")
    brake.derivative("torque_rate", 1.0)  # accepted, not used: it ramps to first order
    brake.derivative("torque", 5.0, order=2)
    brake.step()
    assert brake.get("speed")[0] == V0 + (T0 - T_B) / J * H  # held: no first derivative
    brake.close()
    for name, order, said in (
        ("speed", 1, "value reference {vr} is no input this FMU ramps through a step"),
        ("torque", 0, "order 0 of value reference {vr}; the order of a derivative is 1 or more"),
    ):
        refused = Brake(fmu, "refused")
        with pytest.raises(FMICallException):
            refused.derivative(name, 1.0, order)
        refused.slave.freeInstance()
        out = capfd.readouterr()
        assert said.format(vr=refused.vr[name]) in out.out + out.err


def test_the_table_names_the_input_and_its_rate(fmu) -> None:
    import zipfile

    info = model_info(fmu)
    table = zipfile.ZipFile(fmu).read(RAMPS_FILE).decode().splitlines()
    vr = {n: v.value_reference for n, v in info.variables.items()}
    assert table[1:] == [f"{vr['torque']} {vr['torque_rate']}"]


def _press_feed(directory, monkeypatch=None):
    """Press feed Run 2 over its first crank revolution (0.2 s: every kind of switch)."""
    scene = load_scene(PROJECT / "scenarios" / "press_feed_run2.toml", {"scene.stop": "0.2 s"})
    r = run_scene(scene, output_dir=directory, show_progress=False, plots=False)
    assert r.status == "completed", r.message
    return r, (directory / "events.csv").read_text().splitlines()[1:]


@pytest.mark.slow
def test_the_press_feed_through_the_standard_call(tmp_path, monkeypatch) -> None:
    """The midpoint hold ramping the drive's and the brake's torque through
    fmi2SetRealInputDerivatives (the torque at the step start and its slope) rather than
    through their rate_of inputs (the torque's mean and its rate)."""
    held, held_events = _press_feed(tmp_path / "rate_of")
    monkeypatch.setattr(
        capabilities,
        "takes_input_derivative",
        lambda model, name: model.can_interpolate_inputs and model.role_of(name) is None,
    )
    monkeypatch.setattr(MidpointTrials, "_rate_input", lambda self, j, name: None)
    ramped, ramped_events = _press_feed(tmp_path / "standard")
    assert ramped.stats.do_steps > 0 and held.stats.do_steps > 0
    # The same switches, in the same order, at the same times up to the rounding of the
    # mean: measured over the whole run (0.6 s), 1.3e-12 s and 3.5e-14 of the feed length.
    assert [e.split(",")[1:] for e in ramped_events] == [e.split(",")[1:] for e in held_events]
    for a, b in zip(ramped_events, held_events, strict=True):
        assert float(a.split(",")[0]) == pytest.approx(float(b.split(",")[0]), abs=1e-10)
    scale = np.abs(held.signal("load.feed_length")).max()
    end = abs(ramped.signal("load.feed_length")[-1] - held.signal("load.feed_length")[-1])
    assert end < 1e-10 * scale


def test_an_fmu_that_does_not_interpolate_refuses_derivatives(capfd) -> None:
    fmu = build_fmu("Inertia")
    md = read_model_description(fmu)
    tau = next(v.valueReference for v in md.modelVariables if v.name == "tau")
    slave = FMU2Slave(
        guid=md.guid,
        unzipDirectory=extract(fmu),
        modelIdentifier=md.coSimulation.modelIdentifier,
        instanceName="inertia",
    )
    slave.instantiate()
    with pytest.raises(FMICallException):
        slave.setRealInputDerivatives([tau], [1], [1.0])
    slave.freeInstance()
    out = capfd.readouterr()
    said = "this FMU does not interpolate its inputs (canInterpolateInputs is false)"
    assert said in out.out + out.err
