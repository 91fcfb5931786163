"""Sprag clutch between the outer race (rocker) and the inner race (roller shaft).

Massless one-way coupling of Xu (1993), *Contributions to the Theory of Machine Dynamics*, Part I
eq. (1), App. C, Part II §4 and Part III.  Windup ``w = theta4 - theta5`` (forward-positive
coordinates; = phi5 - phi4 of the thesis).  While w > 0 the clutch is engaged and transmits

    T = max(0, K w^{3/2} + (c_lin + c_nl w^n) w')                (1), Part II (92)

and nothing while w <= 0 (overrunning).  The clamp at zero is the sprags lifting off: a
one-way clutch cannot pull.  Default damping is the Part II law (n = 1/4, C_nl = 62.6
lbf.in.s.rad^-5/4), continuous at engagement; Part I's linear C_sp is the c_lin option.

The stiffness K is either the measured lumped value (model 0) or computed from the two-point
Hertz contact of Part III (model 1, eqs 107-108, M.10-M.14).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .base import (
    Component,
    ComponentError,
    SnapshotPlan,
    Variable,
    common_outputs,
    design_parameter,
)
from .design_rules import raise_first
from .press_feed_data import C_NL, K_SP, N_DAMP, TABLE4, SpragGeometry
from .press_feed_rules import sprag_violations

REGIME_OVERRUN = 0
REGIME_ENGAGED = 1
REGIME_NAMES = {REGIME_OVERRUN: "overrun", REGIME_ENGAGED: "engaged"}
MODEL_LUMPED = 0
MODEL_HERTZ = 1


# -- torque law -----------------------------------------------------------------------------
def clutch_torque(w: float, wd: float, k: float, c_lin: float, c_nl: float, n: float) -> float:
    """Transmitted torque (>= 0) for windup w and windup rate wd."""
    if w <= 0.0:
        return 0.0
    t = k * w * math.sqrt(w) + (c_lin + c_nl * w**n) * wd
    return t if t > 0.0 else 0.0


def clutch_energy(w: float, k: float) -> float:
    """Potential energy (2/5) K w^{5/2} (B.4)."""
    return 0.4 * k * w * w * math.sqrt(w) if w > 0.0 else 0.0


def clutch_dissipation_rate(w: float, wd: float, torque: float, k: float) -> float:
    """Power lost in the clutch: T w' minus the rate of change of the spring energy."""
    if w <= 0.0:
        return 0.0
    return (torque - k * w * math.sqrt(w)) * wd


# -- App. C linearizations and Part II damping ----------------------------------------------
def preload_windup(k: float, t_b: float) -> float:
    """Windup that balances the brake torque, (T_b/K)^{2/3} (C.2)."""
    return (t_b / k) ** (2.0 / 3.0)


def secant_stiffness(k: float, t_b: float) -> float:
    """Regime-1 secant K_l1 = K^{2/3} T_b^{1/3} (C.6-C.8)."""
    return k ** (2.0 / 3.0) * t_b ** (1.0 / 3.0)


def tangent_stiffness(k: float, t_b: float) -> float:
    """Regime-2 tangent at the load point, K_l2 = 1.5 K^{2/3} T_b^{1/3} (C.1-C.5)."""
    return 1.5 * k ** (2.0 / 3.0) * t_b ** (1.0 / 3.0)


def unwinding_stiffness(k: float, w_end: float) -> float:
    """Regime-3 secant from the end of Regime 2, K_l3 = K w_f2^{1/2} (C.9-C.10)."""
    return k * math.sqrt(max(w_end, 0.0))


def linearized_torque(w: float, wd: float, k_l: float, offset: float, c_lin: float) -> float:
    """App. C law T = K_l w + offset + C_sp w' (offset = -T_b/2 in Regime 2, else 0)."""
    return k_l * w + offset + c_lin * wd


def nonlinear_damping_constant(r: float, j: float, k: float, beta: float = 1.5) -> float:
    """C_nl from the amplitude decay ratio R (90) with n = (beta-1)/2 and the integral = pi.

    For beta = 3/2 this is (100): C_nl = sqrt(6 J K) (1 - R) / (pi (1 + R)).
    """
    return 2.0 * math.sqrt(j * k * beta) * (1.0 - r) / (1.0 + r) / math.pi


# -- Part III: two-point Hertz contact ------------------------------------------------------
def _ellipke(m: float) -> tuple[float, float]:
    """Complete elliptic integrals K(m), E(m) (parameter m = e^2) by the AGM."""
    a, b = 1.0, math.sqrt(1.0 - m)
    c2_sum, power = 0.5 * m, 0.5  # sum of 2^(n-1) c_n^2, starting with c_0^2 = m
    for _ in range(40):
        c = 0.5 * (a - b)
        a, b = 0.5 * (a + b), math.sqrt(a * b)
        power *= 2.0
        c2_sum += power * c * c
        if abs(c) < 1e-17:
            break
    k = math.pi / (2.0 * a)
    return k, k * (1.0 - c2_sum)


def roark_lambda(cos_theta: float) -> float:
    """Roark's lambda for point contact, delta = lambda (P^2 C_E^2 / K_D)^{1/3}.

    From Hertz's elliptic contact (Johnson §4.2): the ellipse eccentricity e follows from
    B/A = (1 + cos theta)/(1 - cos theta); lambda = 0.750 at cos theta = 0 (spheres).
    """
    if cos_theta < 1e-9:
        return 0.75
    ratio = (1.0 + cos_theta) / (1.0 - cos_theta)

    def b_over_a(m: float) -> float:
        kk, ee = _ellipke(m)
        return (ee / (1.0 - m) - kk) / (kk - ee)

    lo, hi = 1e-12, 1.0 - 1e-12  # B/A grows monotonically with e^2: bisect
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if b_over_a(mid) < ratio:
            lo = mid
        else:
            hi = mid
        if hi - lo < 1e-16:
            break
    m = 0.5 * (lo + hi)
    kk, ee = _ellipke(m)
    # With A = 1, E* = 1, P = 1: a^3 = 3P(K-E)/(2 pi A E* e^2), delta = A e^2 K a^2/(K-E).
    a = (3.0 * (kk - ee) / (2.0 * math.pi * m)) ** (1.0 / 3.0)
    delta = m * kk * a * a / (kk - ee)
    k_d = 0.75 / (1.0 + ratio)  # K_D = 1.5 / (sum of curvatures) = 0.75/(A + B)
    return delta / (1.0 / k_d) ** (1.0 / 3.0)


@dataclass(frozen=True)
class HertzClutch:
    """Two-point Hertz sprag clutch: N_h = G w^{3/2} per sprag, K = alpha R_i Z G."""

    e_star: float  # [Pa]
    lambda_i: float
    lambda_o: float
    d_i: float  # (L.19) [rad/m]
    d_o: float  # (L.18) [rad/m]
    g: float  # [N/rad^{3/2}]
    k: float  # [N.m/rad^{3/2}]

    def deflections(self, n_h: float, s: SpragGeometry) -> tuple[float, float]:
        """(delta_i, delta_o) for a sprag load N_h, two-point contact (M.10-M.11)."""
        p = (0.5 * n_h / self.e_star) ** (2.0 / 3.0)
        ri, ro, rs = s.r_inner, s.r_outer, s.r_sprag
        di = self.lambda_i * ((2 * ri + rs) / (1.5 * rs * ri)) ** (1 / 3) * p
        do = self.lambda_o * ((2 * ro - rs) / (1.5 * rs * ro)) ** (1 / 3) * p
        return di, do


def two_point_hertz(s: SpragGeometry = TABLE4) -> HertzClutch:
    """Stiffness of the two-point contact model from (107) and Roark point contact (M.10-11)."""
    ri, ro, rs, a = s.r_inner, s.r_outer, s.r_sprag, s.offset
    e_star = 1.0 / (2.0 * (1.0 - s.poisson**2) / s.youngs)  # (M.3), equal materials
    lam_i = roark_lambda(rs / (2.0 * ri + rs))
    lam_o = roark_lambda(rs / (2.0 * ro - rs))
    d_o = (
        2.0
        * (ro - rs)
        / math.sqrt((2 * a * (ri + rs)) ** 2 - (a * a + (ri + rs) ** 2 - (ro - rs) ** 2) ** 2)
    )  # (L.18)
    d_i = (
        2.0
        * (ri + rs)
        / math.sqrt((2 * a * (ro - rs)) ** 2 - (a * a + (ro - rs) ** 2 - (ri + rs) ** 2) ** 2)
    )  # (L.19)
    # w = R_s (R_o + R_i)/(R_o R_i) (D_o delta_o + D_i delta_i) = c N_h^{2/3}   (107)
    per_load = (
        d_o * lam_o * ((2 * ro - rs) / (1.5 * rs * ro)) ** (1 / 3)
        + d_i * lam_i * ((2 * ri + rs) / (1.5 * rs * ri)) ** (1 / 3)
    ) * (0.5 / e_star) ** (2.0 / 3.0)
    c = rs * (ro + ri) / (ro * ri) * per_load
    g = c**-1.5  # (108)
    return HertzClutch(e_star, lam_i, lam_o, d_i, d_o, g, s.strut_inner * ri * s.n_sprags * g)


def m14_g(h: HertzClutch, s: SpragGeometry = TABLE4) -> float:
    """G as printed in (M.14), for cross-checking two_point_hertz."""
    ri, ro, rs = s.r_inner, s.r_outer, s.r_sprag
    bracket = h.d_o * h.lambda_o * (2 - rs / ro) ** (1 / 3) + h.d_i * h.lambda_i * (
        2 + rs / ri
    ) ** (1 / 3)
    return 2.0 * math.sqrt(1.5) * h.e_star / rs * (ro * ri / ((ro + ri) * bracket)) ** 1.5


def sprag_inertia_terms(s: SpragGeometry = TABLE4) -> tuple[float, float, float, float]:
    """Table 5 terms (119)-(120): Z Ri^2 Js/(Ro-Ri)^2, Z Ri^2 ms/4, Z Ri Ro Js/(Ro-Ri)^2,
    -Z Ri Ro ms/4 [kg.m^2]."""
    ri, ro, z = s.r_inner, s.r_outer, s.n_sprags
    gap2 = (ro - ri) ** 2
    return (
        z * ri * ri * s.j_sprag / gap2,
        z * ri * ri * s.m_sprag / 4.0,
        z * ri * ro * s.j_sprag / gap2,
        -z * ri * ro * s.m_sprag / 4.0,
    )


# -- the component ---------------------------------------------------------------------------
_GL_X, _GL_W = np.polynomial.legendre.leggauss(8)
_GL_X, _GL_W = tuple(0.5 * (_GL_X + 1.0)), tuple(0.5 * _GL_W)
_S = TABLE4
# Direct feedthrough: the windup follows the race angles, its rate the race speeds.
_RACE_ANGLES = ("angle_outer", "angle_inner")
_RACE_SPEEDS = ("speed_outer", "speed_inner")
_RACE_MOTION = _RACE_ANGLES + _RACE_SPEEDS


class SpragClutch(Component):
    """Massless sprag clutch; direct feedthrough from the race motions to the torque.

    The sprags lock at the relative position where the outer race last overtook the inner
    one, so the windup is ``w = angle_outer - angle_inner - lock`` with a hidden lock angle.
    While overrunning the sprags slide (w = 0, the lock angle follows the races); the clutch
    re-engages when the relative speed turns positive (at the rocker reversal, F.3) and
    disengages when w returns to zero (E.3).  ``event_indicator`` is w while engaged and the
    relative speed while overrunning: its zero is the next regime change.

    During a step the race angles advance with their held speeds (consistent with the held
    inputs), so the disengagement instant is a linear root, located exactly.

    Ports ``outer`` (rocker side) and ``inner`` (roller side) take the race angle and speed
    and give the transmitted torque, which loads the rocker and drives the roller.
    """

    REGIME_NAMES = REGIME_NAMES

    PORTS = {
        "outer": {"angle": "angle_outer", "speed": "speed_outer", "torque": "torque"},
        "inner": {"angle": "angle_inner", "speed": "speed_inner", "torque": "torque"},
    }

    SNAPSHOT = SnapshotPlan()  # its state is scalars: shared, not pickled

    VARIABLES = (
        Variable(
            "model",
            "parameter",
            "1",
            MODEL_LUMPED,
            "0: lumped K; 1: two-point Hertz",
            min=0.0,
            max=1.0,
        ),
        design_parameter(
            "k", "N.m", K_SP, "lumped stiffness [N.m/rad^1.5] (model 0)", "Xu: K_sp", min=0.0
        ),
        Variable("c_lin", "parameter", "N.m.s/rad", 0.0, "linear damping C_sp (Part I)", min=0.0),
        Variable(
            "c_nl", "parameter", "N.m.s", C_NL, "nonlinear damping C_nl [N.m.s/rad^1.25]", min=0.0
        ),
        Variable("n_damp", "parameter", "1", N_DAMP, "damping exponent n", min=0.0),
        Variable(
            "engaged0", "parameter", "1", 1.0, "1: engaged at t0 with zero windup", min=0.0, max=1.0
        ),
        design_parameter(
            "r_outer",
            "m",
            _S.r_outer,
            "outer race contact radius",
            "Xu: R_o",
            min=0.0,
            exclusive_min=True,
        ),
        design_parameter(
            "r_inner",
            "m",
            _S.r_inner,
            "inner race contact radius",
            "Xu: R_i",
            min=0.0,
            exclusive_min=True,
        ),
        design_parameter(
            "r_sprag",
            "m",
            _S.r_sprag,
            "sprag profile radius",
            "Xu: R_s",
            min=0.0,
            exclusive_min=True,
        ),
        design_parameter(
            "sprag_offset", "m", _S.offset, "sprag curvature-centre offset", "Xu: a", min=0.0
        ),
        design_parameter("n_sprags", "1", _S.n_sprags, "number of sprags", "Xu: Z", min=1.0),
        design_parameter(
            "strut_inner",
            "rad",
            _S.strut_inner,
            "strut angle",
            "Xu: alpha (Part III)",
            min=0.0,
            max=0.5 * math.pi,
        ),
        design_parameter(
            "strut_outer",
            "rad",
            _S.strut_outer,
            "strut angle",
            "Xu: beta",
            min=0.0,
            max=0.5 * math.pi,
        ),
        Variable(
            "youngs",
            "parameter",
            "Pa",
            _S.youngs,
            "Young's modulus (races, sprags)",
            min=0.0,
            exclusive_min=True,
        ),
        Variable("poisson", "parameter", "1", _S.poisson, "Poisson ratio", min=-1.0, max=0.5),
        Variable("angle_outer", "input", "rad", 0.0, "outer race angle (forward positive)"),
        Variable("speed_outer", "input", "rad/s", 0.0, "outer race speed"),
        Variable("angle_inner", "input", "rad", 0.0, "inner race angle (forward positive)"),
        Variable("speed_inner", "input", "rad/s", 0.0, "inner race speed"),
        Variable(
            "torque",
            "output",
            "N.m",
            0.0,
            "torque transmitted outer -> inner (>= 0)",
            depends_on=_RACE_MOTION,
        ),
        Variable(
            "windup",
            "output",
            "rad",
            0.0,
            "windup w >= 0 (0 while overrunning)",
            depends_on=_RACE_ANGLES,
        ),
        Variable(
            "windup_rate",
            "output",
            "rad/s",
            0.0,
            "relative speed outer - inner",
            depends_on=_RACE_SPEEDS,
        ),
        Variable(
            "event_indicator",
            "output",
            "1",
            0.0,
            "w if engaged, rel. speed if not",
            depends_on=_RACE_MOTION,
        ),
        Variable(
            "contact_force",
            "output",
            "N",
            0.0,
            "spring part of N_h per sprag",
            depends_on=_RACE_ANGLES,
        ),
        Variable("k_eff", "output", "N.m", 0.0, "stiffness in use [N.m/rad^1.5]"),
        Variable("event_time", "output", "s", -1.0, "time of the last regime change"),
        Variable("t_event", "output", "s", -1.0, "time of the last regime change"),
        Variable(
            "ind_clutch",
            "output",
            "1",
            0.0,
            "w if engaged, rel. speed if not",
            depends_on=_RACE_MOTION,
        ),
        *common_outputs(stored_energy=_RACE_ANGLES),
    )

    def initialize(self, t0: float) -> None:
        self.model = int(round(self.model))
        if self.model == MODEL_HERTZ:
            geom = SpragGeometry(
                self.r_outer,
                self.r_inner,
                self.r_sprag,
                self.sprag_offset,
                int(self.n_sprags),
                self.strut_inner,
                self.strut_outer,
                self.youngs,
                self.poisson,
                0.0,
                0.0,
                0.0,
            )
            # A sprag that cannot touch both races has no real Hertz stiffness: refused.
            raise_first(sprag_violations(geom))
            self.k_eff = two_point_hertz(geom).k
        elif self.model == MODEL_LUMPED:
            self.k_eff = self.k
        else:
            raise ComponentError(f"SpragClutch: unknown model {self.model}")
        if self.k_eff <= 0.0 or self.c_lin < 0.0 or self.c_nl < 0.0:
            raise ComponentError("SpragClutch: need k > 0, c_lin >= 0, c_nl >= 0")
        self._lever = self.strut_inner * self.r_inner * self.n_sprags  # T = N_h alpha R_i Z
        self._lock = self.angle_outer - self.angle_inner
        self.regime = REGIME_ENGAGED if self.engaged0 > 0.5 else REGIME_OVERRUN
        self.update_outputs()

    def _torque(self, w: float, wd: float) -> float:
        return clutch_torque(w, wd, self.k_eff, self.c_lin, self.c_nl, self.n_damp)

    def update_outputs(self) -> None:
        rel = self.angle_outer - self.angle_inner
        wd = self.speed_outer - self.speed_inner
        if self.regime == REGIME_OVERRUN:
            self._lock = rel  # the sprags slide: no windup builds up
        w = rel - self._lock
        self.windup, self.windup_rate = w, wd
        self.event_indicator = w if self.regime == REGIME_ENGAGED else wd
        self.ind_clutch = self.event_indicator
        self.t_event = self.event_time
        self.torque = self._torque(w, wd) if self.regime == REGIME_ENGAGED else 0.0
        self.contact_force = self.k_eff * max(w, 0.0) ** 1.5 / self._lever
        self.stored_energy = clutch_energy(w, self.k_eff)

    def _dissipate(self, w0: float, wd: float, length: float) -> None:
        """Add the exact-enough (8-point Gauss) clutch loss along w0 + wd s, 0 <= s <= length."""
        if length <= 0.0:
            return
        loss = 0.0
        for x, wt in zip(_GL_X, _GL_W, strict=True):
            w = w0 + wd * x * length
            loss += wt * clutch_dissipation_rate(w, wd, self._torque(w, wd), self.k_eff)
        self.dissipated_work += loss * length

    def step(self, t: float, h: float) -> None:
        wd = self.speed_outer - self.speed_inner
        if self.regime == REGIME_OVERRUN and wd > 0.0:
            self.regime = REGIME_ENGAGED  # outer race overtakes: sprags lock here
            self._lock = self.angle_outer - self.angle_inner
            self.event_time = t
        if self.regime == REGIME_ENGAGED:
            w0 = self.angle_outer - self.angle_inner - self._lock
            if wd < 0.0 and w0 + wd * h <= 0.0:
                s_cross = max(0.0, -w0 / wd)
                self._dissipate(w0, wd, s_cross)
                self.regime = REGIME_OVERRUN
                self.event_time = t + s_cross
            else:
                self._dissipate(w0, wd, h)
        self.angle_outer += self.speed_outer * h
        self.angle_inner += self.speed_inner * h
        self.update_outputs()
