"""Monolithic model of the clock-train S&A (Lowen & Tepper 1982; clock train kinematics of the
US Army fuze report of about 1980, Task 2): the M739 verge regime machine with the live
clock-train physics (``components.clock_gear_train.ClockTrainPhysics``) in place of a held
affine response, one ODE with every event located, as ``orchestrator.scenes.m739.monolithic``
does for the involute train; a tooth handover is an inelastic impact of the new pair."""

from __future__ import annotations

from collections.abc import Mapping

from components.clock_gear_train import LOSS_POINT, ClockTrainPhysics
from components.clock_train_design import body_data, clock_train, design_defaults
from components.kernels import load_kernel
from components.m739_data import M739, M739Data, rpm_to_rad_s
from components.verge_escapement import (
    IND_MESH_HI,
    IND_MESH_LO,
    StepBudgetSpent,
    VergeConstants,
    escapement_data,
)
from components.verge_geometry import kinem
from orchestrator.scenes.m739.monolithic import (
    REFERENCE_TOLERANCE,
    M739Result,
    VergeTrainMonolithic,
    simulate,
)

#: Rotor angle at arming: the M739's rotor travel, PHICUTD of escape wheel times N31 (= 1/32).
ARMING_ROTOR_ANGLE = M739.phi1c + M739.n31 * M739.phi_cut


class _ClockMonolithic(VergeTrainMonolithic):
    """The M739 monolithic verge with the live clock-train physics.

    A tooth handover of the train is an inelastic impact of the new pair: its speed map takes
    the verge inertia along while the verge rides on the wheel (I_p U^2), exactly.
    """

    def event(self, y: list[float], index: int, t: float) -> list[float]:
        tr = self.train
        if index not in (IND_MESH_HI, IND_MESH_LO):
            return super().event(y, index, t)
        j_load = 0.0
        if self.coupled:
            k = self.k
            u = kinem(y[0] + self.phi_off, self.alpha, k.a, k.b, k.c)[2]
            j_load = k.ip * u * u
        w, _ = tr.cross(y[0], y[1], j_load)
        y = [y[0], w, y[2], y[3], y[4]]
        if self.coupled:
            y = self._sync_kinematics(y)
        self.record(y)
        return y


_KERNEL = load_kernel("clock_train_kernel")
if _KERNEL is not None:  # its integration between events runs compiled (components.kernels)
    _M739_KERNEL = load_kernel("m739_kernel")  # whose Sampler ``simulate`` observes with
    _KERNEL.use_classes(
        monolithic=_ClockMonolithic,
        verge_budget_spent=StepBudgetSpent,
        sampler=None if _M739_KERNEL is None else _M739_KERNEL.Sampler,
    )


def arming_phi(phys: ClockTrainPhysics, rotor_angle: float = ARMING_ROTOR_ANGLE) -> float:
    """Cumulative escape-wheel angle at which the rotor reaches rotor_angle (forward kinematics
    of the train, eqs. 1-87 of the clock train report)."""
    theta1 = phys.theta1_0 + (rotor_angle - phys.phi1c)
    return phys.train.escape_angle(theta1) - phys.psi0


def run_clock_train(
    mu: float = M739.mu,
    mu1: float = M739.mu1,
    rpm: float = M739.rpm,
    e_rest: float = M739.e_rest,
    t_stop: float = 0.2,
    loss_model: int = LOSS_POINT,
    pivot_loads: bool = True,
    mesh_phase: float = 0.0,
    center_distance: float = M739.a,
    pallet_inertia: float = M739.ip,
    rotor_arming_angle: float = ARMING_ROTOR_ANGLE,
    tolerance: float = REFERENCE_TOLERANCE,
    sample_dt: float = 1.0e-5,
    design: Mapping[str, float] | None = None,
    verge_data: M739Data | None = None,
) -> M739Result:
    """Simulate the clock-train S&A from rest on the entrance face until arming or t_stop.

    ``design``: the clock train's design parameters (``components.clock_train_design``; the
    missing ones at their defaults), as ClockGearTrain takes them; ``verge_data``: the verge's
    deck (default: the M739's with ``center_distance`` and ``pallet_inertia``).  Same outcome
    record as ``run_m739`` (turns, force maxima with F12/F23 the mesh normal forces, impacts,
    regime log, series); it never raises.
    """
    omega = rpm_to_rad_s(rpm)
    if verge_data is None:
        data = escapement_data(center_distance, pallet_inertia=pallet_inertia)
    else:
        data = verge_data
    values = {**design_defaults(), **(design or {})}
    events: list[tuple[float, int, int, str]] = []

    def log(t: float, old: int, new: int, why: str) -> None:
        events.append((t, old, new, why))

    train = ClockTrainPhysics(
        clock_train(values),
        body_data(values),
        mu=mu,
        omega=omega,
        loss_model=loss_model,
        pivot_loads=pivot_loads,
        mesh_phase=mesh_phase,
    )
    phi_stop = arming_phi(train, rotor_arming_angle)
    k = VergeConstants(data, mu1, mu, omega, e_rest)
    core = _ClockMonolithic(k, train, data.phi_start, phi_stop=phi_stop, log=log)
    result = simulate(core, data, events, t_stop, tolerance, sample_dt)
    result.handovers = train.handovers  # type: ignore[attr-defined]
    return result
