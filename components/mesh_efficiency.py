"""Instantaneous (point) and cycle efficiency of gear meshes with Coulomb friction.

Model of Tepper (1981), *Mesh Efficiency of the Integrated Safe/Arm Device of the Pershing II
Missile System*, ARLCD-TR-81020 (pp. 1-13, App. B): quasi-static rigid teeth, Coulomb
friction mu at the teeth and at both pivots, equal load sharing between two pairs in contact.

Involute meshes (Tepper 1981, pp. 2-13, Figs. 7-9): operating pressure angle for an extended
centre distance (eqs. 39–45), pinion inner form radius (Shaffer, eq. 49), start and end of dual
contact and contact ratio (eqs. 1–34), point efficiency in dual contact (eqs. 46/47 = B19/B20,
corrected) and in single contact (ref. 1 eq. A-26), and the cycle efficiency as the mean of the
K points (eqs. 51/52).  The end of dual contact is computed by the physics,
(sqrt(r_o^2 - r_b^2) - p_b)/r_b; the 1981 program printed other values for four meshes (ALFIN of
Tables 15, 16, 18 and 21, pp. 31-37, disagrees with eqs. 20 + 23), so it can be overridden to
regress against Appendix E.

Clock meshes (Tepper 1981, p. 1, Fig. 2): the report gives no equations (CLOCK2 is in its
ref. 1, Lowen & Tepper, *Fuze Gear Train Analysis*, ARLCD-TR-79030, 1979).  The clock
efficiency here is **derived**: both working profiles are circular arcs (App. A constant-curvature
teeth), continued below their centres of curvature by straight flanks.  In round-on-round contact
the normal passes through both centres of curvature (a four-bar O_G-C_G-C_P-O_P); in round-on-flank
contact it passes through the arc centre, square to the flank.  The single-contact statics,
derived here for any contact normal (normal force, Coulomb force along the sliding direction,
pivot friction mu rho |N|, the friction model of Tepper 1981, App. B), then give the point
efficiency; it reproduces ref. 1 eq. A-26 for an involute contact.  The pair in
contact is the one that holds the driven pinion furthest back, which also hands over to the next
pair.  The centre distance is not tabulated and is taken as R_G + R_P.

Everything is SI inside; the efficiencies are dimensionless.  Angles are in radians.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from .clock_train_kinematics import ClockMesh
from .mesh_efficiency_data import INCH, ClockMeshData, InvoluteMesh

#: The programs' truncated pi and degree factor (ISAD1/ISAD2, Tepper 1981, Apps. C-D, pp. 71-82);
#: only for regression to the printout.
LEGACY_PI = 3.14159

#: Friction coefficients of the report's sweep (0 to 0.3 by 0.025: the ISAD1/ISAD2 loop, Apps. C-D;
#: the text on p. 2 says steps of 0.05).
MU_SWEEP = tuple(0.025 * j for j in range(13))


# ------------------------------------------------------------------------------------------
# Involute geometry
# ------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class InvoluteGeometry:
    gear_base_radius: float  # m, R_b
    pinion_base_radius: float  # m, r_b
    base_pitch: float  # m, p_b
    form_radius: float  # m, pinion inner form radius r_f
    cutter_addendum: float  # m, b (eq. 36)
    undercut: bool  # eqs. 37/38
    op_pressure_angle: float  # rad, theta'
    gear_op_pitch_radius: float  # m
    pinion_op_pitch_radius: float  # m
    contact_ratio: float  # 1
    tip_branch: bool  # True when the gear tip Z limits the path (PZ < PZ')
    alpha_in: float  # rad, driver angle where a new pair enters (start of cycle)
    alpha_fin: float  # rad, driver angle at the end of dual contact
    alpha_fin_physical: float  # rad, eq. 20 (+ 23) value, whatever alpha_fin is
    d: float  # m, TT' = (R_b + r_b) tan theta' (eq. 48)
    driver_base_radius: float  # m
    driven_base_radius: float  # m
    driver_pivot_radius: float  # m
    driven_pivot_radius: float  # m
    pinion_drives: bool

    @property
    def cycle_angle(self) -> float:
        """Driver rotation of one base pitch [rad] (eq. 24 / 34)."""
        return self.base_pitch / self.driver_base_radius


def inner_form_radius(
    pinion_base_radius: float,
    pinion_pitch_radius: float,
    cutter_addendum: float,
    phi: float,
    grid: float = 0.0,
) -> float:
    """Pinion inner form radius r_f (eqs. 35–38, 49).

    Undercut pinion: the sign change of Shaffer's TEST function (eq. 49), found by bracketing.
    Otherwise TEST only touches zero and the classical form radius
    sqrt(r_b^2 + (r_p sin phi - b / sin phi)^2) is its touching point (derived here: the
    classical no-undercut form radius, which the Shaffer root reproduces).
    grid > 0 rounds up to the programs' search grid r_b + n grid (INNERF: 1e-6 in), which the
    printed ALIN of the form-radius branch reflects.
    """
    rb, rp, b = pinion_base_radius, pinion_pitch_radius, cutter_addendum
    sin_phi = math.sin(phi)
    if b <= rp * sin_phi**2:  # not undercut
        return math.sqrt(rb**2 + (rp * sin_phi - b / sin_phi) ** 2)
    c2 = 1.0 - b * math.cos(phi) / rb
    base = rb - b * math.cos(phi)

    def test(rf: float) -> float:
        c1 = math.sqrt(max((rf * math.cos(phi) / base) ** 2 - 1.0, 0.0))
        c3 = math.sqrt(max((rf / rb) ** 2 - 1.0, 0.0))
        return math.atan(c1) - c2 * c1 - phi + c2 * math.tan(phi) - c3 + math.atan(c3)

    lo = max(rb, rp - b) * (1.0 + 1e-12)
    rf = brentq(test, lo, rp, xtol=1e-15, rtol=1e-14)
    if grid > 0.0:
        rf = rb + math.ceil((rf - rb) / grid) * grid
    return rf


def involute_geometry(
    mesh: InvoluteMesh,
    driver: str | None = None,
    alpha_fin: float | None = None,
    legacy: bool = False,
    rasfact: float = 0.883,
) -> InvoluteGeometry:
    """Geometry and contact phases of an involute mesh (Tepper 1981, eqs. 1-45, Figs. 7-8).

    driver: "pinion" (ISAD1) or "gear" (ISAD2); default, as the published run.
    alpha_fin: override of the end of dual contact [rad] (Appendix E used 13.948 deg).
    legacy: reproduce the 1981 printout: the programs' pi = 3.14159 in the base pitch and
        INNERF's 1e-6 in search grid for r_f (last printed digit only).
    """
    driver = driver or mesh.driver
    if driver not in ("pinion", "gear"):
        raise ValueError(f"driver must be 'pinion' or 'gear', not {driver!r}")
    pi = LEGACY_PI if legacy else math.pi
    phi = mesh.pressure_angle
    rg, rp = mesh.gear_pitch_radius, mesh.pinion_pitch_radius
    big_rb, rb = rg * math.cos(phi), rp * math.cos(phi)
    pb = 2.0 * pi * rb / mesh.n_pinion
    b = (1.2 / mesh.diametral_pitch + 0.002) * INCH - mesh.hob_tip_radius * (1.0 - math.sin(phi))
    rf = inner_form_radius(rb, rp, b, phi, 1e-6 * INCH if legacy else 0.0)
    undercut = (1.0 - b / rp) <= rasfact  # standard pitch radius (eqs. 37/38)
    cd = mesh.center_distance
    op = math.acos((rg + rp) * math.cos(phi) / cd)  # eq. 45
    scale = cd / (rg + rp)
    tan_op = math.tan(op)
    big_ro, ro = mesh.gear_outside_radius, mesh.pinion_outside_radius
    s_gear = math.sqrt(big_ro**2 - big_rb**2)
    s_pin = math.sqrt(ro**2 - rb**2)
    s_form = math.sqrt(rf**2 - rb**2)
    pz_form = rb * tan_op - s_form  # eq. 4
    pz_tip = s_gear - big_rb * tan_op  # eq. 8
    tip_branch = pz_form > pz_tip  # the programs' IF(PZP.GT.PZ)
    path = s_gear + s_pin - (big_rb + rb) * tan_op if tip_branch else s_pin - s_form  # 18 / 22
    d = (big_rb + rb) * tan_op
    if driver == "pinion":
        r_drv, r_dvn, p_drv, p_dvn = rb, big_rb, mesh.pinion_pivot_radius, mesh.gear_pivot_radius
        a_in = (d - s_gear) / rb if tip_branch else s_form / rb  # eqs. 11 / 13
    else:
        r_drv, r_dvn, p_drv, p_dvn = big_rb, rb, mesh.gear_pivot_radius, mesh.pinion_pivot_radius
        a_in = (d - s_pin) / big_rb  # eqs. 27, 28
    a_fin = a_in + (path - pb) / r_drv  # eqs. 17–23, 32, 33
    return InvoluteGeometry(
        big_rb, rb, pb, rf, b, undercut, op, rg * scale, rp * scale, path / pb, tip_branch,
        a_in, a_fin if alpha_fin is None else alpha_fin, a_fin, d, r_drv, r_dvn, p_drv, p_dvn,
        driver == "pinion",
    )  # fmt: skip


# ------------------------------------------------------------------------------------------
# Involute point and cycle efficiency
# ------------------------------------------------------------------------------------------
def _signum(alpha: float, tan_op: float) -> float:
    """Eq. B3: +1 in approach (before the pitch point), -1 in recess, 0 at it."""
    return 1.0 if alpha < tan_op else (-1.0 if alpha > tan_op else 0.0)


def involute_point_efficiency(geom: InvoluteGeometry, mu: float, alpha1: float) -> float:
    """Point efficiency at driver roll angle alpha1 [rad] (eqs. 46/47 dual, A-26 single)."""
    r1, r2 = geom.driver_base_radius, geom.driven_base_radius
    rho1, rho2 = geom.driver_pivot_radius, geom.driven_pivot_radius
    tan_op = math.tan(geom.op_pressure_angle)
    d = geom.d
    a1 = r1 * alpha1
    s1 = _signum(alpha1, tan_op)
    if alpha1 <= geom.alpha_fin:  # dual contact, equal load sharing
        alpha2 = alpha1 + geom.base_pitch / r1
        a2 = a1 + geom.base_pitch
        s2 = _signum(alpha2, tan_op)
        s = s1 + s2
        # pivot normal force over F_C: Q / (1 + mu^2) (App. B, B6-B13); mu^4 as the
        # derivation gives, where the ISAD listings print mu^3
        q = math.sqrt(4.0 + mu * mu * (4.0 + s * s) + mu**4 * s * s) / (1.0 + mu * mu)
        num = 2.0 - mu * (s1 * (d - a1) + s2 * (d - a2)) / r2 - mu * rho2 * q / r2
        den = 2.0 - mu * (s1 * a1 + s2 * a2) / r1 + mu * rho1 * q / r1
        return num / den
    return (1.0 - mu * (rho2 + s1 * (d - a1)) / r2) / (1.0 + mu * (rho1 - s1 * a1) / r1)


def involute_efficiency_at(geom: InvoluteGeometry, mu: float, driver_angle: float) -> float:
    """Point efficiency at any driver roll angle [rad]: the base-pitch cycle repeats."""
    alpha = geom.alpha_in + (driver_angle - geom.alpha_in) % geom.cycle_angle
    return involute_point_efficiency(geom, mu, alpha)


def involute_cycle(
    geom: InvoluteGeometry, mu: float, k: int = 25
) -> tuple[np.ndarray, np.ndarray, float, float]:
    """The report's K-point cycle: (driver angles [rad], point efficiencies, cycle, minimum).

    The cycle efficiency is the left-rectangle mean of the K points (eqs. 51/52).
    """
    step = geom.cycle_angle / k
    alphas = geom.alpha_in + step * np.arange(k)
    eff = np.array([involute_point_efficiency(geom, mu, a) for a in alphas])
    return alphas, eff, float(eff.mean()), float(eff.min())


def involute_efficiency_curve(
    geom: InvoluteGeometry, mu: float, n: int = 400
) -> tuple[np.ndarray, np.ndarray]:
    """Point efficiency against driver angle [rad] over one base pitch, densely sampled."""
    alphas = geom.alpha_in + geom.cycle_angle * np.arange(n) / n
    return alphas, np.array([involute_point_efficiency(geom, mu, a) for a in alphas])


def involute_sweep(
    geom: InvoluteGeometry, mus: tuple[float, ...] = MU_SWEEP, k: int = 25
) -> tuple[np.ndarray, np.ndarray]:
    """(cycle efficiency, minimum point efficiency) for each mu (report Figs. 10–18)."""
    res = [involute_cycle(geom, mu, k)[2:] for mu in mus]
    return np.array([r[0] for r in res]), np.array([r[1] for r in res])


# ------------------------------------------------------------------------------------------
# General single-contact statics (derived here) and the derived clock round-on-round model
# ------------------------------------------------------------------------------------------
def _cross(a: np.ndarray, b: np.ndarray) -> float:
    return float(a[0] * b[1] - a[1] * b[0])


def contact_efficiency(
    o1: np.ndarray,
    o2: np.ndarray,
    contact: np.ndarray,
    normal: np.ndarray,
    mu: float,
    rho1: float,
    rho2: float,
    omega1: float = 1.0,
) -> tuple[float, float]:
    """Point efficiency and speed ratio omega2/omega1 of one contact, driver 1 -> driven 2.

    normal: unit normal of the force the driver exerts on the driven member.  The Coulomb
    force acts along the driver's sliding velocity relative to the driven surface; each pivot
    adds a resisting moment mu rho |N| (N the pivot normal reaction, which equals the contact
    normal force for one contact, as in ref. 1 eq. A-26 of
    Tepper 1981).  Efficiency = output power / input power.
    """
    r1, r2 = contact - o1, contact - o2
    ratio = _cross(r1, normal) / _cross(r2, normal)  # equal normal velocities
    omega2 = omega1 * ratio
    v_rel = omega1 * np.array([-r1[1], r1[0]]) - omega2 * np.array([-r2[1], r2[0]])
    speed = math.hypot(v_rel[0], v_rel[1])
    tang = v_rel / speed if speed > 1e-14 * math.hypot(r1[0], r1[1]) * abs(omega1) else 0 * v_rel
    force = normal + mu * tang  # per unit normal force, on the driven member
    m_in = math.copysign(1.0, omega1) * _cross(r1, force) + mu * rho1
    m_out = math.copysign(1.0, omega2) * _cross(r2, force) - mu * rho2
    return (m_out * abs(omega2)) / (m_in * abs(omega1)), ratio


def _near_pi(angle: float) -> float:
    """Angle in [0, 2 pi): pinion leaves that face the gear point near pi (no atan2 wrap)."""
    return math.remainder(angle - math.pi, 2.0 * math.pi) + math.pi


def _unit(angle: float) -> np.ndarray:
    return np.array([math.cos(angle), math.sin(angle)])


@dataclass(frozen=True)
class ClockContact:
    gear_angle: float  # rad, gear tooth 0 centreline (CCW from the line of centres)
    pinion_angle: float  # rad, pinion leaf 0 centreline about its own pivot
    pair: int  # gear tooth index of the active pair
    contact: np.ndarray  # m, contact point (gear pivot at the origin, pinion pivot on +x)
    normal: np.ndarray  # unit normal of the force on the pinion
    phase: str  # "ror" round-on-round, "rof" gear round on pinion flank, "for" the reverse


class ClockMeshModel:
    """Clock mesh with constant-curvature teeth, gear driving counter-clockwise (derived model).

    Gear pivot at the origin, pinion pivot at (b, 0).  Gear tooth j has its centreline at
    phi + j 2pi/N_G; its driving (CCW-side) flank is an arc of radius rho_G centred on the other
    side of the centreline, at distance a_G from the pivot (App. A geometry, C_x = rho - t/2).
    The driven (CCW-side) flank of pinion leaf k, centreline psi - k 2pi/N_P, is the mirror image,
    continued below its arc centre by a straight flank (round-on-flank contact).
    """

    def __init__(self, mesh: ClockMeshData, center_distance: float | None = None) -> None:
        self.mesh = mesh
        self.b = center_distance or (mesh.gear_pitch_radius + mesh.pinion_pitch_radius)
        cx_g = mesh.gear_arc_radius - 0.5 * mesh.gear_tooth_thickness
        cx_p = mesh.pinion_arc_radius - 0.5 * mesh.pinion_tooth_thickness
        self.delta_g = math.asin(cx_g / mesh.gear_center_distance)
        self.delta_p = math.asin(cx_p / mesh.pinion_center_distance)
        self.pitch_g = 2.0 * math.pi / mesh.n_gear
        self.pitch_p = 2.0 * math.pi / mesh.n_pinion
        self.length = mesh.gear_arc_radius + mesh.pinion_arc_radius  # coupler of the four-bar
        self.o_p = np.array([self.b, 0.0])
        self.arc_center_radius_p = math.sqrt(mesh.pinion_center_distance**2 - cx_p**2)
        self.arc_center_radius_g = math.sqrt(mesh.gear_center_distance**2 - cx_g**2)

    def _pair(self, phi: float, j: int) -> tuple[float, np.ndarray, np.ndarray, str] | None:
        """Pinion reference angle implied by gear tooth j in contact (the leaf -j), or None.

        Each profile is its arc above the arc centre (App. A) continued tangentially below it
        by a straight flank at t/2 from the tooth centreline.  Three contact phases follow:
        round-on-round ("ror", a four-bar), gear round on pinion flank ("rof") and pinion round
        on gear flank ("for").  Of the valid ones, the most retarding pinion angle holds.
        """
        m = self.mesh
        tooth = phi + j * self.pitch_g
        e_g = _unit(tooth)
        n_g = np.array([-e_g[1], e_g[0]])  # towards the gear's working flank
        c_g = m.gear_center_distance * _unit(tooth - self.delta_g)
        rel = c_g - self.o_p
        dist = math.hypot(rel[0], rel[1])
        base = math.atan2(rel[1], rel[0])
        a_p, length = m.pinion_center_distance, self.length
        candidates = []

        def on_gear_arc(contact: np.ndarray) -> bool:
            return _cross(e_g, contact) >= 0.0 and e_g @ (contact - c_g) >= 0.0

        def on_pinion_arc(contact: np.ndarray, c_p: np.ndarray, e_p: np.ndarray) -> bool:
            return _cross(e_p, contact - self.o_p) >= 0.0 and e_p @ (contact - c_p) >= 0.0

        cos_t = (a_p**2 + dist**2 - length**2) / (2.0 * a_p * dist)
        if abs(cos_t) <= 1.0:
            for sign in (1.0, -1.0):
                c_p = self.o_p + a_p * _unit(base + sign * math.acos(cos_t))
                normal = (c_p - c_g) / length
                ang_p = _near_pi(math.atan2(c_p[1], c_p[0] - self.b) + self.delta_p)
                contact = c_g + m.gear_arc_radius * normal
                if on_gear_arc(contact) and on_pinion_arc(contact, c_p, _unit(ang_p)):
                    candidates.append((ang_p, contact, normal, "ror"))
        offset = m.gear_arc_radius + 0.5 * m.pinion_tooth_thickness
        if offset < dist:
            ang_p = _near_pi(base - math.asin(offset / dist))
            e_p = _unit(ang_p)
            n_flank = np.array([-e_p[1], e_p[0]])
            contact = c_g - m.gear_arc_radius * n_flank
            along = e_p @ (contact - self.o_p)
            if 0.0 <= along <= self.arc_center_radius_p and on_gear_arc(contact):
                candidates.append((ang_p, contact, -n_flank, "rof"))
        # pinion round on the gear flank: C_P at rho_P + t_G/2 from the gear centreline
        k = (m.pinion_arc_radius + 0.5 * m.gear_tooth_thickness - _cross(e_g, self.o_p)) / a_p
        if abs(k) <= 1.0:
            for psi in (math.asin(k), math.pi - math.asin(k)):
                c_p = self.o_p + a_p * _unit(tooth + psi)
                ang_p = _near_pi(tooth + psi + self.delta_p)
                contact = c_p - m.pinion_arc_radius * n_g
                along = e_g @ contact
                if 0.0 <= along <= self.arc_center_radius_g and on_pinion_arc(
                    contact, c_p, _unit(ang_p)
                ):
                    candidates.append((ang_p, contact, n_g, "for"))
        best = None
        for ang_p, contact, normal, phase in candidates:
            ref = ang_p + j * self.pitch_p
            if best is None or ref < best[0]:
                best = (ref, contact, normal, phase)
        return best

    def contact(self, phi: float) -> ClockContact | None:
        """Active contact at gear angle phi: the pair that holds the pinion furthest back."""
        best, pair = None, 0
        j0 = -round(phi / self.pitch_g)
        for j in range(j0 - 2, j0 + 3):
            res = self._pair(phi, j)
            if res is not None and (best is None or res[0] < best[0]):
                best, pair = res, j
        if best is None:
            return None
        return ClockContact(phi, best[0], pair, best[1], best[2], best[3])

    def point_efficiency(self, mu: float, phi: float) -> tuple[float, float]:
        """(point efficiency, speed ratio omega_P/omega_G) at gear angle phi; nan if no contact."""
        c = self.contact(phi)
        if c is None:
            return math.nan, math.nan
        m = self.mesh
        return contact_efficiency(
            np.zeros(2), self.o_p, c.contact, c.normal, mu, m.gear_pivot_radius,
            m.pinion_pivot_radius,
        )  # fmt: skip

    def cycle(self, mu: float, n: int = 200) -> tuple[np.ndarray, np.ndarray, float, float]:
        """(gear angles, point efficiencies, cycle mean, minimum) over one gear tooth pitch."""
        phis = self.pitch_g * (np.arange(n) / n - 0.5)
        eff = np.array([self.point_efficiency(mu, p)[0] for p in phis])
        return phis, eff, float(np.mean(eff)), float(np.min(eff))


def clock_sweep(
    mesh: ClockMeshData, mus: tuple[float, ...] = MU_SWEEP, n: int = 200
) -> tuple[np.ndarray, np.ndarray]:
    """(cycle efficiency, minimum point efficiency) of a clock mesh for each mu (Figs. 3–6)."""
    model = ClockMeshModel(mesh)
    res = [model.cycle(mu, n)[2:] for mu in mus]
    return np.array([r[0] for r in res]), np.array([r[1] for r in res])


# ------------------------------------------------------------------------------------------
# A cycle at constant load torque: contact phases, input work, extremes
# ------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class CycleSummary:
    """One mesh cycle driven at a set speed against a constant load torque.

    work_efficiency: output work / input work.  The driver torque is load * ratio / eps, so
        this is the ratio-weighted harmonic mean of the point efficiency, not the report's
        CYCLEFF (the arithmetic mean of K points, which holds for a constant driver torque).
    mean_efficiency: the driver-angle mean of the point efficiency (CYCLEFF as K -> infinity).
    minimum, maximum: the extremes over the cycle, one-sided limits at the phase changes
        included (the report's minimum is that of its K points).
    mean_ratio: driven rotation per driver rotation over the cycle.
    """

    work_efficiency: float
    mean_efficiency: float
    minimum: float
    maximum: float
    mean_ratio: float


def involute_phase_breaks(geom: InvoluteGeometry) -> tuple[float, float, float]:
    """Driver angles [rad] in [alpha_in, alpha_in + cycle) where the contact phase changes:
    (a new pair enters, end of dual contact, a pair crosses the pitch point)."""
    a0, c = geom.alpha_in, geom.cycle_angle
    if not a0 < geom.alpha_fin < a0 + c:
        raise ValueError("end of dual contact outside the cycle: contact ratio not in (1, 2)")
    return a0, geom.alpha_fin, a0 + (math.tan(geom.op_pressure_angle) - a0) % c


def involute_linear_terms(
    geom: InvoluteGeometry, mu: float, alpha1: float
) -> tuple[float, float, float, float]:
    """(n0, n1, d0, d1): the point efficiency is (n0 + n1 a) / (d0 + d1 a) for every driver
    roll angle a [rad] of the contact phase of alpha1 (same pairs, same approach/recess signs).

    Eqs. 46/47 and A-26 are linear in a1 = r_drv a and a2 = a1 + p_b within a phase, which makes
    the cycle integrals closed-form.
    """
    r1, r2 = geom.driver_base_radius, geom.driven_base_radius
    rho1, rho2 = geom.driver_pivot_radius, geom.driven_pivot_radius
    tan_op, d, pb = math.tan(geom.op_pressure_angle), geom.d, geom.base_pitch
    s1 = _signum(alpha1, tan_op)
    if alpha1 <= geom.alpha_fin:
        s2 = _signum(alpha1 + pb / r1, tan_op)
        s = s1 + s2
        q = math.sqrt(4.0 + mu * mu * (4.0 + s * s) + mu**4 * s * s) / (1.0 + mu * mu)
        return (
            2.0 - mu * (s * d - s2 * pb + rho2 * q) / r2,
            mu * s * r1 / r2,
            2.0 + mu * (rho1 * q - s2 * pb) / r1,
            -mu * s,
        )
    return 1.0 - mu * (rho2 + s1 * d) / r2, mu * s1 * r1 / r2, 1.0 + mu * rho1 / r1, -mu * s1


def _integral_linear_ratio(p0: float, p1: float, q0: float, q1: float, a: float, b: float) -> float:
    """Integral of (p0 + p1 x) / (q0 + q1 x) over [a, b], the denominator keeping its sign."""
    qa = q0 + q1 * a
    if q1 == 0.0:
        return (p0 * (b - a) + 0.5 * p1 * (b * b - a * a)) / q0
    k = p1 / q1  # numerator = k * denominator + (p0 - k q0)
    return k * (b - a) + (p0 - k * q0) * math.log1p(q1 * (b - a) / qa) / q1


def involute_cycle_summary(geom: InvoluteGeometry, mu: float) -> CycleSummary:
    """Closed-form CycleSummary of an involute mesh (constant speed ratio r_drv / r_dvn)."""
    breaks = sorted(involute_phase_breaks(geom))
    ends = [*breaks, geom.alpha_in + geom.cycle_angle]
    inv_eff = mean = 0.0
    values = []
    for a, b in zip(ends[:-1], ends[1:], strict=True):
        if b <= a:
            continue
        n0, n1, d0, d1 = involute_linear_terms(geom, mu, 0.5 * (a + b))
        if min(n0 + n1 * a, n0 + n1 * b) <= 0.0:
            raise ValueError(f"point efficiency reaches zero with mu = {mu}: the mesh locks")
        inv_eff += _integral_linear_ratio(d0, d1, n0, n1, a, b)
        mean += _integral_linear_ratio(n0, n1, d0, d1, a, b)
        values += [(n0 + n1 * a) / (d0 + d1 * a), (n0 + n1 * b) / (d0 + d1 * b)]
    c = geom.cycle_angle
    ratio = geom.driver_base_radius / geom.driven_base_radius
    return CycleSummary(c / inv_eff, mean / c, min(values), max(values), ratio)


# ------------------------------------------------------------------------------------------
# The derived clock efficiency on the two-pass train kinematics (components.clock_train_kinematics)
# ------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class TrainMeshContact:
    """Contact of a clock_train mesh at one gear angle, in the mesh-1 convention of that
    module (gear pivot at the origin turning counter-clockwise, pinion pivot at b e^(i beta1))."""

    phase: str  # "ror" round-on-round (four-bar), "rof" gear round on the radial pinion flank
    local_angle: float  # rad, gear angle moved into the pair window [handover - pitch, handover)
    pinion_angle: float  # rad, pinion angle with every earlier pair counted (continuous)
    ratio: float  # d pinion / d gear (negative: external mesh)
    pinion_pivot: np.ndarray  # m
    contact: np.ndarray  # m
    normal: np.ndarray  # unit normal of the force on the pinion


def train_mesh_window(mesh: ClockMesh) -> tuple[float, float]:
    """(start, length) of a tooth pair's window of gear angles, mesh-1 convention [rad]: the
    pair takes over at handover - pitch and hands over at handover."""
    pitch = 2.0 * math.pi / mesh.n_gear
    return mesh.handover() - pitch, pitch


def _train_pair_contact(mesh: ClockMesh, local: float, phase: str) -> TrainMeshContact:
    """Contact of the pair at gear angle ``local`` of its window, phase given (no reduction)."""
    s = -1.0 if mesh.mirrored else 1.0
    x = s * mesh.driven_angle(s * local, phase)  # pinion angle, mesh-1 convention
    ratio = mesh.speed_ratio(s * local, phase)
    o_p = mesh.b * _unit(mesh.beta1)
    c_g = mesh.a_g * _unit(local - mesh.delta_g)
    if phase == "ror":  # the normal joins the two centres of curvature
        normal = o_p + mesh.a_p * _unit(x - mesh.delta_p) - c_g
        normal /= math.hypot(normal[0], normal[1])
    else:  # square to the radial flank, through the gear round's centre
        e = _unit(x + mesh.alpha_p)
        m = np.array([-e[1], e[0]])
        normal = -math.copysign(1.0, float(m @ (c_g - o_p))) * m
    return TrainMeshContact(phase, local, x, ratio, o_p, c_g + mesh.rho_g * normal, normal)


def train_mesh_contact(mesh: ClockMesh, phi1: float) -> TrainMeshContact:
    """Contact at gear angle phi1 [rad] (mesh-1 convention), any tooth pair."""
    start, pitch = train_mesh_window(mesh)
    k = math.floor((phi1 - start) / pitch)
    local = phi1 - k * pitch
    phase = "ror" if local < mesh.transition()[0] else "rof"
    c = _train_pair_contact(mesh, local, phase)
    lead = 2.0 * math.pi / mesh.n_pinion
    return TrainMeshContact(
        phase, local, c.pinion_angle - k * lead, c.ratio, c.pinion_pivot, c.contact, c.normal
    )


def train_contact_efficiency(c: TrainMeshContact, mu: float, rho_g: float, rho_p: float) -> float:
    """Point efficiency of a train_mesh_contact result (pivot radii rho_g, rho_p [m])."""
    return contact_efficiency(np.zeros(2), c.pinion_pivot, c.contact, c.normal, mu, rho_g, rho_p)[0]


def train_mesh_efficiency(
    mesh: ClockMesh, mu: float, phi1: float, rho_gear: float, rho_pinion: float
) -> tuple[float, float]:
    """(point efficiency, speed ratio d pinion / d gear) at gear angle phi1 (mesh-1 convention).

    The derived single-contact statics (the same as ClockMeshModel) on the kinematics of
    components.clock_train_kinematics: round-on-round, the normal through both round centres;
    round-on-flank, through the gear round's centre square to the radial flank.
    rho_*: pivot radii [m].
    """
    c = train_mesh_contact(mesh, phi1)
    return train_contact_efficiency(c, mu, rho_gear, rho_pinion), c.ratio


def _train_sliding(mesh: ClockMesh, local: float, phase: str) -> float:
    """Sliding speed of the gear over the pinion along the common tangent, per unit gear speed."""
    c = _train_pair_contact(mesh, local, phase)
    r1, r2 = c.contact, c.contact - c.pinion_pivot
    v = np.array([-r1[1], r1[0]]) - c.ratio * np.array([-r2[1], r2[0]])
    return _cross(c.normal, v)


def train_mesh_breaks(mesh: ClockMesh) -> tuple[tuple[float, str], ...]:
    """Gear angles [rad] (mesh-1 convention) of one window where the contact phase changes,
    sorted, with their kind: "pair" (a new pair takes over: the window start), "contact"
    (round-on-round -> round-on-flank) and "pitch" (the sliding reverses: the contact crosses
    the line of centres, approach -> recess)."""
    start, pitch = train_mesh_window(mesh)
    transition = mesh.transition()[0]
    breaks = [(start, "pair")]
    parts = [(start, start + pitch, "ror")]
    if start < transition < start + pitch:
        breaks.append((transition, "contact"))
        parts = [(start, transition, "ror"), (transition, start + pitch, "rof")]
    for a, b, phase in parts:
        grid = np.linspace(a, b, 65)
        values = [_train_sliding(mesh, float(x), phase) for x in grid]
        for k in range(64):
            if values[k] == 0.0 or values[k] * values[k + 1] < 0.0:
                root = brentq(
                    lambda x, ph=phase: _train_sliding(mesh, x, ph),
                    float(grid[k]), float(grid[k + 1]), xtol=1e-15, rtol=1e-15,
                )  # fmt: skip
                if a < root < b:
                    breaks.append((root, "pitch"))
    return tuple(sorted(breaks))


def train_mesh_cycle_summary(
    mesh: ClockMesh, mu: float, rho_gear: float, rho_pinion: float
) -> CycleSummary:
    """CycleSummary of a clock_train mesh over one pair window (adaptive quadrature per phase).

    The extremes are taken on a dense grid and 1e-9 of the window inside each phase change (the
    efficiency jumps there; at the reversal itself the sliding friction is undefined).
    """
    from scipy.integrate import quad

    start, pitch = train_mesh_window(mesh)
    breaks = [b for b, _ in train_mesh_breaks(mesh)]
    ends = [*breaks, start + pitch]
    transition = mesh.transition()[0]
    inv_eff = mean = 0.0
    values = []
    for a, b in zip(ends[:-1], ends[1:], strict=True):
        phase = "ror" if 0.5 * (a + b) < transition else "rof"

        def eff(x: float, phase: str = phase) -> float:
            return train_contact_efficiency(
                _train_pair_contact(mesh, x, phase), mu, rho_gear, rho_pinion
            )

        def ratio(x: float, phase: str = phase) -> float:
            return -mesh.speed_ratio((-1.0 if mesh.mirrored else 1.0) * x, phase)

        kw = {"epsabs": 0.0, "epsrel": 1e-13, "limit": 200}
        inv_eff += quad(lambda x: ratio(x) / eff(x), a, b, **kw)[0]
        mean += quad(eff, a, b, **kw)[0]
        eps = 1e-9 * pitch
        values += [eff(float(x)) for x in np.linspace(a + eps, b - eps, 201)]
    if min(values) <= 0.0:
        raise ValueError(f"point efficiency reaches zero with mu = {mu}: the mesh locks")
    turned = 2.0 * math.pi / mesh.n_pinion  # one leaf per gear pitch
    return CycleSummary(turned / inv_eff, mean / pitch, min(values), max(values), turned / pitch)


# ------------------------------------------------------------------------------------------
# Contact phases and a cycle at constant load of a Tables 1-4 clock mesh (ClockMeshModel)
# ------------------------------------------------------------------------------------------
def _clock_table_sliding(model: ClockMeshModel, phi: float) -> float:
    """Sliding speed of the gear over the pinion along the common tangent, per unit gear speed
    (zero at the pitch point, where the contact crosses the line of centres)."""
    c = model.contact(phi)
    r1, r2 = c.contact, c.contact - model.o_p
    ratio = _cross(r1, c.normal) / _cross(r2, c.normal)
    v = np.array([-r1[1], r1[0]]) - ratio * np.array([-r2[1], r2[0]])
    return _cross(c.normal, v)


def clock_table_breaks(model: ClockMeshModel) -> tuple[tuple[float, str, str, bool], ...]:
    """Gear angles [rad] of one gear pitch where the contact of a Tables 1-4 clock mesh changes:
    (angle, kind, phase of the piece it opens, approach), sorted, the first being where a new
    pair takes over ("pair"); "contact": round-on-round / round-on-flank / flank-on-round
    changes; "pitch": the sliding reverses at the line of centres.  Approach: the contact lies
    before the line of centres (the gear turns counter-clockwise, the pinion pivot on +x)."""
    pitch = model.pitch_g

    def tag(phi: float) -> tuple[int, str]:
        c = model.contact(phi)
        if c is None:
            raise ValueError(f"no pair in contact at gear angle {phi!r} rad")
        return c.pair, c.phase

    def boundary(lo: float, hi: float) -> float:
        t_lo = tag(lo)
        for _ in range(80):
            mid = 0.5 * (lo + hi)
            if mid in (lo, hi):
                break
            lo, hi = (mid, hi) if tag(mid) == t_lo else (lo, mid)
        return hi

    n = 128
    grid = [pitch * (k / n - 0.5) for k in range(n + 1)]
    tags = [tag(x) for x in grid]
    changes = []
    for k in range(n):
        if tags[k] != tags[k + 1]:
            kind = "pair" if tags[k][0] != tags[k + 1][0] else "contact"
            changes.append((boundary(grid[k], grid[k + 1]), kind))
    starts = [x for x, kind in changes if kind == "pair"]
    if len(starts) != 1:
        raise ValueError(f"expected one change of tooth pair per gear pitch, found {len(starts)}")
    start = starts[0]
    found = [(start + (x - start) % pitch, kind) for x, kind in changes]
    ends = [x for x, _ in sorted(found)] + [start + pitch]
    for a, b in zip(ends[:-1], ends[1:], strict=True):
        eps = 1e-9 * pitch
        xs = np.linspace(a + eps, b - eps, 33)
        values = [_clock_table_sliding(model, float(x)) for x in xs]
        for k in range(32):
            if values[k] * values[k + 1] < 0.0:
                root = brentq(
                    lambda x: _clock_table_sliding(model, x), float(xs[k]), float(xs[k + 1]),
                    xtol=1e-15, rtol=1e-15,
                )  # fmt: skip
                found.append((root, "pitch"))
    found.sort()
    ends = [x for x, _ in found] + [start + pitch]
    out = []
    for (x, kind), b in zip(found, ends[1:], strict=True):
        c = model.contact(0.5 * (x + b))
        out.append((x, kind, c.phase, bool(c.contact[1] < 0.0)))
    return tuple(out)


def clock_table_cycle_summary(model: ClockMeshModel, mu: float) -> CycleSummary:
    """CycleSummary of a Tables 1-4 clock mesh over one gear pitch from a new pair's takeover
    (adaptive quadrature per contact phase; extremes 1e-9 of the pitch inside each)."""
    from scipy.integrate import quad

    breaks = [b[0] for b in clock_table_breaks(model)]
    pitch = model.pitch_g
    ends = [*breaks, breaks[0] + pitch]
    m = model.mesh
    rho_g, rho_p = m.gear_pivot_radius, m.pinion_pivot_radius

    def point(x: float) -> tuple[float, float]:
        c = model.contact(x)
        return contact_efficiency(np.zeros(2), model.o_p, c.contact, c.normal, mu, rho_g, rho_p)

    inv_eff = mean = 0.0
    values = []
    kw = {"epsabs": 0.0, "epsrel": 1e-13, "limit": 200}
    for a, b in zip(ends[:-1], ends[1:], strict=True):
        inv_eff += quad(lambda x: -point(x)[1] / point(x)[0], a, b, **kw)[0]
        mean += quad(lambda x: point(x)[0], a, b, **kw)[0]
        eps = 1e-9 * pitch
        values += [point(float(x))[0] for x in np.linspace(a + eps, b - eps, 201)]
    if min(values) <= 0.0:
        raise ValueError(f"point efficiency reaches zero with mu = {mu}: the mesh locks")
    return CycleSummary(model.pitch_p / inv_eff, mean / pitch, min(values), max(values),
                        model.pitch_p / pitch)  # fmt: skip
