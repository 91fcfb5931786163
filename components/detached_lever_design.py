"""Monday's deck for the detached lever as design parameters, and its consistency rules.

The ten-step program (Monday 1965, App. B, Table III, p. 112) reads one escapement from five
cards: the window angles, C, THETO and OMEGO (card 1), EPIL and SIGMA (card 2), the Coulomb
friction of each of the ten segments R(1..10) (cards 3-4) and the forcing of the six windows
X(2), X(3), X(4), X(7), X(8), X(9) (card 5), all forces per unit balance inertia, signed as the
right-hand side of theta'' + C theta' + OMEGO^2 theta = R(n) + X(n).

Here each R(n) is a torque parameter ``coulomb_<n>`` = R(n) I, and each X(n) is the balance
torque per drive torque ``unlock_ratio_<n>`` / ``impulse_ratio_<n>`` = X(n) I / drive_torque
(the thesis's fixture calibration per window, Ch. IV, pp. 39-45), so the load stays the FMU's
input.  The defaults are the worked example's symmetric deck (pp. 39-45): R(1..5) = +R,
R(6..10) = -R, X(2) = -X(7) = unlock, X(3) = X(4) = -X(8) = -X(9) = -impulse.

The rules are those Monday's model assumes (Ch. III; App. A): an underdamped balance, windows
ordered from unlock to impulse on each side and within a quarter cycle of the dead point, a
balance released from rest at a positive extreme beyond the unlock (phase-scheduled) or
swinging past the unlock (angle-switched), friction opposing the motion, the unlock resisting
it and the impulse driving it, and a lever that gives the balance more work than it takes.
``violations`` lists every broken rule; FMU initialization refuses the first one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from .base import Variable, design_parameter
from .design_rules import Violation
from .detached_lever_data import BALANCE_INERTIA, WORKED_EXAMPLE

PHASE_SCHEDULED = 0
ANGLE_SWITCHED = 1

# Segment kinds.
FREE = 0
UNLOCK = 1
IMPULSE = 2

_HALF_PI = 0.5 * math.pi


@dataclass(frozen=True)
class Segment:
    """One of the ten steps of a cycle (Monday 1965, Table III): its motion and window."""

    n: int  # Monday's segment number 1..10
    direction: int  # nominal sign of the balance speed
    kind: int  # FREE, UNLOCK or IMPULSE
    meaning: str

    @property
    def coulomb(self) -> str:
        return f"coulomb_{self.n}"

    @property
    def ratio(self) -> str | None:
        """The forcing parameter of the segment's window, None for a free segment."""
        if self.kind == UNLOCK:
            return f"unlock_ratio_{self.n}"
        if self.kind == IMPULSE:
            return f"impulse_ratio_{self.n}"
        return None


SEGMENTS: tuple[Segment, ...] = (
    Segment(1, -1, FREE, "free swing from the positive extreme to the unlock"),
    Segment(2, -1, UNLOCK, "unlock, moving negative (epsilon to alpha)"),
    Segment(3, -1, IMPULSE, "impulse before the dead point, moving negative (alpha to 0)"),
    Segment(4, -1, IMPULSE, "impulse after the dead point, moving negative (0 to -beta)"),
    Segment(5, -1, FREE, "free swing to the negative extreme"),
    Segment(6, 1, FREE, "free swing from the negative extreme to the unlock"),
    Segment(7, 1, UNLOCK, "unlock, moving positive (-sigma to -gamma)"),
    Segment(8, 1, IMPULSE, "impulse before the dead point, moving positive (-gamma to 0)"),
    Segment(9, 1, IMPULSE, "impulse after the dead point, moving positive (0 to mu)"),
    Segment(10, 1, FREE, "free swing to the positive extreme"),
)
WINDOWS = tuple(s for s in SEGMENTS if s.ratio is not None)

_I0 = BALANCE_INERTIA
_WE = WORKED_EXAMPLE
#: The worked example's unlock torque per impulse torque, X2/X3 (Monday 1965, pp. 39-45).
UNLOCK_PER_IMPULSE = _WE.x_unlock / _WE.x_impulse


def symmetric_friction(coulomb: float) -> dict[str, float]:
    """coulomb_1..coulomb_10 of one Coulomb torque magnitude [N.m], signed as Monday's cards
    (R(1..5) = +R, R(6..10) = -R)."""
    return {s.coulomb: -s.direction * coulomb for s in SEGMENTS}


def symmetric_deck(coulomb: float, impulse_ratio: float, unlock_ratio: float) -> dict[str, float]:
    """The per-segment parameters of a symmetric deck from magnitudes: Coulomb torque [N.m],
    impulse and unlock balance torque per drive torque, signed as Monday's cards are."""
    out = symmetric_friction(coulomb)
    for s in SEGMENTS:
        if s.kind == UNLOCK:
            out[s.ratio] = -s.direction * unlock_ratio
        elif s.kind == IMPULSE:
            out[s.ratio] = s.direction * impulse_ratio
    return out


_DEFAULTS = symmetric_deck(_I0 * _WE.r, 1.0, UNLOCK_PER_IMPULSE)


def _sign_word(direction: int) -> str:
    return "negative" if direction < 0 else "positive"


def segment_variables() -> tuple[Variable, ...]:
    """coulomb_1..coulomb_10, then the six window ratios, as design parameters."""
    out = [
        design_parameter(
            s.coulomb,
            "N.m",
            _DEFAULTS[s.coulomb],
            f"Coulomb torque R({s.n}) I in segment {s.n}, {s.meaning}; signed, "
            f"{'+' if s.direction < 0 else '-'} opposes the motion",
            f"Monday: R({s.n})",
        )
        for s in SEGMENTS
    ]
    for s in WINDOWS:
        word = "resisting" if s.kind == UNLOCK else "driving"
        out.append(
            design_parameter(
                s.ratio,
                "1",
                _DEFAULTS[s.ratio],
                f"balance torque per drive torque in segment {s.n}, {s.meaning}: "
                f"X({s.n}) = this x drive_torque / I; signed, "
                f"{'+' if (s.direction < 0) == (s.kind == UNLOCK) else '-'} is {word}",
                f"Monday: X({s.n})",
            )
        )
    return tuple(out)


@dataclass(frozen=True)
class LeverDesign:
    """What the rules read: the deck in SI (forces as torques, forcing per drive torque)."""

    inertia: float
    stiffness: float
    viscous: float
    alpha: float
    beta: float
    gamma: float
    mu: float
    epsilon: float
    sigma: float
    theta_start: float
    omega_start: float
    switching_mode: int
    coulomb: tuple[float, ...]  # R(n) I for n = 1..10
    ratio: dict[int, float]  # segment n -> X(n) I / drive_torque, the six windows

    @classmethod
    def of(cls, values: Any) -> LeverDesign:
        """From a component or a mapping of its parameters."""
        get = values.__getitem__ if isinstance(values, dict) else values.__getattribute__
        names = ("inertia", "stiffness", "viscous", "alpha", "beta", "gamma", "mu")
        names += ("epsilon", "sigma", "theta_start", "omega_start")
        return cls(
            *(float(get(n)) for n in names),
            int(get("switching_mode")),
            tuple(float(get(s.coulomb)) for s in SEGMENTS),
            {s.n: float(get(s.ratio)) for s in WINDOWS},
        )

    @property
    def omega0(self) -> float:
        return math.sqrt(self.stiffness / self.inertia)

    def r(self, n: int) -> float:
        """Monday's R(n) [s^-2]."""
        return self.coulomb[n - 1] / self.inertia


def _rad(symbol: str, value: float) -> str:
    return f"{symbol} = {value:.6g} rad"


def violations(d: LeverDesign) -> list[Violation]:
    """Every broken rule of a lever design."""
    out: list[Violation] = []
    if not d.inertia > 0.0 or not d.stiffness > 0.0:
        out.append(
            Violation(
                "balance and hairspring",
                f"I = {d.inertia:.6g} kg.m2, K0 = {d.stiffness:.6g} N.m/rad; expected both > 0",
            )
        )
        return out
    c, w0 = d.viscous / d.inertia, d.omega0
    if not c < 2.0 * w0:
        # Monday 1965, App. A: omega1 = sqrt(4 OMEGO^2 - C^2) / 2 must be real
        out.append(
            Violation(
                "underdamped balance",
                f"C = {c:.6g} 1/s, 2 OMEGO = {2.0 * w0:.6g} 1/s; expected C < 2 OMEGO",
            )
        )
    out += _window_violations(d)
    out += _start_violations(d)
    out += _sign_violations(d)
    out += _work_violations(d)
    return out


def _window_violations(d: LeverDesign) -> list[Violation]:
    out = []
    for side, lift, lift_name, unlock, unlock_name in (
        ("moving negative", d.alpha, "ALPHA", d.epsilon, "EPIL"),
        ("moving positive", d.gamma, "GAMA", d.sigma, "SIGMA"),
    ):
        if not 0.0 <= lift <= unlock:
            out.append(
                Violation(
                    "windows ordered",
                    f"{side}: {_rad(lift_name, lift)}, {_rad(unlock_name, unlock)}; expected "
                    f"0 <= {lift_name} <= {unlock_name} (the unlock ends where the impulse "
                    "begins)",
                )
            )
    for name, value in (("EPIL", d.epsilon), ("SIGMA", d.sigma), ("BETA", d.beta)):
        if not 0.0 <= value <= _HALF_PI:
            out.append(_quarter(name, value))
    if not 0.0 <= d.mu <= _HALF_PI:
        out.append(_quarter("AMU", d.mu))
    return out


def _quarter(name: str, value: float) -> Violation:
    return Violation(
        "windows within a quarter cycle",
        f"{_rad(name, value)}; expected 0 <= {name} <= pi/2 = 1.5708 rad (Monday's windows "
        "lie between a dead point and the next extreme)",
    )


def _start_violations(d: LeverDesign) -> list[Violation]:
    reach = max(d.epsilon, d.sigma)
    if d.switching_mode == PHASE_SCHEDULED:
        # Table III starts every cycle at psi = 0: the balance at rest at a positive extreme
        if d.omega_start != 0.0 or not d.theta_start > reach:
            return [
                Violation(
                    "release at a positive extreme",
                    f"{_rad('THETO', d.theta_start)}, omega_start = {d.omega_start:.6g} rad/s; "
                    f"expected THETO > max(EPIL, SIGMA) = {reach:.6g} rad and omega_start = 0 "
                    "(the phase schedule starts at rest at a positive extreme)",
                )
            ]
        return []
    swing = math.hypot(d.theta_start, d.omega_start / d.omega0)
    if not swing > reach:
        return [
            Violation(
                "windows inside the swing",
                f"start amplitude sqrt(theta_start^2 + (omega_start/OMEGO)^2) = {swing:.6g} rad, "
                f"max(EPIL, SIGMA) = {reach:.6g} rad; expected the balance to swing past the "
                "unlock",
            )
        ]
    return []


def _sign_violations(d: LeverDesign) -> list[Violation]:
    out = []
    for s in SEGMENTS:
        r = d.r(s.n)
        if r * s.direction > 0.0:
            out.append(
                Violation(
                    "friction opposes the motion",
                    f"R({s.n}) = {r:.6g} 1/s^2 in segment {s.n} (moving "
                    f"{_sign_word(s.direction)}); expected "
                    f"{'>= 0' if s.direction < 0 else '<= 0'}",
                )
            )
    for s in WINDOWS:
        x = d.ratio[s.n]
        resists = s.kind == UNLOCK
        # X(n) resists the motion when its sign is opposite to the motion's
        if (x * s.direction > 0.0) if resists else (x * s.direction < 0.0):
            rule = "unlock resists the motion" if resists else "impulse drives the motion"
            want = ">= 0" if (s.direction < 0) == resists else "<= 0"
            out.append(
                Violation(
                    rule,
                    f"X({s.n}) = {x:.6g} x drive_torque / I ({s.ratio} = {x:.6g}) in segment "
                    f"{s.n} (moving {_sign_word(s.direction)}); expected {s.ratio} {want}",
                )
            )
    return out


def lever_works(d: LeverDesign) -> tuple[tuple[float, float], tuple[float, float]]:
    """(impulse work, unlock work) per drive torque on each half-swing, negative and positive
    motion, per unit amplitude for the phase-scheduled model (theta = Theta cos psi over the
    windows), per radian of the windows for the angle-switched model."""
    if d.switching_mode == PHASE_SCHEDULED:
        lift, sin = math.sin, math.sin
    else:
        lift, sin = (lambda a: a), (lambda a: a)
    x = {n: abs(v) for n, v in d.ratio.items()}
    neg = (x[3] * lift(d.alpha) + x[4] * lift(d.beta), x[2] * (sin(d.epsilon) - sin(d.alpha)))
    pos = (x[8] * lift(d.gamma) + x[9] * lift(d.mu), x[7] * (sin(d.sigma) - sin(d.gamma)))
    return neg, pos


def _work_violations(d: LeverDesign) -> list[Violation]:
    out = []
    phase = d.switching_mode == PHASE_SCHEDULED

    def m(symbol: str) -> str:
        return f"sin({symbol})" if phase else symbol

    for (impulse, unlock), side, names in zip(
        lever_works(d),
        ("moving negative", "moving positive"),
        (("X(3)", "ALPHA", "X(4)", "BETA", "X(2)", "EPIL"),
         ("X(8)", "GAMA", "X(9)", "AMU", "X(7)", "SIGMA")),
        strict=True,
    ):  # fmt: skip
        if unlock > impulse:
            x3, a, x4, b, x2, e = names
            out.append(
                Violation(
                    "lever gives net work",
                    f"{side}: impulse |{x3}| {m(a)} + |{x4}| {m(b)} = {impulse:.6g}, unlock "
                    f"|{x2}| ({m(e)} - {m(a)}) = {unlock:.6g} (per drive torque / I); expected "
                    "the impulse to give at least the work the unlock takes",
                )
            )
    return out
