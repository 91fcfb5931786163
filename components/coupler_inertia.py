"""The coupler's inertia functions P1, F1 and the lumped-mass factor, from the geometry.

Xu (1993), *Contributions to the Theory of Machine Dynamics*, App. A (A.2-A.18, A.30-A.42),
App. B (B.15, B.17, B.20) and App. G (G.3-G.9).  In (B.15) the coupler's mass per length
rhoA multiplies

    [(V2s1 + V2s2 + sin^2 2a) L + P1(phi1)] q''      and      F1(phi1) on the right side,

where, with ``w(x) = d r / d q`` the displacement of the coupler point x per unit q (the
bending shape plus the rotation of the coupler that the change of length AC' = a3 + 2 q
sin(alpha) (9) forces on it, A.39-A.42) and ``a(x)`` the acceleration of that point in the
rigid motion:

    (V2s1 + V2s2 + sin^2 2a) L + P1 = integral |w|^2 dx        (B.17 is this integral)
    F1 = - integral a . w dx                                   (B.20 is this integral)

The OCR of (B.20) is long and partly garbled, so both are computed here numerically from
the exact RSSR kinematics, not from the printed formulas: the loop (A.2-A.4) is closed
exactly for AC' = a3 +- 2 h sin(alpha) (A.8 with a3 -> AC', A.10, A.11), the coupler frame
(i1 along section 1, j1 in the bend plane, A.25) placed at each crank angle, and

* w by a central difference in q (it is linear in q up to O(q^2));
* a = phi1dot^2 d^2 r / d phi1^2 by spectral differentiation over one crank turn (the
  motion is periodic and smooth);
* the x integrals by Gauss-Legendre over each section (the integrands are smooth).

The P1 so computed agrees with (B.17) as printed (which drops only terms of relative size
1e-4); Run 1's regime-2 mean is 2.78 in (Table 1 a1), not the printed 2.65, and its F1
coefficients are within 0.5 % (a11, b11) and 3.5 % (a10) of App. H's (for a1 = 0.955 in, the
crank App. H was evidently computed with): see docs/press_feed_design.md.

App. G: a mass M clamped at B adds M |w_B|^2 = M (1 + Q1) (G.4) to the modal mass and
M F3 (G.7) to the forcing.  Xu replaces this by an equivalent density rho_M = f M / A with
f = 0.05 (G.9); computed here as the regime-2 mean of (1 + Q1) / [(V2s1 + V2s2 +
sin^2 2a) L + P1], so that the equivalent mass (19) carries the mass at B exactly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .press_feed_data import RSSRLinkage

#: Crank angles per turn (spectral differentiation), Gauss points per coupler section.
N_CRANK = 256
N_GAUSS = 16
#: Step in q of the central difference for w [m]: w is linear in q to O(q^2).
DQ = 1.0e-7


@dataclass(frozen=True)
class CouplerInertia:
    """What the coupler equation (B.15) takes from the geometry; SI."""

    p1: float  # regime-2 mean of P1 (B.17) [m]
    f1: tuple[float, float, float]  # a10, a11, b11 of F1/phi1dot^2 (B.20) [m^2]
    lumped_factor: float  # f of rho_M = f M / A (G.9) [1/m]
    damping_factor: float  # (3 - 8/pi) of the coupler damping (B.7) [1]


def shape_bracket(alpha: float) -> float:
    """(V2s1 + V2s2 + sin^2 2a) of (19), from (B.11-B.12) [1]."""
    c2a = math.cos(2.0 * alpha)
    v2s2 = c2a**2 - (2.0 - 4.0 / math.pi) * c2a + (1.5 - 4.0 / math.pi)
    return 0.5 + v2s2 + math.sin(2.0 * alpha) ** 2


def coupler_frame(
    lk: RSSRLinkage, alpha: float, phi1: np.ndarray, q: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(r_A, i1, j1) in the frame O1 X0 Y0 Z0 (A.31, A.25) for a chord AC' = a3 + 2 q sin a.

    Components along axis 0, crank angles along axis 1.  The rocker angle closes the loop
    exactly (A.8); phi32 (A.10) and phi2 follow from the chord direction (A.2-A.4).
    """
    ac = lk.a3 + 2.0 * q * math.sin(alpha)
    sp, cp = np.sin(phi1), np.cos(phi1)
    big_a = 2.0 * lk.s1 * lk.a4
    big_b = 2.0 * lk.a4 * (lk.s3 + lk.a1 * sp)
    big_c = (lk.a4**2 + lk.s1**2 + lk.s2**2 + lk.s3**2 + lk.a1**2 - ac**2) + 2.0 * lk.a1 * (
        lk.s2 * cp + lk.s3 * sp
    )
    phi4 = 2.0 * np.arctan((big_a + np.sqrt(big_a**2 + big_b**2 - big_c**2)) / (big_b + big_c))
    zero = np.zeros_like(phi1)
    r_a = np.stack([zero, lk.a1 * cp, lk.a1 * sp])
    r_c = np.stack([lk.a4 * np.sin(phi4) - lk.s1, zero - lk.s2, lk.a4 * np.cos(phi4) - lk.s3])
    u = (r_c - r_a) / ac  # chord direction = cos(a) i1 + sin(a) j1
    sa, ca = math.sin(alpha), math.cos(alpha)
    phi32 = np.arccos(np.clip(u[0] / ca, -1.0, 1.0))  # (A.10)
    r = ca * np.sin(phi32)
    den = r * r + sa * sa
    c2 = (-r * u[1] - sa * u[2]) / den  # cos(phi2), sin(phi2) from (A.3-A.4)
    s2 = (sa * u[1] - r * u[2]) / den
    i1 = np.stack([np.cos(phi32), -c2 * np.sin(phi32), -s2 * np.sin(phi32)])
    j1 = np.stack([zero, s2, -c2])
    return r_a, i1, j1


def coupler_points(
    lk: RSSRLinkage, alpha: float, length: float, phi1: np.ndarray, q: float, x: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Positions of the points x of sections 1 and 2 (A.30, A.32), shape (3, crank, x)."""
    r_a, i1, j1 = coupler_frame(lk, alpha, phi1, q)
    c2a, s2a = math.cos(2.0 * alpha), math.sin(2.0 * alpha)
    i2 = c2a * i1 + s2a * j1  # section 2 turns 2a from section 1 about k1 (A.26)
    j2 = -s2a * i1 + c2a * j1
    v1 = np.sin(math.pi * x / (2.0 * length))  # (6)
    v2 = c2a - 1.0 + np.cos(math.pi * x / (2.0 * length))  # (8)
    a, e1, f1, e2, f2 = (v[:, :, None] for v in (r_a, i1, j1, i2, j2))
    sec1 = a + x * e1 + q * v1 * f1  # (A.30), (5)
    sec2 = a + length * e1 + (x + q * s2a) * e2 + q * v2 * f2  # (A.32), (7)
    return sec1, sec2


def _second_derivative(r: np.ndarray) -> np.ndarray:
    """d^2 r / d phi1^2 of samples over one crank turn (axis 1), spectrally."""
    n = r.shape[1]
    k = np.fft.fftfreq(n, 1.0 / n)
    shape = [1] * r.ndim
    shape[1] = n
    return np.real(np.fft.ifft(-(k**2).reshape(shape) * np.fft.fft(r, axis=1), axis=1))


def inertia_functions(
    lk: RSSRLinkage, alpha: float, length: float, n: int = N_CRANK
) -> dict[str, np.ndarray]:
    """P1, F1/phi1dot^2, Q1 and F3/phi1dot^2 at n crank angles over one turn (SI)."""
    phi1 = np.arange(n) * (2.0 * math.pi / n)
    gx, gw = np.polynomial.legendre.leggauss(N_GAUSS)
    x, wx = 0.5 * length * (gx + 1.0), 0.5 * length * gw
    plus = coupler_points(lk, alpha, length, phi1, DQ, x)
    minus = coupler_points(lk, alpha, length, phi1, -DQ, x)
    rigid = coupler_points(lk, alpha, length, phi1, 0.0, x)
    w_sq = np.zeros(n)
    f1 = np.zeros(n)
    for sec in range(2):
        w = (plus[sec] - minus[sec]) / (2.0 * DQ)
        acc = _second_derivative(rigid[sec])
        w_sq += np.sum(np.sum(w * w, axis=0) * wx, axis=1)
        f1 -= np.sum(np.sum(acc * w, axis=0) * wx, axis=1)
    # The point B (x1 = L): App. G's mass.
    b_plus = _point_b(lk, alpha, length, phi1, DQ)
    b_minus = _point_b(lk, alpha, length, phi1, -DQ)
    w_b = (b_plus - b_minus) / (2.0 * DQ)
    acc_b = _second_derivative(_point_b(lk, alpha, length, phi1, 0.0))
    return {
        "phi1": phi1,
        "p1": w_sq - shape_bracket(alpha) * length,
        "f1": f1,
        "q1": np.sum(w_b * w_b, axis=0) - 1.0,
        "f3": -np.sum(acc_b * w_b, axis=0),
    }


def _point_b(lk: RSSRLinkage, alpha: float, length: float, phi1: np.ndarray, q: float):
    """Position of the bend B (x1 = L, V1 = 1) [m], shape (3, crank)."""
    r_a, i1, j1 = coupler_frame(lk, alpha, phi1, q)
    return r_a + length * i1 + q * j1


def feed_stroke(phi1: np.ndarray, phi1_max: float, phi1_min: float) -> np.ndarray:
    """Mask of the crank angles of the feed stroke (regime 2: rocker maximum to minimum)."""
    two_pi = 2.0 * math.pi
    return ((phi1 - phi1_max) % two_pi) <= ((phi1_min - phi1_max) % two_pi)


@lru_cache(maxsize=64)
def _computed(key: tuple[float, ...]) -> CouplerInertia:
    from .rssr_kinematics import ExactRSSR, rocker_extremes

    lk = RSSRLinkage(*key[:6])
    alpha, length = key[6], key[7]
    fn = inertia_functions(lk, alpha, length)
    phi1 = fn["phi1"]
    _, at_max, _, at_min = rocker_extremes(ExactRSSR(lk, alpha))
    stroke = feed_stroke(phi1, at_max, at_min)
    p1 = float(np.mean(fn["p1"][stroke]))
    f1 = fn["f1"]
    coeffs = (
        float(np.mean(f1)),
        float(2.0 * np.mean(f1 * np.cos(phi1))),
        float(2.0 * np.mean(f1 * np.sin(phi1))),
    )
    mass_b = (1.0 + fn["q1"]) / (shape_bracket(alpha) * length + fn["p1"])
    return CouplerInertia(
        p1=p1,
        f1=coeffs,
        lumped_factor=float(np.mean(mass_b[stroke])),
        damping_factor=3.0 - 8.0 / math.pi,
    )


def computed_inertia(lk: RSSRLinkage, alpha: float, length: float) -> CouplerInertia:
    """P1 (regime-2 mean), the F1 Fourier coefficients (constant + first harmonic, as App. H
    keeps them), the lumped-mass factor and the exact damping factor of a linkage and coupler.

    The linkage must assemble at every crank angle (``press_feed_rules``)."""
    return _computed((lk.a1, lk.a3, lk.a4, lk.s1, lk.s2, lk.s3, alpha, length))
