"""Geometry and kinematics of the M739 S&A (Lowen & Tepper 1982, App B-E).

* fuze-body angles of the pivots and centre lines (App B, B1-B39);
* coupled-motion kinematics of a wheel tooth tip sliding on a straight verge face
  (App C: C15, C17-C21, C25, C26 with the corrected sign of V);
* moment arms and normal velocities (App D: A1'..D1', D13, D15);
* free-motion contact sensing (App E: E4, E5);
* the impact map (B205, B210-B212 with the corrected restitution sign and D1' factor).

All functions work on plain floats (they sit on the integrator's hot path).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .kernels import load_kernel
from .m739_data import M739Data

TWO_PI = 2.0 * math.pi


@dataclass(frozen=True)
class FuzeAngles:
    """Pivot polar angles and centre-line directions in the fuze-body frame [rad]."""

    gamma2: float
    gamma3: float
    gamma4: float
    gamma3p: float
    gamma4p: float
    delta2: float
    delta3: float
    delta4: float
    beta1: float  # direction O1 -> O2
    beta2: float  # direction O2 -> O3
    beta3: float  # direction O3 (= O_s) -> O_p
    gamma_pp: float  # gamma_p': angle from +x' to the outward radial at O_p


@dataclass(frozen=True)
class TrainAngles:
    """The train's pivot polar angles and mesh centre-line directions [rad] (B1-B10)."""

    gamma2: float
    gamma3: float
    gamma3p: float
    delta2: float
    delta3: float
    beta1: float  # direction O1 -> O2
    beta2: float  # direction O2 -> O3


def train_angles(d: M739Data) -> TrainAngles:
    """App B, B1-B10: the rotor, gear-2 and escape-wheel pivots (s6 = +1 for configuration
    1, -1 for configuration 2); the pallet pivot does not enter them."""
    s6 = 1.0 if d.config == 1 else -1.0
    c12 = d.rp1_cap + d.rp2  # centre distance, mesh 1
    c23 = d.rp2_cap + d.rp3  # centre distance, mesh 2
    gamma2 = s6 * math.acos((d.r1**2 + d.r2**2 - c12**2) / (2 * d.r1 * d.r2))
    gamma3p = math.acos((d.r2**2 + d.r3**2 - c23**2) / (2 * d.r2 * d.r3))
    gamma3 = gamma2 + s6 * gamma3p
    delta2 = math.acos((c12**2 + d.r1**2 - d.r2**2) / (2 * d.r1 * c12))
    delta3 = math.acos((c23**2 + d.r2**2 - d.r3**2) / (2 * d.r2 * c23))
    beta1 = math.pi - s6 * delta2
    beta2 = gamma2 + math.pi - s6 * delta3
    return TrainAngles(gamma2, gamma3, gamma3p, delta2, delta3, beta1, beta2)


def fuze_angles(d: M739Data) -> FuzeAngles:
    """App B, B1-B31 (s6 = +1 for configuration 1, -1 for configuration 2)."""
    s6 = 1.0 if d.config == 1 else -1.0
    t = train_angles(d)
    gamma4p = math.acos((d.r3**2 + d.r4**2 - d.a**2) / (2 * d.r3 * d.r4))
    gamma4 = t.gamma3 + s6 * gamma4p
    delta4 = math.acos((d.a**2 + d.r3**2 - d.r4**2) / (2 * d.a * d.r3))
    beta3 = t.gamma3 + math.pi - s6 * delta4
    # B14 (configuration 1) / B26 (configuration 2).
    gamma_pp = delta4 + gamma4p if d.config == 1 else TWO_PI - delta4 - gamma4p
    return FuzeAngles(
        t.gamma2,
        t.gamma3,
        gamma4,
        t.gamma3p,
        gamma4p,
        t.delta2,
        t.delta3,
        delta4,
        t.beta1,
        t.beta2,
        beta3,
        gamma_pp,
    )


def kinem(
    phi: float, alpha: float, a: float, b: float, c: float
) -> tuple[float, float, float, float, float, float, float]:
    """Coupled kinematics for a tooth tip on the face of angle alpha (App C, D).

    Returns (psi, g, U, V, A1', B1', D1') with psi from C18 (minus root, as subroutine
    KINEM; right branch on both faces), g from C15, U = P/Q (C21) and
    V = dU/dphi (C26; the report's C28 prints a wrong leading minus).  C1' = -c sin(alpha)
    is constant per face and is not returned.
    """
    cap_a = a * math.cos(alpha) + b * math.cos(phi - alpha)
    cap_b = a * math.sin(alpha) - b * math.sin(phi - alpha)
    cap_c = c * math.sin(alpha)
    disc = cap_a * cap_a + cap_b * cap_b - cap_c * cap_c
    if disc < 0.0:
        disc = 0.0  # tangency: keep the real part (only reached far outside contact)
    psi = 2.0 * math.atan2(cap_a - math.sqrt(disc), cap_b + cap_c)
    if psi < 0.0:
        psi += TWO_PI
    spa = math.sin(psi + alpha)
    cpa = math.cos(psi + alpha)
    arg = phi - alpha - psi
    sarg = math.sin(arg)
    carg = math.cos(arg)
    g = (b * math.sin(phi) - c * math.sin(psi)) / spa
    p = b * carg  # = A1'
    q = a * cpa + p  # = D1' in contact
    u = p / q
    v = (a * p * p * spa - b * (p - q) ** 2 * sarg) / (q * q * q)
    return psi, g, u, v, p, b * sarg, c * math.cos(alpha) + g


def face_arms(
    phi: float, psi: float, alpha: float, b: float, c: float
) -> tuple[float, float, float]:
    """(g, A1', D1') at an arbitrary (phi, psi): g from C15, arms from App D."""
    g = (b * math.sin(phi) - c * math.sin(psi)) / math.sin(psi + alpha)
    return g, b * math.cos(phi - psi - alpha), c * math.cos(alpha) + g


def sliding_velocity(
    phi: float, psi: float, phi_dot: float, psi_dot: float, alpha: float, b: float, c: float
) -> float:
    """V_S/T along n_t (C25): -[phi_dot b sin(phi - psi - alpha) + psi_dot c sin(alpha)]."""
    return -(phi_dot * b * math.sin(phi - psi - alpha) + psi_dot * c * math.sin(alpha))


def contact_sensing(
    phi: float, psi: float, alpha: float, a: float, b: float, c: float
) -> tuple[float, float]:
    """Free-motion gap f (E4) and tip projection g' along the face (E5)."""
    f = a * math.sin(psi + alpha) - b * math.sin(phi - psi - alpha) - c * math.sin(alpha)
    gp = a * math.cos(psi + alpha) + b * math.cos(phi - psi - alpha) - c * math.cos(alpha)
    return f, gp


def normal_velocities(
    phi: float, psi: float, phi_dot: float, psi_dot: float, alpha: float, b: float, c: float
) -> tuple[float, float]:
    """(V_TN, V_SN) along n_n: pallet D1' psi_dot (D13) and tooth A1' phi_dot (D15)."""
    _, a1p, d1p = face_arms(phi, psi, alpha, b, c)
    return d1p * psi_dot, a1p * phi_dot


def impact_map(
    phi_dot: float,
    psi_dot: float,
    a1p: float,
    d1p: float,
    i_p: float,
    i_stot: float,
    e_rest: float,
) -> tuple[float, float]:
    """Post-impact speeds (B211, B212) from B205 and the restitution law B210.

    B210 is V_TNf - V_SNf = -e (V_TNi - V_SNi) (the OCR drops the minus sign) and the
    psi_dot term of B211 carries the factor A1' D1' (the OCR drops D1').
    """
    ipa = i_p * a1p
    den = ipa * a1p + i_stot * d1p * d1p
    phi_f = (
        phi_dot * (i_stot * d1p * d1p - e_rest * ipa * a1p) + psi_dot * ipa * d1p * (1.0 + e_rest)
    ) / den
    psi_f = (phi_f * a1p - e_rest * (psi_dot * d1p - phi_dot * a1p)) / d1p
    return phi_f, psi_f


_KERNEL = load_kernel("m739_kernel")
if _KERNEL is not None:  # the compiled twins (components.kernels): the same results
    kinem = _KERNEL.kinem
    sliding_velocity = _KERNEL.sliding_velocity
