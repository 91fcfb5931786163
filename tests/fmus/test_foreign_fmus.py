"""FMUs not built by this project: a hand-written C FMU and FMPy's container FMU around it."""

from __future__ import annotations

import math
import uuid
from pathlib import Path

import foreign_fmus
import numpy as np
import pytest
from fmpy import extract, read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu
from foreign_fmus import ForeignFmus, torsion_body_reference

from fmus.build import build_fmu

if foreign_fmus.c_compiler() is None:
    pytest.skip("no C compiler to build the foreign test FMUs", allow_module_level=True)

STEP = 1e-3
# Inertia A driving TorsionBody; stiff enough that the coupling matters within 100 steps.
PARAMS = dict(J_a=2e-4, phi0_a=0.1, w0_a=10.0, J=1e-4, k=2.0, d=2e-3, phi0=0.05, w0=-3.0)
N_SUB = 10


class Slave:
    """An instantiated FMU2Slave addressed by variable name."""

    def __init__(self, fmu: Path, name: str, guid: str | None = None) -> None:
        md = read_model_description(fmu)
        self.md = md
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.fmu = FMU2Slave(
            guid=guid or md.guid,
            unzipDirectory=extract(fmu),
            modelIdentifier=md.coSimulation.modelIdentifier,
            instanceName=name,
        )
        self.fmu.instantiate()

    def start(
        self, reals: dict[str, float] | None = None, ints: dict[str, int] | None = None
    ) -> Slave:
        self.fmu.setupExperiment(startTime=0.0)
        self.fmu.enterInitializationMode()
        self.set(reals or {})
        if ints:
            self.fmu.setInteger([self.vr[n] for n in ints], list(ints.values()))
        return self

    def set(self, values: dict[str, float]) -> None:
        if values:
            self.fmu.setReal([self.vr[n] for n in values], list(values.values()))

    def get(self, *names: str) -> list[float]:
        return self.fmu.getReal([self.vr[n] for n in names])

    def close(self) -> None:
        self.fmu.terminate()
        self.fmu.freeInstance()


def relative_error(actual: np.ndarray, expected: np.ndarray) -> float:
    """Largest deviation relative to the signal's own scale (zero crossings are harmless)."""
    return float(np.max(np.abs(actual - expected)) / np.max(np.abs(expected)))


def test_foreign_fmus_validate(foreign: ForeignFmus) -> None:
    for fmu in (foreign.torsion_body, foreign.stateless, foreign.container):
        assert validate_fmu(str(fmu)) == [], fmu.name
    body = read_model_description(foreign.torsion_body)
    stateless = read_model_description(foreign.stateless)
    container = read_model_description(foreign.container)
    assert body.coSimulation.modelIdentifier == "TorsionBody"
    assert body.variableNamingConvention == "structured"
    assert body.coSimulation.canGetAndSetFMUstate
    assert not stateless.coSimulation.canGetAndSetFMUstate
    assert not container.coSimulation.canGetAndSetFMUstate
    assert body.guid != stateless.guid  # every build has its own GUID
    units = {v.name: v.unit for v in body.modelVariables}
    assert units["spring.d"] == "N.m.s/rad" and units["flange.tau"] == "N.m"
    tau = next(u for u in body.outputs if u.variable.name == "flange.tau")
    assert {v.name for v in tau.dependencies} == {"flange.phi", "flange.w"}
    assert all(u.dependencies == [] for u in body.outputs if u.variable.name != "flange.tau")
    # The container can stand where the TorsionBody stands: same names, units, causalities.
    inner = {v.name: (v.causality, v.unit, v.type) for v in body.modelVariables}
    outer = {v.name: (v.causality, v.unit, v.type) for v in container.modelVariables}
    assert outer.pop("time") == ("independent", "s", "Real")
    assert outer == inner


def test_torsion_body_alone_matches_rk4_and_closed_form(foreign: ForeignFmus) -> None:
    J, k, d = 1e-4, 2.0, 2e-3
    phi_in0, w_in, phi0, w0 = 0.3, 2.0, -0.1, 1.0
    stop = 0.2
    result = simulate_fmu(
        str(foreign.torsion_body),
        stop_time=stop,
        output_interval=STEP,
        start_values={
            "body.J": J,
            "spring.k": k,
            "spring.d": d,
            "body.phi0": phi0,
            "body.w0": w0,
            "flange.phi": phi_in0,
            "flange.w": w_in,
            "n_sub": N_SUB,
        },
        output=["body.phi", "body.w", "flange.tau", "flange.phi"],
    )
    t = result["time"]
    assert len(t) == round(stop / STEP) + 1 and t[0] == 0.0
    # Nothing resets the input, so the flange keeps moving at w_in from phi_in0.
    assert np.allclose(result["flange.phi"], phi_in0 + w_in * t, rtol=0, atol=1e-14)

    # By hand: RK4 on x' = A x is x <- P(A hs) x with P the 4th-order Taylor polynomial.
    a_mat = np.array([[0.0, 1.0], [-k / J, -d / J]])
    z = a_mat * (STEP / N_SUB)
    p = np.eye(2) + z + z @ z / 2 + z @ z @ z / 6 + z @ z @ z @ z / 24
    step_map = np.linalg.matrix_power(p, N_SUB)
    x = np.empty((len(t), 2))
    x[0] = (phi0 - phi_in0, w0 - w_in)
    for i in range(1, len(t)):
        x[i] = step_map @ x[i - 1]
    y, v = x[:, 0], x[:, 1]
    assert relative_error(result["body.phi"] - (phi_in0 + w_in * t), y) < 1e-13
    assert relative_error(result["body.w"], w_in + v) < 1e-13
    assert relative_error(result["flange.tau"], k * y + d * v) < 1e-13

    # Closed form of the damped oscillator: RK4 at omega*hs = 0.014 is good to ~2e-9.
    alpha = d / (2 * J)
    omega_d = math.sqrt(k / J - alpha**2)
    y0, v0 = x[0]
    decay, c, s = np.exp(-alpha * t), np.cos(omega_d * t), np.sin(omega_d * t)
    y_exact = decay * (y0 * c + (v0 + alpha * y0) / omega_d * s)
    v_exact = decay * (v0 * c - (alpha * v0 + k / J * y0) / omega_d * s)
    assert relative_error(y, y_exact) < 1e-8
    assert relative_error(v, v_exact) < 1e-8
    assert relative_error(result["flange.tau"], k * y_exact + d * v_exact) < 1e-8


def jacobi_run(inertia_fmu: Path, body_fmu: Path, stop: float) -> dict[str, np.ndarray]:
    """Fixed-step Jacobi co-simulation driven through FMPy's low-level FMI 2.0 API."""
    p = PARAMS
    a = Slave(inertia_fmu, "inertia").start({"J": p["J_a"], "phi0": p["phi0_a"], "w0": p["w0_a"]})
    b = Slave(body_fmu, "torsion_body").start(
        {
            "body.J": p["J"],
            "spring.k": p["k"],
            "spring.d": p["d"],
            "body.phi0": p["phi0"],
            "body.w0": p["w0"],
        },
        {"n_sub": N_SUB},
    )
    # consistent start: the flange inputs take A's initial motion
    phi_a, w_a = a.get("phi", "w")
    b.set({"flange.phi": phi_a, "flange.w": w_a})
    a.fmu.exitInitializationMode()
    b.fmu.exitInitializationMode()

    n = round(stop / STEP)
    rows = []
    for i in range(n + 1):
        t = i * STEP
        phi_a, w_a = a.get("phi", "w")
        phi, w, tau = b.get("body.phi", "body.w", "flange.tau")
        rows.append((t, phi_a, w_a, phi, w, tau))
        if i == n:
            break
        # Jacobi: every output was read above, before any input is set
        a.set({"tau": tau})
        b.set({"flange.phi": phi_a, "flange.w": w_a})
        a.fmu.doStep(t, STEP)
        b.fmu.doStep(t, STEP)
    a.close()
    b.close()
    table = np.array(rows)
    return {key: table[:, j] for j, key in enumerate(("t", "phi_a", "w_a", "phi", "w", "tau"))}


@pytest.mark.parametrize("which", ["torsion_body", "container"])
def test_jacobi_with_inertia_matches_reference(
    foreign: ForeignFmus, fmu_cache: Path, which: str
) -> None:
    stop = 0.1
    inertia = build_fmu("Inertia", fmu_cache)
    run = jacobi_run(inertia, getattr(foreign, which), stop)
    ref = torsion_body_reference(**PARAMS, n_sub=N_SUB, step=STEP, stop=stop)
    assert np.array_equal(run["t"], ref["t"])
    for key in ("phi_a", "w_a", "phi", "w", "tau"):
        assert relative_error(run[key], ref[key]) < 1e-12, key
    # a real exchange took place: A was decelerated and B dragged along
    assert ref["w_a"][-1] < PARAMS["w0_a"] and ref["phi"][-1] > PARAMS["phi0"]


@pytest.mark.parametrize("which", ["torsion_body", "stateless", "container"])
def test_invalid_steps_are_errors(foreign: ForeignFmus, which: str, capfd) -> None:
    slave = Slave(getattr(foreign, which), "bad_steps").start()
    slave.fmu.exitInitializationMode()
    for h in (0.0, -1.0, math.nan, math.inf):
        with pytest.raises(FMICallException):
            slave.fmu.doStep(0.0, h)
    with pytest.raises(FMICallException):
        slave.fmu.doStep(math.nan, STEP)
    slave.fmu.doStep(0.0, STEP)  # the rejected calls left the instance usable
    slave.close()
    if which != "container":
        assert "communicationStepSize must be finite and > 0" in capfd.readouterr().out


def test_state_round_trip_and_stateless_variant(foreign: ForeignFmus) -> None:
    inputs = {"flange.phi": 0.2, "flange.w": 1.5}
    slave = Slave(foreign.torsion_body, "stateful").start({"body.w0": 2.0})
    slave.fmu.exitInitializationMode()
    slave.set(inputs)
    slave.fmu.doStep(0.0, STEP)
    state = slave.fmu.getFMUstate()
    first = [slave.get("body.phi", "body.w", "flange.tau")]
    for i in range(1, 4):
        slave.fmu.doStep(i * STEP, STEP)
        first.append(slave.get("body.phi", "body.w", "flange.tau"))
    slave.fmu.setFMUstate(state)
    again = [slave.get("body.phi", "body.w", "flange.tau")]
    for i in range(1, 4):
        slave.fmu.doStep(i * STEP, STEP)
        again.append(slave.get("body.phi", "body.w", "flange.tau"))
    slave.fmu.freeFMUstate(state)
    slave.close()
    assert again == first

    for fmu in (foreign.stateless, foreign.container):
        slave = Slave(fmu, "stateless").start()
        slave.fmu.exitInitializationMode()
        with pytest.raises(FMICallException):
            slave.fmu.getFMUstate()
        slave.close()


def test_container_steps_in_multiples_of_its_fixed_step(foreign: ForeignFmus) -> None:
    start = {"body.w0": 2.0, "flange.phi": 0.2, "flange.w": 1.5}
    direct = Slave(foreign.torsion_body, "direct").start(start)
    direct.fmu.exitInitializationMode()
    direct.fmu.doStep(0.0, STEP)
    direct.fmu.doStep(STEP, STEP)
    container = Slave(foreign.container, "container").start(start)
    container.fmu.exitInitializationMode()
    with pytest.raises(FMICallException):
        container.fmu.doStep(0.0, 1.5 * STEP)
    container.fmu.doStep(0.0, 2 * STEP)  # two internal steps of STEP, bit for bit
    names = ("body.phi", "body.w", "flange.tau", "flange.phi")
    assert container.get(*names) == direct.get(*names)
    assert container.get("time") == [2 * STEP]
    # direct feedthrough through the container, no step needed
    container.set({"flange.w": 0.0})
    direct.set({"flange.w": 0.0})
    assert container.get("flange.tau") == direct.get("flange.tau")
    direct.close()
    container.close()


def test_torsion_body_guards(foreign: ForeignFmus) -> None:
    with pytest.raises(Exception, match="instantiate"):
        Slave(foreign.torsion_body, "wrong_guid", guid="{" + str(uuid.uuid4()) + "}")
    slave = Slave(foreign.torsion_body, "guards").start({"body.J": -1.0})
    with pytest.raises(FMICallException):  # J <= 0 is refused when initialization ends
        slave.fmu.exitInitializationMode()
    slave.fmu.freeInstance()
    slave = Slave(foreign.torsion_body, "fixed").start()
    slave.fmu.exitInitializationMode()
    with pytest.raises(FMICallException):  # fixed parameters stay fixed
        slave.set({"spring.k": 3.0})
    slave.close()
