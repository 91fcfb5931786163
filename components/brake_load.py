"""Roller shaft with the referred strip inertia and a dry-friction brake.

Xu (1993), *Contributions to the Theory of Machine Dynamics* (PhD thesis, CUNY), Part I §3e
(p. 13) and Table 1 (p. 36): brake and strip-on-table friction lumped into one torque T_b on the
roller shaft, which holds the shaft in Regimes 1, 3 and 4 (§3f, p. 14).

The brake and table friction are one constant torque T_b (static = kinetic).  State machine:

* STICK: the shaft is held, speed exactly 0 (no creep), while |T| <= T_b;
* SLIP_FORWARD / SLIP_BACKWARD: J theta5'' = T - T_b sign(theta5').

Slip ends when the speed reaches zero; the shaft then sticks if |T| <= T_b (no chattering:
a stuck shaft leaves only when the applied torque exceeds T_b).  With the input torque held
over a step the motion is a piecewise parabola, so the step is exact, including the stop.
"""

from __future__ import annotations

import math

from .base import (
    COMMON_OUTPUTS,
    Component,
    ComponentError,
    SnapshotPlan,
    Variable,
    design_parameter,
    rate_input,
)
from .press_feed_data import APP_H_J_O5, LBF_IN, ROLLER_RADIUS

REGIME_STICK = 0
REGIME_SLIP_FORWARD = 1
REGIME_SLIP_BACKWARD = 2
REGIME_NAMES = {
    REGIME_STICK: "stick",
    REGIME_SLIP_FORWARD: "slip-forward",
    REGIME_SLIP_BACKWARD: "slip-backward",
}


def slip_direction(torque: float, brake_torque: float) -> int:
    """Regime a stuck shaft goes to under a torque (break-away test, static friction)."""
    if torque > brake_torque:
        return REGIME_SLIP_FORWARD
    if torque < -brake_torque:
        return REGIME_SLIP_BACKWARD
    return REGIME_STICK


def shaft_acceleration(regime: int, torque: float, brake_torque: float, j: float) -> float:
    """theta5'' in a given regime (zero while stuck)."""
    if regime == REGIME_SLIP_FORWARD:
        return (torque - brake_torque) / j
    if regime == REGIME_SLIP_BACKWARD:
        return (torque + brake_torque) / j
    return 0.0


def breakaway_margin(torque: float, brake_torque: float) -> float:
    """Event indicator while stuck: positive once |T| exceeds the friction torque."""
    return abs(torque) - brake_torque


class BrakeLoad(Component):
    """Roller shaft + strip + constant dry friction; input: the clutch torque (held over a
    step, or ramped about its held value by ``torque_rate`` where the shaft slips through
    the whole step).

    Port ``shaft`` (angle, speed out; torque in) joins the clutch's inner race.
    ``ind_brake`` is the break-away margin while stuck and the speed while slipping: its
    zero is the next regime change.  ``input_work`` is port work from the clutch, inside
    the scene, so it is not ``external_work``.
    """

    REGIME_NAMES = REGIME_NAMES

    PORTS = {"shaft": {"angle": "angle", "speed": "speed", "torque": "torque"}}

    SNAPSHOT = SnapshotPlan()  # its state is scalars: shared, not pickled

    VARIABLES = (
        design_parameter(
            "j",
            "kg.m2",
            APP_H_J_O5,
            "shaft + referred strip inertia",
            "Xu: J_o5",
            min=0.0,
            exclusive_min=True,
        ),
        design_parameter(
            "brake_torque", "N.m", 160.0 * LBF_IN, "friction torque", "Xu: T_b", min=0.0
        ),
        Variable(
            "roller_radius",
            "parameter",
            "m",
            ROLLER_RADIUS,
            "feed roller radius",
            min=0.0,
            exclusive_min=True,
        ),
        Variable("angle0", "parameter", "rad", 0.0, "initial angle (forward positive)"),
        Variable("speed0", "parameter", "rad/s", 0.0, "initial speed"),
        Variable("torque", "input", "N.m", 0.0, "torque from the clutch (forward positive)"),
        rate_input("torque", "N.m"),
        # Nominals: a feed turns the roller about a radian at a few rad/s, from rest.
        Variable(
            "angle",
            "output",
            "rad",
            0.0,
            "inner race / roller angle, forward positive",
            nominal=1.0,
        ),
        Variable(
            "speed",
            "output",
            "rad/s",
            0.0,
            "roller speed; zero while slipping = stop",
            nominal=1.0,
        ),
        Variable("feed_length", "output", "m", 0.0, "strip advance since start"),
        Variable(
            "breakaway",
            "output",
            "N.m",
            0.0,
            "|torque| - T_b; zero while stuck = slip",
            depends_on=("torque",),
        ),
        Variable("input_work", "output", "J", 0.0, "work done by the input torque"),
        Variable("event_time", "output", "s", -1.0, "time of the last stop (slip -> stick)"),
        Variable("t_event", "output", "s", -1.0, "time of the last regime change"),
        Variable(
            "ind_brake",
            "output",
            "1",
            0.0,
            "|T| - T_b if stuck, speed if slipping",
            depends_on=("torque",),
        ),
        *COMMON_OUTPUTS,
    )

    def initialize(self, t0: float) -> None:
        if self.j <= 0.0 or self.brake_torque < 0.0:
            raise ComponentError("BrakeLoad: need j > 0 and brake_torque >= 0")
        self.angle, self.speed = self.angle0, self.speed0
        if self.speed > 0.0:
            self.regime = REGIME_SLIP_FORWARD
        elif self.speed < 0.0:
            self.regime = REGIME_SLIP_BACKWARD
        else:
            self.regime = slip_direction(self.torque, self.brake_torque)
        self.input_work = self.dissipated_work = 0.0
        self.update_outputs()

    def update_outputs(self) -> None:
        self.feed_length = self.roller_radius * (self.angle - self.angle0)
        self.breakaway = breakaway_margin(self.torque, self.brake_torque)
        self.stored_energy = 0.5 * self.j * self.speed * self.speed
        self.ind_brake = self.breakaway if self.regime == REGIME_STICK else self.speed

    def _advance(self, s: float) -> None:
        """Move along the current regime's parabola for a time s."""
        a = shaft_acceleration(self.regime, self.torque, self.brake_torque, self.j)
        d = self.speed * s + 0.5 * a * s * s
        self.angle += d
        self.speed += a * s
        self.input_work += self.torque * d
        self.dissipated_work += self.brake_torque * abs(d)

    def _slip_ramped(self, h: float) -> bool:
        """Take the whole step slipping under the torque ramped about its held value,
        T(s) = torque + torque_rate (s - h/2), if the shaft slips throughout; else False
        (nothing done: a step with a stop or a break-away holds the torque, and its event
        ends the master's step there)."""
        if self.regime == REGIME_STICK:
            return False
        direction = 1.0 if self.regime == REGIME_SLIP_FORWARD else -1.0
        r, j = self.torque_rate, self.j
        a0 = shaft_acceleration(self.regime, self.torque - 0.5 * r * h, self.brake_torque, j)
        b = 0.5 * r / j  # v(s) = v0 + a0 s + b s^2, a0 at s = 0

        def v(s: float) -> float:
            return self.speed + (a0 + b * s) * s

        turn = -0.5 * a0 / b if b else -1.0  # where the speed turns, if inside the step
        ends = (v(h), v(turn)) if 0.0 < turn < h else (v(h),)
        if direction * self.speed < 0.0 or min(direction * x for x in ends) <= 0.0:
            return False
        d = (self.speed + (0.5 * a0 + b * h / 3.0) * h) * h
        # Work of the ramped torque: T v is a cubic in s, exact by two-point Gauss.
        work = 0.0
        for x in (0.5 - 0.5 / math.sqrt(3.0), 0.5 + 0.5 / math.sqrt(3.0)):
            s = x * h
            work += 0.5 * h * (self.torque + r * (s - 0.5 * h)) * v(s)
        self.speed = v(h)
        self.angle += d
        self.input_work += work
        self.dissipated_work += self.brake_torque * abs(d)
        return True

    def step(self, t: float, h: float) -> None:
        if self.torque_rate and self._slip_ramped(h):
            self.update_outputs()
            return
        left = h
        for _ in range(3):  # at most: slip, stop, slip the other way
            if self.regime == REGIME_STICK:
                self.regime = slip_direction(self.torque, self.brake_torque)
                if self.regime == REGIME_STICK:
                    break
                self.t_event = t + (h - left)  # break-away: the held torque exceeds T_b
            a = shaft_acceleration(self.regime, self.torque, self.brake_torque, self.j)
            if self.speed * a < 0.0 and -self.speed / a < left:
                stop = -self.speed / a
                self._advance(stop)
                self.speed = 0.0  # exact stop
                left -= stop
                self.event_time = self.t_event = t + (h - left)
                self.regime = slip_direction(self.torque, self.brake_torque)
                if self.regime == REGIME_STICK:
                    break
                continue
            self._advance(left)
            left = 0.0
            if self.speed == 0.0 and math.fabs(self.torque) <= self.brake_torque:
                self.regime = REGIME_STICK
            break
        self.update_outputs()
