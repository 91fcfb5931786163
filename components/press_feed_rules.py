"""Consistency rules of a press-feed design (Xu 1993, Table 1, Table 4, App. A, Part I §9).

Each rule returns the broken ones as ``Violation`` (components.design_rules), quantities in
inches and degrees as Table 1 prints them.  The drive refuses a broken linkage or coupler and
the clutch a broken sprag geometry at initialization; the press-feed scene check lists them
all when a scene loads.  The brake-torque rule is a note, not a refusal: a brake below the
engagement minimum lets the roller overrun the rocker (a design one may want to study).
"""

from __future__ import annotations

import math

import numpy as np

from .design_rules import Violation, degrees, inches
from .press_feed_data import BentCoupler, RSSRLinkage, SpragGeometry
from .units import INCH, LBF_IN

#: Crank angles sampled over a turn for the assembly rule.
N_SAMPLES = 720
#: a3 = 2 L cos(alpha) within this relative tolerance (Table 1 prints a3 to 1e-5 of it).
CHORD_TOLERANCE = 1.0e-4


def assembly_violations(lk: RSSRLinkage, alpha: float) -> list[Violation]:
    """The RSSR closes (A.8: A^2 + B^2 - C^2 > 0) and the bent coupler's frame exists
    (A.10: |a4 sin(phi4) - s1| < a3 cos(alpha)) at every sampled crank angle."""
    phi1 = np.arange(N_SAMPLES) * (2.0 * math.pi / N_SAMPLES)
    sp, cp = np.sin(phi1), np.cos(phi1)
    big_a = 2.0 * lk.s1 * lk.a4
    big_b = 2.0 * lk.a4 * (lk.s3 + lk.a1 * sp)
    big_c = (lk.a4**2 + lk.s1**2 + lk.s2**2 + lk.s3**2 + lk.a1**2 - lk.a3**2) + 2.0 * lk.a1 * (
        lk.s2 * cp + lk.s3 * sp
    )
    disc = big_a**2 + big_b**2 - big_c**2
    dims = (
        f"{inches('a1', lk.a1, 3)}, {inches('a3', lk.a3, 3)}, {inches('a4', lk.a4, 3)}, "
        f"{inches('s1', lk.s1, 3)}, {inches('s2', lk.s2, 3)}, {inches('s3', lk.s3, 3)}"
    )
    bad = ~(disc > 0.0)
    if bad.any():
        k = int(np.argmin(np.where(np.isfinite(disc), disc, -np.inf)))
        return [
            Violation(
                "RSSR assembly",
                f"{dims}: the loop (A.8) does not close at {int(bad.sum())} of {N_SAMPLES} "
                f"crank angles (first at {degrees('phi1', phi1[k], 1)}); expected "
                "A^2 + B^2 - C^2 > 0 at every crank angle",
            )
        ]
    phi4 = 2.0 * np.arctan((big_a + np.sqrt(disc)) / (big_b + big_c))
    reach = np.abs(lk.a4 * np.sin(phi4) - lk.s1) / (lk.a3 * math.cos(alpha))
    if not (reach < 1.0).all():
        k = int(np.argmax(reach))
        return [
            Violation(
                "RSSR assembly",
                f"{dims}, {degrees('alpha', alpha)}: at {degrees('phi1', phi1[k], 1)} "
                f"|a4 sin(phi4) - s1| = {reach[k]:.4f} a3 cos(alpha); expected below "
                "a3 cos(alpha) (A.10) at every crank angle",
            )
        ]
    return []


def chord_violations(lk: RSSRLinkage, c: BentCoupler) -> list[Violation]:
    """The bent coupler's chord is the linkage's: a3 = 2 L cos(alpha) (Part I §4)."""
    chord = 2.0 * c.length * math.cos(c.alpha)
    if abs(lk.a3 - chord) <= CHORD_TOLERANCE * chord:
        return []
    return [
        Violation(
            "coupler chord",
            f"{inches('a3', lk.a3)} against 2 L cos(alpha) = {chord / INCH:.5f} in "
            f"({inches('L', c.length)}, {degrees('alpha', c.alpha)}); expected equal "
            f"within {CHORD_TOLERANCE:.0e} (relative)",
        )
    ]


def tube_violations(c: BentCoupler) -> list[Violation]:
    """The coupler tube has a wall: D_i < D_o (Table 1)."""
    if c.d_inner < c.d_outer:
        return []
    return [
        Violation(
            "coupler tube",
            f"{inches('D_i', c.d_inner)} against {inches('D_o', c.d_outer)}; expected "
            "D_i < D_o (a tube with a wall)",
        )
    ]


def drive_violations(lk: RSSRLinkage, c: BentCoupler, elastic: bool) -> list[Violation]:
    """Every broken rule of the drive: the linkage assembles; an elastic coupler's chord and
    tube are consistent (a rigid coupler's L, alpha and tube are not used)."""
    out = assembly_violations(lk, c.alpha)
    if elastic:
        out += chord_violations(lk, c) + tube_violations(c)
    return out


def sprag_violations(s: SpragGeometry) -> list[Violation]:
    """The two-point Hertz formulas are real (Part III, L.18-L.19, M.10-M.11): R_i < R_o,
    R_s < R_o, and the sprag's curvature centres (offset a) reach both races: a, R_i + R_s
    and R_o - R_s are the sides of a triangle."""
    ri, ro, rs, a = s.r_inner, s.r_outer, s.r_sprag, s.offset
    radii = f"{inches('R_i', ri)}, {inches('R_o', ro)}, {inches('R_s', rs)}"
    if not ri < ro or not rs < ro:
        return [
            Violation(
                "sprag geometry",
                f"{radii}; expected R_i < R_o and R_s < R_o (the sprag between the races)",
            )
        ]
    inner, outer = ri + rs, ro - rs
    if not abs(outer - inner) < a < outer + inner:
        return [
            Violation(
                "sprag geometry",
                f"{radii}, {inches('a', a)}: |R_o - R_i - 2 R_s| = "
                f"{abs(outer - inner) / INCH:.5f} in; expected |R_o - R_i - 2 R_s| < a < "
                "R_o + R_i (the contact triangle of L.18-L.19, else its Hertz stiffness is not "
                "real)",
            )
        ]
    return []


def engagement_minimum(lk: RSSRLinkage, alpha: float, omega: float, j5: float) -> float:
    """The brake torque below which the roller overruns the rigid rocker as it slows on the
    feed stroke: J_o5 times its largest deceleration, J_o5 phi1dot^2 max(phi4r'') over the
    stroke [N.m] (a rigid-body lower bound of Xu's T(min), Part I §9, eqs 65-67)."""
    from .rssr_kinematics import ExactRSSR, rocker_extremes

    kin = ExactRSSR(lk, alpha)
    _, at_max, _, at_min = rocker_extremes(kin)
    span = (at_min - at_max) % (2.0 * math.pi)
    angles = at_max + np.linspace(0.0, span, 361)
    decel = max(kin(float(p))[2] for p in angles)  # phi4 falls on the stroke: phi4'' > 0 slows
    return j5 * omega * omega * max(decel, 0.0)


def brake_note(lk: RSSRLinkage, alpha: float, omega: float, j5: float, t_b: float) -> str | None:
    """A note when T_b is below the engagement minimum, else None."""
    t_min = engagement_minimum(lk, alpha, omega, j5)
    if t_b >= t_min:
        return None
    return (
        f"design note 'brake engagement minimum': T_b = {t_b / LBF_IN:.1f} lbf*in is below "
        f"J_o5 phi1dot^2 max(phi4r'') = {t_min / LBF_IN:.1f} lbf*in (J_o5 = "
        f"{j5 / LBF_IN:.4g} lbf*in*s^2, {omega / (2 * math.pi) * 60:.4g} rpm): the roller "
        "overruns the rocker before the feed stroke ends (Part I §9)"
    )
