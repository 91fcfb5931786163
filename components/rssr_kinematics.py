"""Rocker kinematics of the RSSR feed linkage (Xu 1993, App. A, pp. 134-141; Hartenberg & Denavit).

All angles are in the thesis convention here (phi4 measured from Z0, *decreasing* on the
feed stroke); the components turn them into forward-positive coordinates.  Derivatives are
with respect to the crank angle phi1: ``'`` = d/dphi1.

A rocker model returns, for a crank angle, the tuple
``(phi4r, phi4r', phi4r'', F2, F2', F2'')`` where ``phi4e = phi4r + F2 q`` (14), (B.21).
"""

from __future__ import annotations

import math

import numpy as np

from .kernels import load_kernel
from .press_feed_data import RSSRLinkage

Kinematics = tuple[float, float, float, float, float, float]


class ExactRSSR:
    """Closed-form rigid rocker angle (A.8-A.9) and the elastic coupling F2 = 2 sin(alpha) eta4.

    ``f2_const`` (rad/m), when not None, replaces F2(phi1) by a constant (the thesis uses
    0.098 rad/in in its linearized model, App. C b).
    """

    def __init__(self, linkage: RSSRLinkage, alpha: float, f2_const: float | None = None) -> None:
        lk = linkage
        self.a1, self.a3, self.a4 = lk.a1, lk.a3, lk.a4
        self.s1, self.s2, self.s3 = lk.s1, lk.s2, lk.s3
        self.A = 2.0 * lk.s1 * lk.a4  # (A.9)
        self.c0 = lk.a4**2 + lk.s1**2 + lk.s2**2 + lk.s3**2 + lk.a1**2 - lk.a3**2
        self.f2_gain = 4.0 * lk.a3 * math.sin(alpha)  # F2 = 2 sin(alpha) * (-2 a3 / D)
        self.f2_const = f2_const
        # The last angle asked and its answer: a step asks the same angle several times
        # (outputs, indicators, the first stage), and the answer depends on nothing else.
        self._memo: tuple[float, Kinematics] = (math.nan, (math.nan,) * 6)

    def __call__(self, phi1: float) -> Kinematics:
        memo = self._memo
        if memo[0] == phi1:
            return memo[1]
        out = self._solve(phi1)
        self._memo = (phi1, out)
        return out

    def _solve(self, phi1: float) -> Kinematics:
        a1, a4, s2, s3, A = self.a1, self.a4, self.s2, self.s3, self.A
        sp, cp = math.sin(phi1), math.cos(phi1)
        B = 2.0 * a4 * (s3 + a1 * sp)
        C = self.c0 + 2.0 * a1 * s2 * cp + 2.0 * s3 * a1 * sp
        phi4 = 2.0 * math.atan((A + math.sqrt(A * A + B * B - C * C)) / (B + C))  # (A.8)
        # Implicit derivatives of f = A sin(phi4) + B cos(phi4) - C = 0.
        B1 = 2.0 * a4 * a1 * cp
        B2 = -2.0 * a4 * a1 * sp
        C1 = -2.0 * a1 * s2 * sp + 2.0 * s3 * a1 * cp
        C2 = -2.0 * a1 * s2 * cp - 2.0 * s3 * a1 * sp
        s4, c4 = math.sin(phi4), math.cos(phi4)
        D = A * c4 - B * s4  # df/dphi4, the denominator of eta4 (A.16)
        d1 = -(B1 * c4 - C1) / D
        D1 = -A * s4 * d1 - B1 * s4 - B * c4 * d1
        d2 = -(B2 * c4 - B1 * s4 * d1 - C2 + D1 * d1) / D
        if self.f2_const is not None:
            return phi4, d1, d2, self.f2_const, 0.0, 0.0
        D2 = (
            -A * c4 * d1 * d1
            - A * s4 * d2
            - B2 * s4
            - 2.0 * B1 * c4 * d1
            + B * s4 * d1 * d1
            - B * c4 * d2
        )
        g = self.f2_gain
        f2 = -g / D
        f2_1 = g * D1 / (D * D)
        f2_2 = g * (D2 / (D * D) - 2.0 * D1 * D1 / (D * D * D))
        return phi4, d1, d2, f2, f2_1, f2_2


class FourierRocker:
    """phi4r as the App. H constant + first harmonic (a30, a31, b31), constant F2.

    This is the rocker the thesis's linearized model uses for its forcing (C.12-C.22); its
    second derivative times F2 reproduces the printed a2n coefficients.
    """

    def __init__(self, coeffs: tuple[float, float, float], f2_const: float) -> None:
        self.a0, self.a1, self.b1 = coeffs
        self.f2 = f2_const

    def __call__(self, phi1: float) -> Kinematics:
        c, s = math.cos(phi1), math.sin(phi1)
        p = self.a0 + self.a1 * c + self.b1 * s
        dp = -self.a1 * s + self.b1 * c
        ddp = -self.a1 * c - self.b1 * s
        return p, dp, ddp, self.f2, 0.0, 0.0


def rocker_extremes(kin: ExactRSSR | FourierRocker) -> tuple[float, float, float, float]:
    """(phi4_max, phi1 at max, phi4_min, phi1 at min) of the rigid rocker, phi1 in [0, 2pi).

    Grid search, then Newton on phi4r'(phi1) = 0 with the analytic phi4r''.
    """
    grid = np.linspace(0.0, 2.0 * math.pi, 721)
    vals = np.array([kin(p)[0] for p in grid])
    out: list[float] = []
    for idx in (int(np.argmax(vals)), int(np.argmin(vals))):
        p = float(grid[idx])
        for _ in range(50):
            _, d1, d2, *_ = kin(p)
            dp = d1 / d2
            p -= dp
            if abs(dp) < 1e-15:
                break
        out.extend([kin(p)[0], p % (2.0 * math.pi)])
    return out[0], out[1], out[2], out[3]


_KERNEL = load_kernel("press_feed_kernel")
if _KERNEL is not None:  # the compiled twin (components.kernels): the same results
    _KERNEL.use_classes(exact=ExactRSSR, fourier=FourierRocker)
    ExactRSSR.__call__ = _KERNEL.exact_rssr_call  # type: ignore[method-assign]
