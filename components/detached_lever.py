"""Detached lever escapement: balance wheel and hairspring driven by the train through the lever.

Model of Monday (1965), *Detached Lever Clock Mechanism Dynamics* (PhD thesis, Oklahoma State
University), Ch. III and App. A.  One degree of freedom, the balance angle theta, with

    I theta'' + c theta' + k theta = T_coulomb + T_drive          (Monday 1965, App. A, p. 94)

where the Coulomb torque opposes the motion and the drive torque acts only in short windows near
the dead point: a resisting *unlock* torque and an aiding *impulse* torque (Monday 1965, Figs. 2
and 8, pp. 11 and 38; Ch. IV, pp. 39-45).  Within a window the right-hand side is constant, so
every segment is a linear ODE solved in closed form (Monday 1965, Ch. III; App. A, pp. 94-102)
and the step needs no numerical integrator.

Two switching modes (``switching_mode``):

* ``PHASE_SCHEDULED`` (0): the thesis model.  Windows are scheduled on the phase
  psi = omega1 (t - t_cycle) of the damped free oscillation, the Coulomb sign follows the nominal
  phase, and each cycle lasts exactly 2 pi / omega1 (Monday 1965, Fig. 2, p. 11; Table III,
  p. 112).  This is the regression
  reference: it reproduces the worked example and the computed unit curves.
* ``ANGLE_SWITCHED`` (1): the physical model.  Unlock and impulse start and end when the balance
  angle crosses the escapement angles, in the direction the lever is waiting for; the Coulomb sign
  follows the actual speed and the balance sticks when the spring cannot overcome it.  Crossings
  are located exactly inside the step.  The period then depends on the drive torque (rate).

Window angles (Monday 1965, Fig. 8, p. 38): moving negative, unlock from +epsilon to +alpha,
impulse from +alpha to -beta; moving positive, unlock from -sigma to -gamma, impulse from -gamma
to +mu.  After an impulse the lever passes to the other side (drop and lock are not modelled).

Friction and forcing are Monday's deck, per segment of Table III (``detached_lever_design``):
a Coulomb torque ``coulomb_<n>`` = R(n) I for each of the ten segments, and for each of the six
windows the balance torque per drive torque (``unlock_ratio_2``, ``impulse_ratio_3``, ...), so
X(n) = ratio x drive_torque / I.  The input is the torque the train applies at the escape wheel.
The defaults are the worked example's symmetric deck: the input is the impulse torque at the
balance and the unlock torque the fixture calibration 0.007155/0.06215 of it (Monday 1965,
Ch. IV, pp. 39-45).  An impulse whose halves before and after the dead point differ switches
there; one whose halves are alike is one segment.  A design that breaks a rule of Monday's model
is refused at initialization (``detached_lever_design.violations``).

The pure functions at the end give the per-cycle amplitude map of the phase-scheduled model
(derived here from the Table III program: at the cycle end only its A terms survive, so the
amplitude obeys an affine map), the computed unit curves, the graph factor, and steady amplitude
and period against drive for the angle-switched model and the Table I units.
"""

from __future__ import annotations

import math

import numpy as np

from .base import (
    COMMON_OUTPUTS,
    Component,
    ComponentError,
    SnapshotPlan,
    Variable,
    design_parameter,
)
from .design_rules import raise_first
from .detached_lever_data import (
    BALANCE_INERTIA,
    LIFT_ANGLE,
    OVERBANK,
    TABLE_I,
    UNLOCK_START,
    WORKED_EXAMPLE,
)
from .detached_lever_design import (
    ANGLE_SWITCHED,
    FREE,
    IMPULSE,
    PHASE_SCHEDULED,
    SEGMENTS,
    UNLOCK,
    LeverDesign,
    segment_variables,
    symmetric_deck,
    violations,
)
from .event_integration import STEP_BUDGET_VARIABLE, StepBudgetSpent

# Regime codes: FREE, UNLOCK, IMPULSE (the segment kinds), and
STOPPED = 3
REGIME_NAMES = {FREE: "free", UNLOCK: "unlock", IMPULSE: "impulse", STOPPED: "stopped"}

_HALF_PI = 0.5 * math.pi
_TWO_PI = 2.0 * math.pi

_WE = WORKED_EXAMPLE
_I0 = BALANCE_INERTIA
SEGMENT_VARIABLES = segment_variables()


def _flow(
    x0: float, v0: float, tau: float, half_c: float, w1: float, w0sq: float
) -> tuple[float, float]:
    """Exact solution of x'' + 2 half_c x' + w0sq x = 0 after time tau (Monday 1965, App. A)."""
    e = math.exp(-half_c * tau)
    cs = math.cos(w1 * tau)
    sn = math.sin(w1 * tau) / w1
    return (
        e * (x0 * cs + (v0 + half_c * x0) * sn),
        e * (v0 * cs - (w0sq * x0 + half_c * v0) * sn),
    )


def _time_to_rest(x0: float, v0: float, half_c: float, w1: float, w0sq: float) -> float:
    """First tau > 0 where the speed of the free segment is zero (closed form)."""
    s = (w0sq * x0 + half_c * v0) / w1
    if v0 == 0.0 and s == 0.0:
        return math.inf
    # v ~ v0 cos(w1 tau) - s sin(w1 tau) = m cos(w1 tau + phi)
    arg = math.fmod(_HALF_PI - math.atan2(s, v0), math.pi)
    if arg < 0.0:
        arg += math.pi
    if arg <= 0.0:
        arg = math.pi
    return arg / w1


class DetachedLever(Component):
    """Balance wheel and hairspring of a detached lever escapement (Monday 1965, Ch. III).

    regime: 0 free, 1 unlock, 2 impulse, 3 stopped (Coulomb sticking, angle-switched only).
    beat_count, amplitude and period follow the true extremes (speed zeros) in both modes;
    cycle_end_angle is the thesis's amplitude, theta sampled at psi = 2 pi (mode 0).
    """

    REGIME_NAMES = REGIME_NAMES
    SNAPSHOT = SnapshotPlan()  # all its values are immutable scalars and tuples: shared

    VARIABLES = (
        Variable(
            "inertia",
            "parameter",
            "kg.m2",
            _I0,
            "balance polar inertia I",
            min=0.0,
            exclusive_min=True,
        ),
        design_parameter(
            "stiffness",
            "N.m/rad",
            _I0 * _WE.omega0**2,
            "hairspring rate K0 = I OMEGO^2",
            "Monday: K0",
            min=0.0,
        ),
        design_parameter(
            "viscous", "N.m.s/rad", _I0 * _WE.c, "viscous coefficient C I", "Monday: C", min=0.0
        ),
        *SEGMENT_VARIABLES[:10],
        # Window angles: within a quarter turn of the dead point (the impulse pin leaves the
        # fork long before; the phase-scheduled model requires it).
        *(
            design_parameter(
                name, "rad", value, meaning, f"Monday: {symbol}", min=0.0, max=_HALF_PI
            )
            for name, value, meaning, symbol in (
                ("alpha", _WE.alpha, "impulse before dead point, moving -", "ALPHA"),
                ("beta", _WE.alpha, "impulse after dead point, moving -", "BETA"),
                ("gamma", _WE.alpha, "impulse before dead point, moving +", "GAMA"),
                ("mu", _WE.alpha, "impulse after dead point, moving +", "AMU"),
                ("epsilon", _WE.epsilon, "start of unlock, moving -", "EPIL"),
                ("sigma", _WE.epsilon, "start of unlock, moving +", "SIGMA"),
            )
        ),
        *SEGMENT_VARIABLES[10:],
        Variable(
            "switching_mode",
            "parameter",
            "1",
            PHASE_SCHEDULED,
            "0 phase-scheduled (thesis), 1 angle-switched (physical)",
            "Integer",
            min=PHASE_SCHEDULED,
            max=ANGLE_SWITCHED,
        ),
        design_parameter(
            "theta_start", "rad", _WE.theta0, "initial balance angle", "Monday: THETO"
        ),
        Variable(
            "overbank_angle",
            "parameter",
            "rad",
            OVERBANK,
            "amplitude at which the impulse pin would strike the fork from behind",
            min=0.0,
        ),
        Variable("omega_start", "parameter", "rad/s", 0.0, "initial balance speed"),
        Variable(
            "drive_torque",
            "input",
            "N.m",
            _I0 * _WE.x_impulse,
            "torque of the train at the escape wheel",
        ),
        *COMMON_OUTPUTS,
        Variable("theta", "output", "rad", _WE.theta0, "balance angle"),
        Variable("omega", "output", "rad/s", 0.0, "balance speed"),
        Variable("drive_work", "output", "J", 0.0, "work done on the balance by the lever"),
        Variable("beat_count", "output", "1", 0, "half-cycles completed (extremes)", "Integer"),
        Variable("amplitude", "output", "rad", 0.0, "|theta| at the last extreme"),
        Variable("period", "output", "s", 0.0, "time between the last two positive extremes"),
        Variable("cycle_count", "output", "1", 0, "phase cycles completed (mode 0)", "Integer"),
        Variable("cycle_end_angle", "output", "rad", 0.0, "theta at the last cycle end (mode 0)"),
        Variable("lever_side", "output", "1", 1, "+1 lever waits for negative motion", "Integer"),
        Variable(
            "overbanked",
            "output",
            "1",
            0,
            "1 once an extreme reached overbank_angle (the knock itself is not modelled)",
            "Integer",
        ),
        Variable(
            "indicator_switch",
            "output",
            "rad",
            1.0,
            "distance (angle or phase) to the next window switch; zero at the switch",
        ),
        Variable("indicator_reversal", "output", "rad/s", 0.0, "balance speed; zero at reversal"),
        STEP_BUDGET_VARIABLE,
    )

    # -- life cycle -------------------------------------------------------------------
    def initialize(self, t0: float) -> None:
        self.check_parameters()
        self._mode = int(self.switching_mode)
        if self._mode not in (PHASE_SCHEDULED, ANGLE_SWITCHED):
            raise ComponentError(f"DetachedLever: unknown switching_mode {self._mode}")
        raise_first(violations(LeverDesign.of(self)))  # a broken design is refused, not run
        self._w0sq = self.stiffness / self.inertia
        self._half_c = 0.5 * self.viscous / self.inertia
        self._w1 = math.sqrt(self._w0sq - self._half_c**2)  # Monday 1965, App. A
        # Per segment n (Table III): Coulomb torque R(n) I and balance torque per drive torque.
        # Tuples indexed by n (immutable: shared between snapshots).
        self._coul = (0.0, *(getattr(self, s.coulomb) for s in SEGMENTS))
        self._ratio = (0.0, *(getattr(self, s.ratio) if s.ratio else 0.0 for s in SEGMENTS))
        # The impulse is one segment unless its halves before and after the dead point differ.
        self._split = frozenset(n for n in (3, 8) if self._forcing_of(n) != self._forcing_of(n + 1))
        a, b, g, m, e, s = self.alpha, self.beta, self.gamma, self.mu, self.epsilon, self.sigma
        if self._mode == PHASE_SCHEDULED:
            p = _HALF_PI
            # (phase at segment end, Coulomb/motion sign d, drive kind, segment), Table III's
            # ten steps; an impulse whose halves are alike is one step.
            ends = (p - e, p - a, p, p + b, 2 * p, 3 * p - s, 3 * p - g, 3 * p, 3 * p + m, 4 * p)
            schedule = []
            for seg, end in zip(SEGMENTS, ends, strict=True):
                if seg.n in (4, 9) and seg.n - 1 not in self._split:
                    schedule[-1] = (end, *schedule[-1][1:])
                else:
                    schedule.append((end, seg.direction, seg.kind, seg.n))
            self._schedule = tuple(schedule)
            self._seg = 0
            self._segn = 1
            self._cycle_t0 = t0
        self.theta = float(self.theta_start)
        self.omega = float(self.omega_start)
        self._last_peak_t = math.nan
        self.dissipated_work = 0.0
        self.drive_work = 0.0
        self.beat_count = 0
        self.cycle_count = 0
        self.overbanked = 0
        self.amplitude = abs(self.theta) if self.omega == 0.0 else 0.0
        self.period = 0.0
        self.cycle_end_angle = self.theta
        if self._mode == PHASE_SCHEDULED:
            _, self._dir, self.regime, self._segn = self._schedule[0]
        else:
            self.lever_side = 1 if self.theta >= 0.0 else -1
            self._dir = int(math.copysign(1.0, self.omega)) if self.omega != 0.0 else 0
            if self._dir == 0:
                self._release()
            else:
                self._classify()
        self._update_outputs(t0)

    def step(self, t: float, h: float) -> None:
        # Every member is a scalar or a tuple: a step that spends its budget is undone
        # from this copy, so nothing of it is kept.
        start = dict(self.__dict__)
        try:
            self._advance(t, t + h, stop_at_beat=False, budget=int(self.max_internal_steps))
        except StepBudgetSpent:
            self.__dict__.clear()
            self.__dict__.update(start)
            raise

    # -- forces -----------------------------------------------------------------------
    def _forcing_of(self, n: int) -> tuple[float, float]:
        return self._coul[n], self._ratio[n]

    def _drive(self) -> float:
        """Lever torque on the balance in the current segment, X(n) I (Monday, App. A)."""
        return self._ratio[self._segn] * self.drive_torque

    # -- angle-switched window logic --------------------------------------------------
    def _classify(self) -> None:
        """Set regime, segment and next target angle from (theta, direction, lever side)."""
        th, d = self.theta, self._dir
        for _ in range(2):
            side = self.lever_side
            if side == 1 and d < 0:
                if th > self.epsilon:
                    self.regime, self._segn, self._target = FREE, 1, self.epsilon
                elif th > self.alpha:
                    self.regime, self._segn, self._target = UNLOCK, 2, self.alpha
                elif th > -self.beta:
                    self.regime, self._segn, self._target = IMPULSE, 3, -self.beta
                    if 3 in self._split:  # the impulse changes at the dead point
                        if th > 0.0:
                            self._target = 0.0
                        else:
                            self._segn = 4
                else:
                    self.lever_side = -1
                    continue
                return
            if side == -1 and d > 0:
                if th < -self.sigma:
                    self.regime, self._segn, self._target = FREE, 6, -self.sigma
                elif th < -self.gamma:
                    self.regime, self._segn, self._target = UNLOCK, 7, -self.gamma
                elif th < self.mu:
                    self.regime, self._segn, self._target = IMPULSE, 8, self.mu
                    if 8 in self._split:
                        if th < 0.0:
                            self._target = 0.0
                        else:
                            self._segn = 9
                else:
                    self.lever_side = 1
                    continue
                return
            break
        # detached: the free swing after an impulse (or back before an unlock)
        self.regime, self._segn, self._target = FREE, 5 if d < 0 else 10, math.nan

    def _release(self) -> bool:
        """From rest: pick the direction the net torque can move, or stick (Coulomb)."""
        for d in (-1, 1):
            self._dir = d
            self._classify()
            net = -self.stiffness * self.theta + self._drive()
            if net * d > abs(self._coul[self._segn]):
                return True
        self._dir = 0
        self.regime, self._target = STOPPED, math.nan
        return False

    # -- the integrator ---------------------------------------------------------------
    def _advance(
        self, t: float, t_end: float, stop_at_beat: bool, budget: int | None = None
    ) -> float:
        """Advance to t_end (or to the next extreme); returns the time reached.  ``budget``:
        the most pieces of motion (between events) it may take (StepBudgetSpent beyond)."""
        w0sq, half_c, w1, inertia = self._w0sq, self._half_c, self._w1, self.inertia
        phase = self._mode == PHASE_SCHEDULED
        pieces = 0
        while t < t_end:
            pieces += 1
            if budget is not None and pieces > budget:
                raise StepBudgetSpent(
                    f"DetachedLever: the step to t = {t_end:.9g} s spent its budget of "
                    f"{budget} internal steps (max_internal_steps) at t = {t:.9g} s; take "
                    "shorter communication steps or give a larger budget"
                )
            if self.regime == STOPPED:
                if not self._release():
                    t = t_end
                    break
            d = self._dir
            m_drive = self._drive()
            # R(n) I: phase-scheduled, signed by the nominal phase as Table III has it;
            # angle-switched, opposing the actual motion (the segment follows the motion)
            t_coul = self._coul[self._segn]
            f = (m_drive + t_coul) / inertia
            th0, v0 = self.theta, self.omega
            x0 = th0 - f / w0sq
            rem = t_end - t
            dt_rest = _time_to_rest(x0, v0, half_c, w1, w0sq)
            event = 0  # 0 none, 1 reversal, 2 switch
            dt = rem
            if dt_rest <= dt:
                dt, event = dt_rest, 1
            if phase:
                t_sw = self._cycle_t0 + self._schedule[self._seg][0] / w1
                if t_sw - t <= dt:
                    dt, event = max(t_sw - t, 0.0), 2
            elif self._target == self._target:  # a target angle exists
                tau = self._crossing(x0, v0, f, d, dt)
                if tau is not None:
                    dt, event = tau, 2
            x, v = _flow(x0, v0, dt, half_c, w1, w0sq)
            th = x + f / w0sq
            if event == 1:
                v = 0.0
            elif event == 2 and not phase:
                th = self._target
            self._account(th0, v0, th, v, m_drive, t_coul)
            self.theta, self.omega = th, v
            if event == 2 and phase:
                t = t_sw
                self._next_segment()
            elif event == 0:
                t = t_end
            else:
                t += dt
            if event == 1:
                self._beat(t)
                if not phase:
                    self._dir = -d
                    self._classify()
                    net = -self.stiffness * th + self._drive()
                    if net * -d <= abs(self._coul[self._segn]):
                        self._release()
                if stop_at_beat:
                    break
            elif event == 2 and not phase:
                self._classify()
        self._update_outputs(t)
        return t

    def _crossing(self, x0: float, v0: float, f: float, d: int, dt_max: float) -> float | None:
        """Time at which theta reaches the target angle within dt_max, or None.

        Between speed zeros theta is monotonic, so a sign change at the ends brackets the only
        root; it is refined by safeguarded Newton to round-off.
        """
        w0sq, half_c, w1 = self._w0sq, self._half_c, self._w1
        off = f / w0sq - self._target
        g0 = d * (x0 + off)
        if g0 >= 0.0:
            return 0.0
        x1, _ = _flow(x0, v0, dt_max, half_c, w1, w0sq)
        if d * (x1 + off) < 0.0:
            return None
        lo, hi = 0.0, dt_max
        tau = dt_max * g0 / (g0 - d * (x1 + off))
        for _ in range(100):
            if not lo < tau < hi:
                tau = 0.5 * (lo + hi)
            x, v = _flow(x0, v0, tau, half_c, w1, w0sq)
            g = d * (x + off)
            if g >= 0.0:
                hi = tau
            else:
                lo = tau
            if hi - lo <= 4e-16 * (1.0 + hi) or g == 0.0:
                break
            dv = d * v
            tau = tau - g / dv if dv > 0.0 else 0.5 * (lo + hi)
        return hi

    def _next_segment(self) -> None:
        self._seg += 1
        if self._seg == len(self._schedule):
            self._seg = 0
            self._cycle_t0 += _TWO_PI / self._w1
            self.cycle_count += 1
            self.cycle_end_angle = self.theta
        _, self._dir, self.regime, self._segn = self._schedule[self._seg]

    def _account(
        self, th0: float, v0: float, th: float, v: float, m_drive: float, t_coul: float
    ) -> None:
        """Energy bookkeeping of one exact segment (viscous loss from the energy balance)."""
        k, inertia = self.stiffness, self.inertia
        de = 0.5 * inertia * (v * v - v0 * v0) + 0.5 * k * (th * th - th0 * th0)
        w_drive = m_drive * (th - th0)
        self.drive_work += w_drive
        self.dissipated_work += w_drive - de

    def _beat(self, t: float) -> None:
        self.beat_count += 1
        self.amplitude = abs(self.theta)
        if self.amplitude >= self.overbank_angle:
            self.overbanked = 1
        if self.theta > 0.0:
            if self._last_peak_t == self._last_peak_t:
                self.period = t - self._last_peak_t
            self._last_peak_t = t

    def _update_outputs(self, t: float) -> None:
        th, v = self.theta, self.omega
        self.stored_energy = 0.5 * self.inertia * v * v + 0.5 * self.stiffness * th * th
        self.indicator_reversal = v
        if self._mode == PHASE_SCHEDULED:
            self.indicator_switch = self._schedule[self._seg][0] - self._w1 * (t - self._cycle_t0)
        elif self._target == self._target:
            self.indicator_switch = -self._dir * (th - self._target)
        else:
            self.indicator_switch = 1.0

    # -- helpers for the steady-state functions ----------------------------------------
    def advance_to_next_beat(self, t: float, t_limit: float) -> float:
        """Advance to the next extreme (or t_limit); returns the time reached."""
        return self._advance(t, t_limit, stop_at_beat=True)


# ------------------------------------------------------------------------------------------
# Phase-scheduled model as a per-cycle amplitude map (derived here; exact equivalent of Table III)
# ------------------------------------------------------------------------------------------
def phase_cycle_map(
    c: float,
    omega0: float,
    r: float,
    x_unlock: float,
    x_impulse: float,
    alpha: float,
    epsilon: float,
    beta: float | None = None,
    gamma: float | None = None,
    mu: float | None = None,
    sigma: float | None = None,
) -> tuple[float, float]:
    """(ratio, offset) of Theta_{n+1} = ratio Theta_n + offset for one phase cycle of a
    symmetric deck.

    All forcing terms are magnitudes per unit inertia [1/s^2]: Coulomb r, unlock x_unlock,
    impulse x_impulse; c [1/s] is the viscous coefficient per unit inertia.  Omitted angles take
    the symmetric values beta = gamma = mu = alpha and sigma = epsilon.
    """
    f = (r, r + x_unlock, r - x_impulse, r - x_impulse, r, -r, -r - x_unlock,
         -r + x_impulse, -r + x_impulse, -r)  # fmt: skip
    return deck_cycle_map(c, omega0, f, alpha, epsilon, beta, gamma, mu, sigma)


def deck_cycle_map(
    c: float,
    omega0: float,
    forcing: tuple[float, ...],
    alpha: float,
    epsilon: float,
    beta: float | None = None,
    gamma: float | None = None,
    mu: float | None = None,
    sigma: float | None = None,
) -> tuple[float, float]:
    """(ratio, offset) of the cycle map for any deck: ``forcing`` is F(n) = R(n) + X(n) of the
    ten segments [1/s^2], signed as Monday's cards (Table III, p. 112)."""
    beta = alpha if beta is None else beta
    gamma = alpha if gamma is None else gamma
    mu = alpha if mu is None else mu
    sigma = epsilon if sigma is None else sigma
    w1 = 0.5 * math.sqrt(4.0 * omega0**2 - c**2)
    b = c / (2.0 * w1)
    p = _HALF_PI
    w0sq = omega0**2
    f = forcing
    ph = (p - epsilon, p - alpha, p, p + beta, 2 * p, 3 * p - sigma, 3 * p - gamma, 3 * p,
          3 * p + mu)  # fmt: skip
    const = sum(
        (f[k] - f[k + 1]) / w0sq * math.exp(-b * (_TWO_PI - q)) * (math.cos(q) - b * math.sin(q))
        for k, q in enumerate(ph)
    )
    ratio = math.exp(-_TWO_PI * b)
    return ratio, const + f[-1] / w0sq - ratio * f[0] / w0sq


def deck_amplitudes(
    theta0: float, n_cycles: int, **map_args: float | tuple[float, ...]
) -> np.ndarray:
    """Cycle-end amplitudes Theta_0..Theta_n of the phase-scheduled model for any deck."""
    ratio, offset = deck_cycle_map(**map_args)
    return _iterate(theta0, n_cycles, ratio, offset)


def _iterate(theta0: float, n_cycles: int, ratio: float, offset: float) -> np.ndarray:
    out = np.empty(n_cycles + 1)
    out[0] = theta0
    for n in range(n_cycles):
        out[n + 1] = ratio * out[n] + offset
    return out


def phase_amplitudes(theta0: float, n_cycles: int, **map_args: float) -> np.ndarray:
    """Cycle-end amplitudes Theta_0..Theta_n of the phase-scheduled model (Table III output)."""
    ratio, offset = phase_cycle_map(**map_args)
    return _iterate(theta0, n_cycles, ratio, offset)


def unit_curve(
    c_over_omega0: float,
    k: float,
    n_cycles: int = 41,
    theta0: float = OVERBANK,
    alpha: float = LIFT_ANGLE,
) -> np.ndarray:
    """Computed unit curve (CUC): impulse-only drive X3/omega0^2 = K, released at 6.28 rad.

    Returns the cycle-end amplitudes [rad] for cycles 0..n_cycles (Monday 1965, pp. 30-38).  With
    omega0 = 1 the cycle period is 2 pi / sqrt(1 - (C/omega0)^2/4) in units of 1/omega0.
    """
    return phase_amplitudes(
        theta0, n_cycles, c=c_over_omega0, omega0=1.0, r=0.0, x_unlock=0.0,
        x_impulse=k, alpha=alpha, epsilon=UNLOCK_START,
    )  # fmt: skip


def unit_curve_steady(c_over_omega0: float, k: float, alpha: float = LIFT_ANGLE) -> float:
    """Steady amplitude Theta* [rad] of a computed unit curve (fixed point of the map)."""
    ratio, offset = phase_cycle_map(
        c_over_omega0, 1.0, 0.0, 0.0, k, alpha=alpha, epsilon=UNLOCK_START
    )
    return offset / (1.0 - ratio)


def graph_factor(c_over_omega0: float, alpha: float = LIFT_ANGLE) -> float:
    """K / B: impulse-only drive K giving the curve of Coulomb-only drive -B (Monday, p. 37)."""
    _, per_k = phase_cycle_map(c_over_omega0, 1.0, 0.0, 0.0, 1.0, alpha=alpha, epsilon=alpha)
    _, per_b = phase_cycle_map(c_over_omega0, 1.0, -1.0, 0.0, 0.0, alpha=alpha, epsilon=alpha)
    return per_b / per_k


# ------------------------------------------------------------------------------------------
# Angle-switched model: steady amplitude and period against drive
# ------------------------------------------------------------------------------------------
def cycle_from_rest(
    params: dict[str, float], drive_torque: float, amplitude: float
) -> tuple[float, float]:
    """One full cycle of the angle-switched model released at rest from +amplitude.

    Returns (amplitude at the next positive extreme [rad], cycle time [s]); nan when the
    balance sticks or does not come back.
    """
    lever = DetachedLever(
        **{**params, "switching_mode": ANGLE_SWITCHED, "theta_start": amplitude,
           "omega_start": 0.0}
    )  # fmt: skip
    lever.drive_torque = drive_torque
    lever.initialize(0.0)
    t_limit = 4.0 * _TWO_PI / lever._w1
    t = 0.0
    for _ in range(2):
        t = lever.advance_to_next_beat(t, t_limit)
        if lever.regime == STOPPED or t >= t_limit:
            return math.nan, math.nan
    if lever.theta <= 0.0:
        return math.nan, math.nan
    return lever.theta, t


def steady_state(
    params: dict[str, float], drive_torque: float, n_scan: int = 24
) -> tuple[float, float]:
    """Steady amplitude [rad] and period [s] of the angle-switched model at a drive torque.

    The cycle map is scanned from the unlock angle to overbank for the stable fixed point
    (map above the diagonal below it, below above it; Coulomb sticking makes the map jump), then
    refined by bracketing.  (nan, nan) when the escapement does not sustain motion.
    """
    from scipy.optimize import brentq  # not at module level: the FMU packs numpy only

    eps = max(params.get("epsilon", _WE.epsilon), params.get("sigma", _WE.epsilon))

    def gap(a: float) -> float:
        nxt, _ = cycle_from_rest(params, drive_torque, a)
        return -a if nxt != nxt else nxt - a

    grid = np.linspace(eps * 1.0001, OVERBANK, n_scan)
    gaps = [gap(a) for a in grid]
    for k in range(n_scan - 1, 0, -1):
        if gaps[k - 1] > 0.0 >= gaps[k]:
            a = brentq(gap, grid[k - 1], grid[k], xtol=1e-12, rtol=1e-13)
            if abs(gap(a)) < 1e-9:
                return a, cycle_from_rest(params, drive_torque, a)[1]
    return math.nan, math.nan


def table_i_params(
    unit: int, inertia: float = BALANCE_INERTIA, coulomb: float = 0.0
) -> dict[str, float]:
    """Component parameters for a Table I unit: symmetric angles, the Coulomb torque [N.m] in
    every segment, impulse ratio 1 and the unit's X2/X3 in the unlock windows."""
    u = TABLE_I[unit]
    a, e = u.alpha, u.epsilon
    return {
        "inertia": inertia,
        "stiffness": inertia * u.omega0**2,
        "viscous": inertia * u.c_over_omega0 * u.omega0,
        "alpha": a, "beta": a, "gamma": a, "mu": a, "epsilon": e, "sigma": e,
        **symmetric_deck(coulomb, 1.0, table_i_unlock_ratio(unit)),
    }  # fmt: skip


def table_i_unlock_ratio(unit: int) -> float:
    """Unlock torque per impulse torque, X2/X3 of a Table I unit's first load (p. 56)."""
    row = TABLE_I[unit].rows[0]
    return row.x_unlock / row.x_impulse


def table_i_phase_steady(unit: int) -> list[float]:
    """Steady amplitudes [rad] of the K-only CUCs matched to a unit's three loads (Table I)."""
    u = TABLE_I[unit]
    return [unit_curve_steady(u.c_over_omega0, row.k) for row in u.rows]


def table_i_phase_curve(unit: int, load_multiples: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Steady amplitude [rad] and period [s] of the phase-scheduled model against load multiple.

    K is fitted linearly in load through the unit's three Table I values; the period is
    2 pi / omega1 whatever the load (the phase-scheduled forcing of Monday 1965, Fig. 2, fixes it),
    with omega1 from omega0 and C (the printed omega1 of units 1 and 3 in Table I, p. 56, disagrees
    with omega1 = sqrt(4 omega0^2 - C^2)/2).
    """
    u = TABLE_I[unit]
    slope, icpt = np.polyfit([r.load_multiple for r in u.rows], [r.k for r in u.rows], 1)
    loads = np.asarray(load_multiples, dtype=float)
    per_k = unit_curve_steady(u.c_over_omega0, 1.0)
    omega1 = u.omega0 * math.sqrt(1.0 - 0.25 * u.c_over_omega0**2)
    return per_k * (icpt + slope * loads), np.full(loads.shape, _TWO_PI / omega1)


def table_i_angle_switched_fit(unit: int, inertia: float = BALANCE_INERTIA) -> tuple[float, float]:
    """(Coulomb torque [N.m], impulse torque per load multiple [N.m]) of the angle-switched
    model, fitted so that its steady amplitudes match the phase model's at the unit's loads.

    The thesis's R and X belong to the phase-scheduled model and cannot be reused (derived here:
    a phase window of half-width alpha delivers energy in proportion to the amplitude, an angle
    window a fixed energy), so a load-independent Coulomb torque and a drive proportional to load
    are refitted by least squares on the three steady amplitudes (C, omega0 and the angles are the
    unit's own).
    The period is then a prediction of the angle-switched model.
    """
    from scipy.optimize import least_squares  # not at module level: the FMU packs numpy only

    u = TABLE_I[unit]
    targets = np.array(table_i_phase_steady(unit))
    loads = np.array([row.load_multiple for row in u.rows], dtype=float)
    scale = inertia * u.omega0**2  # fit in units of torque / (I omega0^2), i.e. radians

    def residual(z: np.ndarray) -> np.ndarray:
        p = table_i_params(unit, inertia, abs(z[0]) * scale)
        amps = [steady_state(p, abs(z[1]) * scale * m)[0] for m in loads]
        return np.array([3.0 if a != a else a - t for a, t in zip(amps, targets, strict=True)])

    # start: viscous-only energy balance at the middle load, per half swing (as in the cycle map)
    a, e, cw = u.alpha, u.epsilon, u.c_over_omega0
    work_per_x = 2.0 * a - table_i_unlock_ratio(unit) * (e - a)
    x0 = 0.5 * math.pi * cw * targets[1] ** 2 / work_per_x / loads[1]
    sol = least_squares(residual, [0.01, x0], x_scale=[0.1, x0], diff_step=1e-6)
    return abs(sol.x[0]) * scale, abs(sol.x[1]) * scale


def table_i_rate_curve(
    unit: int, load_multiples: np.ndarray, inertia: float = BALANCE_INERTIA
) -> tuple[np.ndarray, np.ndarray]:
    """Steady amplitude [rad] and period [s] of the angle-switched model against load multiple
    for a Table I unit, with the refitted friction and drive of ``table_i_angle_switched_fit``."""
    coulomb, per_load = table_i_angle_switched_fit(unit, inertia)
    params = table_i_params(unit, inertia, coulomb)
    res = [steady_state(params, per_load * m) for m in np.asarray(load_multiples, float)]
    return np.array([r[0] for r in res]), np.array([r[1] for r in res])
