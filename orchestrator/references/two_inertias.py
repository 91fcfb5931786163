"""Closed-form reference of the two-inertia scene: two bodies joined by a spring–damper.

The centre of mass moves at constant speed; the twist x = phi_a - phi_b is a damped
oscillator with the reduced inertia J_a J_b / (J_a + J_b).
"""

from __future__ import annotations

import numpy as np

from components.rotational import damped_oscillator_transition


def two_inertias_exact(
    t: np.ndarray,
    J_a: float,
    J_b: float,
    k: float,
    d: float,
    phi_a0: float = 0.0,
    w_a0: float = 0.0,
    phi_b0: float = 0.0,
    w_b0: float = 0.0,
) -> dict[str, np.ndarray]:
    """Angles and speeds of both bodies at times t (measured from the start)."""
    t = np.asarray(t, dtype=float)
    total = J_a + J_b
    j_red = J_a * J_b / total
    centre0 = (J_a * phi_a0 + J_b * phi_b0) / total
    centre_w = (J_a * w_a0 + J_b * w_b0) / total
    x0, v0 = phi_a0 - phi_b0, w_a0 - w_b0
    x = np.empty_like(t)
    v = np.empty_like(t)
    for n, tn in enumerate(t):
        m = damped_oscillator_transition(k / j_red, d / j_red, float(tn))
        x[n] = m[0, 0] * x0 + m[0, 1] * v0
        v[n] = m[1, 0] * x0 + m[1, 1] * v0
    centre = centre0 + centre_w * t
    return {
        "phi_a": centre + J_b / total * x,
        "w_a": centre_w + J_b / total * v,
        "phi_b": centre - J_a / total * x,
        "w_b": centre_w - J_a / total * v,
    }
