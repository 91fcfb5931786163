"""Elementary rotational bodies: a free inertia, and an inertia on a torsional spring–damper.

Together they form the two-FMU plumbing scene (``scenarios/two_inertias.toml``): body A is
driven by the torque the spring–damper of body B returns, and B sees A's angle and speed.
Both steps are exact for their held inputs, so any error in a coupled run is coupling error.
"""

from __future__ import annotations

import math

from .base import COMMON_OUTPUTS, Component, ComponentError, SnapshotPlan, Variable, common_outputs


class Inertia(Component):
    """A rigid body on a frictionless pivot, driven by an input torque."""

    SNAPSHOT = SnapshotPlan()  # scalars (and caches of parameters): shared, not pickled
    VARIABLES = (
        Variable(
            "J", "parameter", "kg.m2", 1.0e-3, "moment of inertia", min=0.0, exclusive_min=True
        ),
        Variable("phi0", "parameter", "rad", 0.0, "initial angle"),
        Variable("w0", "parameter", "rad/s", 0.0, "initial angular velocity"),
        Variable("tau", "input", "N.m", 0.0, "torque applied to the body"),
        Variable("phi", "output", "rad", 0.0, "angle"),
        Variable("w", "output", "rad/s", 0.0, "angular velocity"),
        Variable("port_work", "output", "J", 0.0, "work done on the body through its flange"),
        *COMMON_OUTPUTS,
    )
    PORTS = {"flange": {"angle": "phi", "speed": "w", "torque": "tau"}}

    def initialize(self, t0: float) -> None:
        if not self.J > 0.0:
            raise ComponentError(f"Inertia: J must be positive, got {self.J}")
        self.phi, self.w = self.phi0, self.w0
        self.port_work = 0.0
        self.stored_energy = 0.5 * self.J * self.w**2

    def step(self, t: float, h: float) -> None:
        # Constant torque over the step: the motion is an exact parabola.
        alpha = self.tau / self.J
        dphi = self.w * h + 0.5 * alpha * h * h
        self.port_work += self.tau * dphi
        self.phi += dphi
        self.w += alpha * h
        self.stored_energy = 0.5 * self.J * self.w**2


class SpringDamperInertia(Component):
    """A body tied by a torsional spring–damper to the port of another body.

    The port's angle and speed are inputs; during a step the port is taken to move at its
    held speed (angle ramps as ``phi_in + w_in*s``), which keeps the held inputs consistent.
    ``tau`` is the torque the spring–damper exerts on the *other* body, evaluated with the
    current inputs (direct feedthrough).
    """

    SNAPSHOT = SnapshotPlan()  # scalars (and caches of parameters): shared, not pickled
    VARIABLES = (
        Variable(
            "J", "parameter", "kg.m2", 1.0e-3, "moment of inertia", min=0.0, exclusive_min=True
        ),
        Variable("k", "parameter", "N.m/rad", 10.0, "torsional stiffness", min=0.0),
        Variable("d", "parameter", "N.m.s/rad", 0.01, "torsional damping", min=0.0),
        Variable(
            "max_twist", "parameter", "rad", 1.0e30, "twist at which the coupling breaks", min=0.0
        ),
        Variable("phi0", "parameter", "rad", 0.0, "initial angle"),
        Variable("w0", "parameter", "rad/s", 0.0, "initial angular velocity"),
        Variable("phi_in", "input", "rad", 0.0, "angle of the other body's port", sampled=True),
        Variable("w_in", "input", "rad/s", 0.0, "angular velocity of the other body's port"),
        Variable("phi", "output", "rad", 0.0, "angle"),
        Variable("w", "output", "rad/s", 0.0, "angular velocity"),
        Variable(
            "tau", "output", "N.m", 0.0, "torque on the other body", depends_on=("phi_in", "w_in")
        ),
        *common_outputs(stored_energy=("phi_in",)),
    )
    PORTS = {"coupling": {"angle": "phi_in", "speed": "w_in", "torque": "tau"}}

    def initialize(self, t0: float) -> None:
        if not self.J > 0.0 or self.k < 0.0 or self.d < 0.0:
            raise ComponentError(
                f"SpringDamperInertia: need J > 0, k >= 0, d >= 0; got {self.J}, {self.k}, {self.d}"
            )
        self.phi, self.w = self.phi0, self.w0
        self._cache_transition: dict[float, tuple[float, float, float, float]] = {}
        self.update_outputs()

    def update_outputs(self) -> None:
        twist = self.phi_in - self.phi
        self.tau = -(self.k * twist + self.d * (self.w_in - self.w))
        self.stored_energy = 0.5 * self.J * self.w**2 + 0.5 * self.k * twist**2

    def step(self, t: float, h: float) -> None:
        # Relative coordinate y = phi - (phi_in + w_in s) obeys J y'' + d y' + k y = 0 while the
        # port moves at constant speed, so the step is the exact 2x2 transition matrix.
        y0 = self.phi - self.phi_in
        v0 = self.w - self.w_in
        m = self._cache_transition.get(h)
        if m is None:
            m = damped_oscillator_transition(self.k / self.J, self.d / self.J, h)
            if len(self._cache_transition) > 8:  # variable steps: keep the state small
                self._cache_transition.clear()
            self._cache_transition[h] = m
        y1 = m[0] * y0 + m[1] * v0
        v1 = m[2] * y0 + m[3] * v0
        # Work dissipated by the damper over the step: integral of d*y'^2, exact for the
        # same transition (trapezoid would be O(h^2)); use energy of the relative motion.
        e0 = 0.5 * self.J * v0**2 + 0.5 * self.k * y0**2
        e1 = 0.5 * self.J * v1**2 + 0.5 * self.k * y1**2
        self.dissipated_work += e0 - e1
        if abs(y1) > self.max_twist:
            raise ComponentError(
                f"twist {abs(y1):.6g} rad exceeds the coupling's limit {self.max_twist:.6g} rad"
            )
        self.phi_in += self.w_in * h
        self.phi = self.phi_in + y1
        self.w = self.w_in + v1
        self.update_outputs()


def damped_oscillator_transition(
    k_over_j: float, d_over_j: float, h: float
) -> tuple[float, float, float, float]:
    """exp(A h) for A = [[0, 1], [-k/J, -d/J]], row by row, in closed form for every damping.

    Plain floats (not numpy scalars): they end up in the state, which is saved every step.
    """
    a = 0.5 * d_over_j
    disc = a * a - k_over_j
    e = math.exp(-a * h)
    if disc < 0.0:  # under-damped
        wd = math.sqrt(-disc)
        c, s = math.cos(wd * h), math.sin(wd * h) / wd
    elif disc > 0.0:  # over-damped
        r = math.sqrt(disc)
        c, s = math.cosh(r * h), math.sinh(r * h) / r
    else:  # critically damped
        c, s = 1.0, h
    return (e * (c + a * s), e * s, -e * k_over_j * s, e * (c - a * s))
