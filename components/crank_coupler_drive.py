"""Crank drive, RSSR linkage and elastic bent coupler: the rocker (outer race) motion.

Physics of Xu (1993), *Contributions to the Theory of Machine Dynamics*, Part I §4-5 and App. B
(pp. 15-23, 142-149): the crank turns at constant speed; the coupler's first bending
mode q (inverted-cantilever space function, eqs 3-9) is the only elastic DOF and moves the
rocker by ``phi4e = phi4r(phi1) + F2(phi1) q`` (14).  Eq. (B.15) with P2, P3 dropped:

    M' q'' + c q' + K_e q = rhoA F1 + F2 (T - J_o4 phi4e'')

with ``M' = rhoA[(V2s1 + V2s2 + sin^2 2a) L + P1]`` (19) and T >= 0 the torque the clutch
transmits (it acts on the rocker in the thesis +phi4 sense, i.e. against the feed stroke).
Substituting ``phi4e'' = a_r + F2 q''`` moves J_o4 F2^2 into the mass, as in (19).

Ports are forward-positive: ``theta4 = phi4_max - phi4e`` grows on the feed stroke.
Energy: the crank delivers ``P_in = rhoA F1 q' + (J_o4 phi4e'' - T) v_r`` where
``v_r = phi1dot (phi4r' + F2' q)``; then dE/dt + c q'^2 = P_in - T theta4' with
``E = M'q'^2/2 + K_e q^2/2 + J_o4 phi4e'^2/2``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from .base import (
    COMMON_OUTPUTS,
    Component,
    ComponentError,
    SnapshotPlan,
    Variable,
    design_parameter,
    rate_input,
)
from .coupler_inertia import computed_inertia
from .design_rules import raise_first
from .event_integration import (
    advance,
    integration_step_control,
    integration_variables,
    use_compiled_loop,
)
from .kernels import load_kernel
from .press_feed_data import (
    APP_H_FOURIER,
    COUPLER_STANDARD,
    J_O4,
    LINKAGE_TABLE1,
    BentCoupler,
    RSSRLinkage,
)
from .press_feed_rules import drive_violations
from .rssr_kinematics import ExactRSSR, FourierRocker, rocker_extremes
from .units import RPM

REGIME_RETURN = 0  # rocker moving back (theta4 decreasing)
REGIME_FORWARD = 1  # rocker on the feed stroke (theta4 increasing)
REGIME_NAMES = {REGIME_RETURN: "return", REGIME_FORWARD: "forward"}

#: Magnitudes below which the integration controls the state [phi1, q, q', W_in, W_diss]
#: absolutely: rad, m, m/s, J, J (Run 1 peaks: q 0.8 mm, q' 0.4 m/s, 24 J in 0.9 s).
STATE_SCALES = (1.0, 1.0e-3, 0.5, 1.0, 1.0e-2)


# -- coupler properties (Part I §4, Table 1) ----------------------------------------------
def tube_section(c: BentCoupler) -> tuple[float, float]:
    """(area, second moment of area) of the tubular coupler."""
    area = math.pi / 4.0 * (c.d_outer**2 - c.d_inner**2)
    inertia = math.pi / 64.0 * (c.d_outer**4 - c.d_inner**4)
    return area, inertia


def coupler_stiffness(c: BentCoupler) -> float:
    """K_e = (pi/2)^4 EI / L^3 from the strain energy (B.4) [N/m]."""
    return (math.pi / 2.0) ** 4 * c.youngs * tube_section(c)[1] / c.length**3


def coupler_rho_a(c: BentCoupler) -> float:
    """Mass per length; App. G (G.9) adds rho_M = f M / A for a mass clamped at B.

    The printed f = 0.05 is per inch: about 1/[(V2s1 + V2s2 + sin^2 2a) L + P1] = 1/20.3 in
    (components.coupler_inertia computes it from the geometry).
    """
    area = tube_section(c)[0]
    return c.density * area + c.lumped_factor * c.lumped_mass


def coupler_modal_mass(c: BentCoupler) -> float:
    """M' = rhoA[(V2s1 + V2s2 + sin^2 2a) L + P1] (19), without the rocker term J_o4 F2^2."""
    c2a = math.cos(2.0 * c.alpha)
    v2s2 = c2a**2 - (2.0 - 4.0 / math.pi) * c2a + (1.5 - 4.0 / math.pi)  # (B.9-B.14)
    bracket = (0.5 + v2s2 + math.sin(2.0 * c.alpha) ** 2) * c.length + c.p1
    return coupler_rho_a(c) * bracket


def coupler_damping(c: BentCoupler) -> float:
    """Modal viscous damping 0.45 L C_co (18.e) [N.s/m] (the factor exactly 3 - 8/pi, B.7,
    where the coupler's inertia is computed from the geometry)."""
    return c.damping_factor * c.length * c.c_co


def strain_factors(c: BentCoupler) -> tuple[float, float]:
    """Outer-fibre strain per unit q at the gauge (63) and at B (maximum) [1/m]."""
    curv = (c.d_outer / 2.0) * (math.pi / (2.0 * c.length)) ** 2
    return curv * math.sin(math.pi * c.gauge_x1 / (2.0 * c.length)), curv


@dataclass(frozen=True)
class DriveModel:
    """Everything the coupler equation needs, in SI; shared with the monolithic reference."""

    omega: float  # crank speed [rad/s]
    kin: ExactRSSR | FourierRocker
    m_co: float  # M' [kg]
    k_e: float  # [N/m]
    c_e: float  # [N.s/m]
    j_o4: float  # [kg.m^2]
    rho_a: float  # multiplies F1 (21) [kg/m]
    f1: tuple[float, float, float]  # Fourier coefficients of F1/phi1dot^2 [m^2]
    phi4_max: float  # forward coordinate origin [rad]
    rigid: bool


def coupler_derivatives(
    m: DriveModel, phi1: float, q: float, qd: float, torque: float, kin: tuple | None = None
) -> tuple[float, float, float, float, float]:
    """(q'', theta4, theta4', P_in, P_diss) at one instant; torque = clutch torque T >= 0.

    Time derivatives (not crank-angle).  Implements (B.15) with constant P1, see module doc.
    """
    w = m.omega
    p4, d4, dd4, f2, f2d, f2dd = kin if kin is not None else m.kin(phi1)
    v_r = w * (d4 + f2d * q)  # part of phi4e' not due to q'
    a_r = w * w * (dd4 + f2dd * q) + 2.0 * w * f2d * qd  # part of phi4e'' not due to q''
    if m.rigid:
        qdd = 0.0
        f1 = 0.0
    else:
        a0, a1, b1 = m.f1
        f1 = m.rho_a * w * w * (a0 + a1 * math.cos(phi1) + b1 * math.sin(phi1))
        qdd = (f1 - m.c_e * qd - m.k_e * q + f2 * (torque - m.j_o4 * a_r)) / (
            m.m_co + m.j_o4 * f2 * f2
        )
    phi4e_dd = a_r + f2 * qdd
    p_in = f1 * qd + (m.j_o4 * phi4e_dd - torque) * v_r
    theta4 = m.phi4_max - (p4 + f2 * q)
    theta4_d = -(v_r + f2 * qd)
    return qdd, theta4, theta4_d, p_in, m.c_e * qd * qd


def rocker_motion(
    m: DriveModel, phi1: float, q: float, qd: float, kin: tuple | None = None
) -> tuple[float, float]:
    """(theta4, theta4') of the rocker, forward positive (14)."""
    p4, d4, _, f2, f2d, _ = kin if kin is not None else m.kin(phi1)
    return m.phi4_max - (p4 + f2 * q), -(m.omega * (d4 + f2d * q) + f2 * qd)


def rocker_angles(m: DriveModel, phi1: np.ndarray, q: np.ndarray) -> np.ndarray:
    """theta4 of the rocker (rocker_motion's angle) at each crank angle and deflection."""
    return np.array(
        [m.phi4_max - (p[0] + p[3] * qk) for p, qk in zip(map(m.kin, phi1), q, strict=True)]
    )


def coupler_energy(m: DriveModel, q: float, qd: float, theta4_d: float) -> float:
    """Kinetic + strain energy held by the coupler and the rocker [J]."""
    return 0.5 * m.m_co * qd * qd + 0.5 * m.k_e * q * q + 0.5 * m.j_o4 * theta4_d * theta4_d


def build_drive_model(
    rpm: float,
    linkage: RSSRLinkage = LINKAGE_TABLE1,
    coupler: BentCoupler = COUPLER_STANDARD,
    j_o4: float = J_O4,
    f1: tuple[float, float, float] = APP_H_FOURIER.f1,
    f2_const: float | None = None,
    fourier_phi4: tuple[float, float, float] | None = None,
    m_e: float | None = None,
    k_e: float | None = None,
    c_e: float | None = None,
    rigid: bool = False,
    phi4_max: float | None = None,
) -> DriveModel:
    """Assemble a DriveModel from data; m_e/k_e/c_e override the geometric values.

    ``m_e`` is the total equivalent mass of (19) including J_o4 F2^2 (App. H prints 0.00632
    lb.s^2/in); it requires a constant F2.  ``fourier_phi4`` selects the App. H rocker.
    """
    exact = ExactRSSR(linkage, coupler.alpha, f2_const)
    if fourier_phi4 is not None:
        if f2_const is None:
            raise ComponentError("the Fourier rocker needs a constant F2")
        kin: ExactRSSR | FourierRocker = FourierRocker(fourier_phi4, f2_const)
    else:
        kin = exact
    if phi4_max is None:
        phi4_max = rocker_extremes(exact)[0]
    m_co = coupler_modal_mass(coupler)
    if m_e is not None:
        if f2_const is None:
            raise ComponentError("an equivalent-mass override needs a constant F2")
        m_co = m_e - j_o4 * f2_const**2
    return DriveModel(
        omega=rpm * RPM,
        kin=kin,
        m_co=m_co,
        k_e=coupler_stiffness(coupler) if k_e is None else k_e,
        c_e=coupler_damping(coupler) if c_e is None else c_e,
        j_o4=j_o4,
        rho_a=coupler_rho_a(coupler),
        f1=f1,
        phi4_max=phi4_max,
        rigid=rigid,
    )


class _CouplerMotion:
    """The coupler equation over one step with the clutch torque held (or ramped about its
    step mean: ``torque + rate (t - t_mid)``, t_mid where the crank is at ``phi1_mid``), for
    the shared integrator: state [phi1, q, q', W_in, W_diss]; its one event is the rocker
    reversal (``direction`` * rocker speed turns negative), which changes only the
    direction."""

    __slots__ = ("m", "torque", "direction", "rate", "phi1_mid")

    def __init__(
        self,
        m: DriveModel,
        torque: float,
        direction: float,
        rate: float = 0.0,
        phi1_mid: float = 0.0,
    ) -> None:
        self.m, self.torque, self.direction = m, torque, direction
        self.rate, self.phi1_mid = rate, phi1_mid

    def deriv(self, y: list[float]) -> list[float]:
        m = self.m
        torque = self.torque
        if self.rate:  # the crank angle is the clock: t - t_mid = (phi1 - phi1_mid) / omega
            torque += self.rate * (y[0] - self.phi1_mid) / m.omega
        qdd, _, _, p_in, p_diss = coupler_derivatives(m, y[0], y[1], y[2], torque)
        return [m.omega, y[2], qdd, p_in, p_diss]

    def indicators(self, y: list[float]) -> tuple[float]:
        return (self.direction * rocker_motion(self.m, y[0], y[1], y[2])[1],)

    def event(self, y: list[float], index: int, t: float) -> list[float]:
        self.direction = -self.direction
        return y


def with_inertia(
    linkage: RSSRLinkage,
    coupler: BentCoupler,
    f1: tuple[float, float, float],
    computed: float,
) -> tuple[BentCoupler, tuple[float, float, float]]:
    """The coupler and F1 coefficients the drive uses: as given (``computed`` = 0: Run 1's
    printed P1, F1, 0.05/in and 0.45), or P1, F1, the lumped-mass and damping factors
    computed from the linkage and coupler (``computed`` = 1, components.coupler_inertia)."""
    if computed < 0.5:
        return coupler, f1
    ci = computed_inertia(linkage, coupler.alpha, coupler.length)
    out = replace(
        coupler, p1=ci.p1, lumped_factor=ci.lumped_factor, damping_factor=ci.damping_factor
    )
    return out, ci.f1


# -- the component ----------------------------------------------------------------------
_T1 = LINKAGE_TABLE1
_C = COUPLER_STANDARD


class CrankCouplerDrive(Component):
    """Constant-speed crank, RSSR linkage with elastic bent coupler, rocker = outer race.

    Input ``torque``: the torque the clutch transmits (>= 0); it loads the rocker against
    the feed stroke.  Input ``torque_rate``: where a master knows how the torque moves over
    a step, it ramps about ``torque`` at mid-step (a master's first-order hold; 0: held).
    Internal event: rocker reversal (``speed`` = 0), located exactly; it changes only the
    reported regime, not the equations.  The coupler equation is
    integrated by the shared Dormand-Prince pair (``components.event_integration``) with
    the torque held (or ramped) over the step; ``tolerance`` and ``h_max`` set its accuracy.

    Port ``rocker`` (angle, speed out; torque in) joins the clutch's outer race.  The crank
    work is ``external_work`` (brought in from outside the scene, see components.base);
    ``input_work`` is the same number under its older name.
    """

    REGIME_NAMES = REGIME_NAMES

    PORTS = {"rocker": {"angle": "angle", "speed": "speed", "torque": "torque"}}

    # Its state is scalars and its model (DriveModel) is frozen: shared, not pickled.
    SNAPSHOT = SnapshotPlan()

    VARIABLES = (
        Variable(
            "rpm", "parameter", "1", 200.0, "crank speed [rev/min] (if crank_speed = 0)", min=0.0
        ),
        Variable("crank_speed", "parameter", "rad/s", 0.0, "crank speed; 0: take rpm", min=0.0),
        Variable("phi1_0", "parameter", "rad", 0.0, "crank angle at t0 (if start_at_max = 0)"),
        Variable(
            "start_at_max",
            "parameter",
            "1",
            1.0,
            "1: start at the rigid rocker maximum",
            min=0.0,
            max=1.0,
        ),
        design_parameter("a1", "m", _T1.a1, "crank length", "Xu: a1", min=0.0, exclusive_min=True),
        design_parameter(
            "a3", "m", _T1.a3, "coupler chord AC", "Xu: a3", min=0.0, exclusive_min=True
        ),
        design_parameter("a4", "m", _T1.a4, "rocker length", "Xu: a4", min=0.0, exclusive_min=True),
        # Frame offsets are signed distances along the joint axes (Hartenberg-Denavit).
        design_parameter("s1", "m", _T1.s1, "frame offset s1", "Xu: s1"),
        design_parameter("s2", "m", _T1.s2, "frame offset s2", "Xu: s2"),
        design_parameter("s3", "m", _T1.s3, "frame offset s3", "Xu: s3"),
        design_parameter(
            "alpha",
            "rad",
            _C.alpha,
            "coupler half bend angle",
            "Xu: alpha",
            min=0.0,
            max=0.5 * math.pi,
        ),
        design_parameter(
            "L", "m", _C.length, "coupler section length", "Xu: L", min=0.0, exclusive_min=True
        ),
        design_parameter(
            "d_outer",
            "m",
            _C.d_outer,
            "coupler tube outer diameter",
            "Xu: D_o",
            min=0.0,
            exclusive_min=True,
        ),
        design_parameter(
            "d_inner", "m", _C.d_inner, "coupler tube inner diameter", "Xu: D_i", min=0.0
        ),
        design_parameter(
            "youngs",
            "Pa",
            _C.youngs,
            "coupler Young's modulus",
            "Xu: E",
            min=0.0,
            exclusive_min=True,
        ),
        design_parameter(
            "density",
            "kg/m3",
            _C.density,
            "coupler density",
            "Xu: rho",
            min=0.0,
            exclusive_min=True,
        ),
        design_parameter(
            "c_co", "N.s/m2", _C.c_co, "coupler damping per unit length", "Xu: C_co", min=0.0
        ),
        Variable("p1", "parameter", "m", _C.p1, "mean of P1 (B.17) (coupler_inertia = 0)", min=0.0),
        design_parameter(
            "gauge_x1", "m", _C.gauge_x1, "strain gauge position from A", "Xu: x1", min=0.0
        ),
        design_parameter("lumped_mass", "kg", 0.0, "mass clamped at B (App. G)", "Xu: M", min=0.0),
        design_parameter(
            "j_o4", "kg.m2", J_O4, "rocker + clutch input inertia", "Xu: J_o4", min=0.0
        ),
        Variable(
            "f1_a0",
            "parameter",
            "m2",
            APP_H_FOURIER.f1[0],
            "F1/phi1dot^2 constant a10 (coupler_inertia = 0)",
        ),
        Variable(
            "f1_a1",
            "parameter",
            "m2",
            APP_H_FOURIER.f1[1],
            "F1/phi1dot^2 cos term a11 (coupler_inertia = 0)",
        ),
        Variable(
            "f1_b1",
            "parameter",
            "m2",
            APP_H_FOURIER.f1[2],
            "F1/phi1dot^2 sin term b11 (coupler_inertia = 0)",
        ),
        Variable("f2_const", "parameter", "rad/m", 0.0, "constant F2 (0: F2(phi1) exact)", min=0.0),
        Variable("rigid", "parameter", "1", 0.0, "1: rigid coupler (q = 0)", min=0.0, max=1.0),
        Variable(
            "coupler_inertia",
            "parameter",
            "1",
            0.0,
            "0: P1, F1, the lumped-mass and damping factors as printed for Run 1; "
            "1: computed from the linkage and coupler (App. B, G)",
            min=0.0,
            max=1.0,
        ),
        # The rocker reverses twice a crank turn (0.3 s at 200 rpm): 1 ms steps see it.
        *integration_variables(h_max=1.0e-3),
        Variable("torque", "input", "N.m", 0.0, "torque transmitted by the clutch (>= 0)"),
        rate_input("torque", "N.m"),
        Variable("phi1", "output", "rad", 0.0, "crank angle (absolute, unwrapped)"),
        # Nominals: the rocker swings about half a radian at a few rad/s; it starts at rest.
        Variable(
            "angle",
            "output",
            "rad",
            0.0,
            "rocker / outer race angle, forward positive",
            nominal=1.0,
        ),
        Variable(
            "speed", "output", "rad/s", 0.0, "rocker speed; zero = rocker reversal", nominal=1.0
        ),
        Variable("q", "output", "m", 0.0, "coupler midpoint deflection (+ = tension)"),
        Variable("q_dot", "output", "m/s", 0.0, "coupler deflection rate"),
        Variable("strain", "output", "1", 0.0, "outer-fibre strain at the gauge (63)"),
        Variable("strain_b", "output", "1", 0.0, "outer-fibre strain at the bend B"),
        Variable("phi4_max", "output", "rad", 0.0, "thesis phi4 at theta4 = 0"),
        Variable("input_work", "output", "J", 0.0, "work done by the crank drive"),
        Variable("external_work", "output", "J", 0.0, "work done by the crank drive"),
        Variable("event_time", "output", "s", -1.0, "time of the last rocker reversal"),
        Variable("t_event", "output", "s", -1.0, "time of the last rocker reversal"),
        Variable("ind_rocker_speed", "output", "rad/s", 0.0, "rocker speed; zero = reversal"),
        *COMMON_OUTPUTS,
    )

    def linkage(self) -> RSSRLinkage:
        return RSSRLinkage(self.a1, self.a3, self.a4, self.s1, self.s2, self.s3)

    def coupler(self) -> BentCoupler:
        return BentCoupler(
            length=self.L,
            alpha=self.alpha,
            d_outer=self.d_outer,
            d_inner=self.d_inner,
            youngs=self.youngs,
            density=self.density,
            c_co=self.c_co,
            p1=self.p1,
            gauge_x1=self.gauge_x1,
            lumped_mass=self.lumped_mass,
        )

    def _build(self) -> tuple[DriveModel, BentCoupler]:
        linkage = self.linkage()
        coupler, f1 = with_inertia(
            linkage, self.coupler(), (self.f1_a0, self.f1_a1, self.f1_b1), self.coupler_inertia
        )
        return build_drive_model(
            self.crank_rpm(),
            linkage,
            coupler,
            j_o4=self.j_o4,
            f1=f1,
            f2_const=self.f2_const if self.f2_const > 0.0 else None,
            rigid=self.rigid > 0.5,
        ), coupler

    def crank_rpm(self) -> float:
        """Crank speed in rev/min: crank_speed when given, else rpm."""
        return self.crank_speed / RPM if self.crank_speed > 0.0 else self.rpm

    def initialize(self, t0: float) -> None:
        if self.crank_rpm() <= 0.0:
            raise ComponentError("CrankCouplerDrive: rpm must be positive")
        # A linkage that does not assemble or a coupler at odds with it is refused, not run.
        raise_first(drive_violations(self.linkage(), self.coupler(), self.rigid <= 0.5))
        self._m, coupler = self._build()
        self._control = integration_step_control(self, STATE_SCALES)
        self._h_next = 0.0
        self._gauge, self._at_b = strain_factors(coupler)
        exact = ExactRSSR(self.linkage(), self.alpha)
        if self.start_at_max > 0.5:
            self.phi1_0 = rocker_extremes(exact)[1]
        self._t0 = t0
        self._t = t0
        self.q = self.q_dot = 0.0
        self.input_work = self.dissipated_work = 0.0
        self.phi4_max = self._m.phi4_max
        self.update_outputs()
        if self.start_at_max > 0.5:
            # At the located extreme the speed is rounding noise of either sign; a few ulps
            # on the crank make it leave forward, so the clutch does not see a spurious
            # return (and disengage) in its first step.
            for _ in range(64):
                if self.speed >= 0.0:
                    break
                self.phi1_0 = math.nextafter(self.phi1_0, math.inf)
                self.update_outputs()
        self.regime = REGIME_FORWARD if self.speed >= 0.0 else REGIME_RETURN

    def update_outputs(self) -> None:
        m = self._m
        self.phi1 = self.phi1_0 + m.omega * (self._t - self._t0)
        _, th, thd, _, _ = coupler_derivatives(m, self.phi1, self.q, self.q_dot, self.torque)
        self.angle, self.speed = th, thd
        self.strain = self._gauge * self.q
        self.strain_b = self._at_b * self.q
        self.stored_energy = coupler_energy(m, self.q, self.q_dot, thd)
        self.ind_rocker_speed = thd
        self.external_work = self.input_work
        self.t_event = self.event_time

    def step(self, t: float, h: float) -> None:
        m = self._m
        phi1 = self.phi1_0 + m.omega * (t - self._t0)
        speed = rocker_motion(m, phi1, self.q, self.q_dot)[1]
        # The side the rocker is on: from its speed, or at rest from the regime.
        forward = speed > 0.0 or (speed == 0.0 and self.regime == REGIME_FORWARD)
        motion = _CouplerMotion(
            m, self.torque, 1.0 if forward else -1.0, self.torque_rate, phi1 + 0.5 * m.omega * h
        )
        y = [phi1, self.q, self.q_dot, self.input_work, self.dissipated_work]
        done = advance(motion, y, h, self._control, self._h_next)
        self._h_next = done.h_next
        if done.events:
            self.event_time = t + done.t_last_event
            self.regime = REGIME_FORWARD if motion.direction > 0.0 else REGIME_RETURN
        _, self.q, self.q_dot, wi, wd = done.y
        self.input_work, self.dissipated_work = wi, wd
        self._t = t + h
        self.update_outputs()


_KERNEL = load_kernel("press_feed_kernel")
if _KERNEL is not None:  # the compiled twins (components.kernels): the same results
    _KERNEL.use_python(
        coupler_derivatives=coupler_derivatives,
        rocker_motion=rocker_motion,
        rocker_angles=rocker_angles,
        deriv=_CouplerMotion.deriv,
        indicators=_CouplerMotion.indicators,
    )
    _KERNEL.use_classes(coupler_motion=_CouplerMotion)
    use_compiled_loop(_KERNEL)  # event_integration.advance runs the drive's model in C
    coupler_derivatives = _KERNEL.coupler_derivatives  # noqa: F811
    rocker_motion = _KERNEL.rocker_motion  # noqa: F811
    rocker_angles = _KERNEL.rocker_angles  # noqa: F811
    _CouplerMotion.deriv = _KERNEL.coupler_motion_deriv  # type: ignore[method-assign]
    _CouplerMotion.indicators = _KERNEL.coupler_motion_indicators  # type: ignore[method-assign]
