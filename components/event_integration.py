"""Integration of a piecewise-smooth model with its discrete mode frozen inside a step, and
exact location of the sign changes of its indicators (events).

The method is the embedded Runge-Kutta pair of Dormand & Prince, "A family of embedded
Runge-Kutta formulae", J. Comp. Appl. Math. 6 (1980) 19-26: fifth-order solution, fourth-
order error estimate, step size from the estimate.  Its continuous extension (Hairer,
Norsett & Wanner, Solving Ordinary Differential Equations I, 2nd ed., Springer 1993,
section II.6, dense output of DOPRI5) gives the state anywhere inside an accepted step, so
an event is located on that polynomial instead of by repeated integration.

A model changes its mode only in ``event`` (after an indicator crossing); between events its
right-hand side is smooth, so the error estimate is that of a smooth problem and every
discontinuity is a located step boundary.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from types import ModuleType
from typing import NamedTuple, Protocol

from .base import ComponentError, Variable
from .kernels import load_kernel


class EventModel(Protocol):
    """What :func:`advance` needs from a model (the mode lives inside the model).

    Optional: ``accept(y, t)`` after each accepted step (to observe it: it must not change
    the mode), and an attribute ``halted`` that stops the integration.
    """

    def deriv(self, y: list[float]) -> list[float]: ...

    def indicators(self, y: list[float]) -> Sequence[float]: ...

    def event(self, y: list[float], index: int, t: float) -> list[float]: ...


@dataclass(frozen=True)
class IntegrationStepControl:
    """Accuracy of the integration.

    The local error of each state component i is held below
    ``rtol * (scales[i] + max|y_i|)`` (mixed absolute/relative), so ``scales`` are the
    magnitudes below which that component is controlled absolutely.  ``h_max`` caps the
    step (events are seen at step ends only, so it bounds how short an excursion of an
    indicator below zero can be and still be seen).
    """

    rtol: float
    scales: tuple[float, ...]
    h_max: float = math.inf
    #: budget of one ``advance``: integration steps, accepted and rejected (None: unbounded)
    max_steps: int | None = None

    def __post_init__(self) -> None:
        if not (0.0 < self.rtol < 1.0):
            raise ComponentError(f"integration tolerance must be in (0, 1), got {self.rtol}")
        if not self.h_max > 0.0:
            raise ComponentError(f"largest integration step must be positive, got {self.h_max}")


#: The FMU parameters of a component integrated here: its accuracy and largest step.
INTEGRATION_VARIABLES = (
    Variable(
        "tolerance",
        "parameter",
        "1",
        1.0e-8,
        "relative local error tolerance of the internal integration",
        min=1.0e-14,
        max=1.0e-2,
    ),
    Variable(
        "h_max",
        "parameter",
        "s",
        1.0e-4,
        "largest internal integration step (events are seen at step ends)",
        min=1.0e-9,
    ),
)


#: Internal steps one doStep may take by default: far beyond any example scene's, about
#: 5 to 10 s of work; a doStep that needs more ends with a message instead of running on.
DEFAULT_STEP_BUDGET = 100_000

#: The FMU parameter that bounds the work of one doStep (the components integrated here
#: declare it with their INTEGRATION_VARIABLES or through ``TrainComponent``).
STEP_BUDGET_VARIABLE = Variable(
    "max_internal_steps",
    "parameter",
    "1",
    DEFAULT_STEP_BUDGET,
    "budget of one doStep in internal integration steps, accepted and rejected (spent: "
    "the step is discarded, with a message)",
    "Integer",
    min=1.0,
)


class StepBudgetSpent(ComponentError):
    """One ``advance`` took more internal steps than its control's ``max_steps``."""


def integration_variables(h_max: float) -> tuple[Variable, ...]:
    """INTEGRATION_VARIABLES with another default largest step (a model whose indicators
    change slowly need not cap its steps at 0.1 ms), and the step budget."""
    tolerance, largest = INTEGRATION_VARIABLES
    return tolerance, replace(largest, start=h_max), STEP_BUDGET_VARIABLE


def integration_step_control(
    component: object, scales: tuple[float, ...]
) -> IntegrationStepControl:
    """The IntegrationStepControl of a component from its INTEGRATION_VARIABLES (and its
    ``max_internal_steps``, where it has one)."""
    budget = getattr(component, "max_internal_steps", None)
    return IntegrationStepControl(
        float(component.tolerance),  # type: ignore[attr-defined]
        scales,
        float(component.h_max),  # type: ignore[attr-defined]
        None if budget is None else int(budget),
    )


#: observe(t0, t1, state_at): a stretch of the solution in one mode (see ``advance``).
Observer = Callable[[float, float, Callable[[float], list[float]]], None]


class Advanced(NamedTuple):
    """The state after :func:`advance` and what happened on the way."""

    y: list[float]
    t_first_event: float  # offset of the first event from the start, -1.0 if none
    t_last_event: float  # offset of the last event, -1.0 if none
    events: int
    h_next: float  # the step the controller proposes next (pass it to the next call)
    steps: int  # accepted steps
    rejected: int  # steps rejected by the error test


# Dormand-Prince 5(4) coefficients (DP 1980, table 2).
_C2, _C3, _C4, _C5 = 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0
_A21 = 1.0 / 5.0
_A31, _A32 = 3.0 / 40.0, 9.0 / 40.0
_A41, _A42, _A43 = 44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0
_A51, _A52, _A53, _A54 = 19372.0 / 6561.0, -25360.0 / 2187.0, 64448.0 / 6561.0, -212.0 / 729.0
_A61, _A62, _A63 = 9017.0 / 3168.0, -355.0 / 33.0, 46732.0 / 5247.0
_A64, _A65 = 49.0 / 176.0, -5103.0 / 18656.0
_B1, _B3, _B4 = 35.0 / 384.0, 500.0 / 1113.0, 125.0 / 192.0
_B5, _B6 = -2187.0 / 6784.0, 11.0 / 84.0
# Fifth- minus fourth-order weights: the error estimate.
_E1, _E3, _E4 = 71.0 / 57600.0, -71.0 / 16695.0, 71.0 / 1920.0
_E5, _E6, _E7 = -17253.0 / 339200.0, 22.0 / 525.0, -1.0 / 40.0
# Continuous extension (HNW 1993, II.6, the dense output of DOPRI5).
_D1, _D3, _D4 = (
    -12715105075.0 / 11282082432.0,
    87487479700.0 / 32700410799.0,
    (-10690763975.0 / 1880347072.0),
)
_D5, _D6, _D7 = (
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    (69997945.0 / 29380423.0),
)

# Step-size controller: safety factor, bounds of one change, exponent 1/(order + 1).
_SAFETY = 0.9
_GROW_MAX = 5.0
_SHRINK_MIN = 0.2
_EXPONENT = 0.2
# A stage that fails (a model outside its domain beyond an event) shrinks the step so.
_SHRINK_ON_FAILURE = 0.25
# Steps shorter than this fraction of the time reached are refused (no progress).
_H_MIN_RELATIVE = 1e-14
_H_MIN_ABSOLUTE = 1e-16


class _Step(NamedTuple):
    y1: list[float]
    k7: list[float]
    err: float
    dense: tuple[list[float], ...]


def _dp5_step(
    deriv: Callable[[list[float]], list[float]],
    y: list[float],
    k1: list[float],
    h: float,
    control: IntegrationStepControl,
) -> _Step:
    n = len(y)
    rng = range(n)
    k2 = deriv([y[i] + h * _A21 * k1[i] for i in rng])
    k3 = deriv([y[i] + h * (_A31 * k1[i] + _A32 * k2[i]) for i in rng])
    k4 = deriv([y[i] + h * (_A41 * k1[i] + _A42 * k2[i] + _A43 * k3[i]) for i in rng])
    k5 = deriv(
        [y[i] + h * (_A51 * k1[i] + _A52 * k2[i] + _A53 * k3[i] + _A54 * k4[i]) for i in rng]
    )
    k6 = deriv(
        [
            y[i] + h * (_A61 * k1[i] + _A62 * k2[i] + _A63 * k3[i] + _A64 * k4[i] + _A65 * k5[i])
            for i in rng
        ]
    )
    y1 = [
        y[i] + h * (_B1 * k1[i] + _B3 * k3[i] + _B4 * k4[i] + _B5 * k5[i] + _B6 * k6[i])
        for i in rng
    ]
    k7 = deriv(y1)
    rtol, scales = control.rtol, control.scales
    # The states past the scales are quadratures (an integral over the step): integrated
    # with the others, not controlled, so adding them leaves the steps as they were.
    m = len(scales)
    acc = 0.0
    for i in range(m):
        e = h * (_E1 * k1[i] + _E3 * k3[i] + _E4 * k4[i] + _E5 * k5[i] + _E6 * k6[i] + _E7 * k7[i])
        sc = rtol * (scales[i] + max(abs(y[i]), abs(y1[i])))
        acc += (e / sc) ** 2
    err = math.sqrt(acc / m)
    if err != err:  # NaN: treat as a failed stage
        raise ArithmeticError("non-finite error estimate")
    dy = [y1[i] - y[i] for i in rng]
    r3 = [h * k1[i] - dy[i] for i in rng]
    r4 = [dy[i] - h * k7[i] - r3[i] for i in rng]
    r5 = [
        h * (_D1 * k1[i] + _D3 * k3[i] + _D4 * k4[i] + _D5 * k5[i] + _D6 * k6[i] + _D7 * k7[i])
        for i in rng
    ]
    return _Step(y1, k7, err, (y, dy, r3, r4, r5))


def dense_state(dense: tuple[list[float], ...], theta: float) -> list[float]:
    """The state at fraction ``theta`` of an accepted step (fourth-order accurate)."""
    y0, dy, r3, r4, r5 = dense
    s1 = 1.0 - theta
    return [
        y0[i] + theta * (dy[i] + s1 * (r3[i] + theta * (r4[i] + s1 * r5[i])))
        for i in range(len(y0))
    ]


def _interpolant(
    dense: tuple[list[float], ...], t0: float, h: float
) -> Callable[[float], list[float]]:
    def state_at(t: float) -> list[float]:
        return dense_state(dense, (t - t0) / h)

    return state_at


def _locate(
    model: EventModel,
    dense: tuple[list[float], ...],
    h: float,
    idx: int,
    g_lo: float,
    g_hi: float,
    tol_t: float,
) -> tuple[float, list[float]]:
    """Illinois root search of indicator idx on the dense output (g_lo >= 0 > g_hi).

    Returns the first point found with the indicator < 0, i.e. just past the crossing,
    so that the event handler always sees the new side.
    """
    lo, hi = 0.0, 1.0
    y_hi = None
    side = 0
    tol = tol_t / h
    for _ in range(80):
        if hi - lo <= tol:
            break
        th = hi - g_hi * (hi - lo) / (g_hi - g_lo)
        if not (lo < th < hi):
            th = 0.5 * (lo + hi)
        yt = dense_state(dense, th)
        gt = model.indicators(yt)[idx]
        if gt < 0.0:
            hi, g_hi, y_hi = th, gt, yt
            if side == -1:
                g_lo *= 0.5
            side = -1
        else:
            lo, g_lo = th, gt
            if side == 1:
                g_hi *= 0.5
            side = 1
    if y_hi is None:
        y_hi = dense_state(dense, hi)
    return hi * h, y_hi


def _restep(
    model: EventModel,
    deriv: Callable[[list[float]], list[float]],
    y: list[float],
    k1: list[float],
    th: float,
    y_dense: list[float],
    idx: int,
    control: IntegrationStepControl,
    tol_t: float,
) -> tuple[float, list[float]]:
    """The event state by one step of length th from the step start instead of from the
    dense output.  A caller that repeats the step up to the reported event time (a master
    that rolls back and steps to the event) then computes exactly this step again and
    sees the same crossing; the dense state would differ by the interpolation error.
    If the step lands short of the crossing, it is lengthened by a few time tolerances."""
    for nudge in (0.0, 1.0, 4.0, 16.0):
        tn = th + nudge * tol_t
        try:
            yt = _dp5_step(deriv, y, k1, tn, control).y1
        except (ArithmeticError, ValueError):
            break
        if model.indicators(yt)[idx] < 0.0:
            return tn, yt
    return th, y_dense


def _first_step(y: list[float], k1: list[float], control: IntegrationStepControl) -> float:
    """A first step from the sizes of y and y' (HNW 1993, II.4, the simple part)."""
    n = len(control.scales)  # the controlled states (see _dp5_step)
    sc = [control.rtol * (control.scales[i] + abs(y[i])) for i in range(n)]
    d0 = math.sqrt(sum((y[i] / sc[i]) ** 2 for i in range(n)) / n)
    d1 = math.sqrt(sum((k1[i] / sc[i]) ** 2 for i in range(n)) / n)
    if d0 < 1e-5 or d1 < 1e-5:
        return 1e-6
    return 0.01 * d0 / d1


def _model_halted(model: EventModel) -> bool:
    """Whether the model has halted.  A wrapper that only ends the step at an event
    (``components.early_return.UntilFirstEvent``) says apart whether the model itself did
    (``model_halted``): the events of that instant still all fire."""
    own = getattr(model, "model_halted", None)
    return own if own is not None else getattr(model, "halted", False)


def _fire_at_instant(
    model: EventModel, y: list[float], first: int, t: float, g_start: Sequence[float]
) -> tuple[list[float], int, Sequence[float]]:
    """Handle event ``first`` at t, then every other event of the same instant.

    An indicator that was armed (>= 0) at the step start and is past zero once an event
    has been handled crossed at this instant too, within the location tolerance, or was
    pushed across by that event's change of state.  Either way it fires here: after the
    first, in index order, each once, every one seeing the state the previous one left.
    Without this it would start the next step below zero and never fire (two crossings
    at one instant would lose one).  Returns the state, the number of events fired and
    the indicators there (the next step starts from them).
    """
    y = model.event(y, first, t)
    fired = {first}
    while True:
        g = model.indicators(y)
        if _model_halted(model):
            break
        nxt = next(
            (
                j
                for j, (a, b) in enumerate(zip(g_start, g, strict=True))
                if b < 0.0 <= a and j not in fired
            ),
            -1,
        )
        if nxt < 0:
            break
        y = model.event(y, nxt, t)
        fired.add(nxt)
    return y, len(fired), g


def advance(
    model: EventModel,
    y: list[float],
    h_total: float,
    control: IntegrationStepControl,
    h_try: float = 0.0,
    tol_t: float = 1e-14,
    max_events: int = 2000,
    observe: Observer | None = None,
) -> Advanced:
    """Integrate over h_total with error-controlled steps, stopping exactly at indicator
    crossings.

    An indicator fires when it goes from >= 0 to < 0 (at once if it is exactly 0 at the
    step start); the located point is just past the crossing, so an event handler that
    leaves y there sees the new side and does not fire again.  The earliest crossing in
    a step fires first; others of the same instant follow it (``_fire_at_instant``).  The
    model's ``event`` changes its mode (and may change y); the integration then continues
    from there.
    ``h_try`` is the step to try first (the ``h_next`` of the previous call; 0: choose).
    ``observe(t0, t1, state_at)`` is called for every stretch integrated in one mode,
    before the mode changes: ``state_at(t)`` is the state at any t in [t0, t1] (offsets
    from the start), e.g. for output at fixed times without shortening the steps.
    """
    for compiled in _COMPILED:  # the same loop in C, for the models it knows (else None)
        done = compiled(model, y, h_total, control, h_try, tol_t, max_events, observe)
        if done is not None:
            return Advanced(*done)
    deriv = model.deriv
    accept = getattr(model, "accept", None)
    t = 0.0
    g0 = model.indicators(y)
    k1 = deriv(y)
    n_events = steps = rejected = 0
    recent: list[int] = []  # indicators that fired first (named when it chatters)
    t_first = t_event = -1.0
    end = h_total * (1.0 - 1e-14)
    h = h_try if h_try > 0.0 else _first_step(y, k1, control)
    h_next = h
    h_min = max(_H_MIN_ABSOLUTE, _H_MIN_RELATIVE * h_total)
    budget = control.max_steps
    while t < end:
        if budget is not None and steps + rejected >= budget:
            raise StepBudgetSpent(
                f"spent its budget of {budget} internal steps (max_internal_steps) "
                f"{t:.6g} s into a step of {h_total:.6g} s; take shorter communication "
                "steps or give a larger budget"
            )
        left = h_total - t
        if t > 0.0 and left <= h_min:  # an event left a sliver below the time resolution
            break
        h = min(h, control.h_max)
        # Land on the end instead of leaving a sliver for one more step.
        h_step = left if h >= 0.99 * left else h
        if h_step < h_min and h_step < left:
            raise ComponentError(f"integration step underflow ({h_step:.3g} s)")
        try:
            step = _dp5_step(deriv, y, k1, h_step, control)
            g1 = model.indicators(step.y1)
        except (ArithmeticError, ValueError) as exc:
            # Outside the model's domain (e.g. past a contact end): a shorter step.
            if h_step <= 1e3 * tol_t:
                raise ComponentError(f"model evaluation failed at a tiny step: {exc}") from exc
            h = h_step * _SHRINK_ON_FAILURE
            rejected += 1
            continue
        err = step.err
        if err > 1.0:
            h = h_step * max(_SHRINK_MIN, _SAFETY * err**-_EXPONENT)
            rejected += 1
            continue
        factor = _GROW_MAX if err == 0.0 else min(_GROW_MAX, _SAFETY * err**-_EXPONENT)
        h_next = h_step * factor
        if h_step < h:  # shortened to land on the end: keep the step the error allows
            h_next = max(h_next, h)
        steps += 1
        first = -1
        th_best = h_step
        y_best = step.y1
        for i, (a, b) in enumerate(zip(g0, g1, strict=True)):
            if a >= 0.0 and b < 0.0:
                if a == 0.0:  # exactly on the switching surface: it fires at once
                    th, yy = 0.0, y
                else:
                    th, yy = _locate(model, step.dense, h_step, i, a, b, tol_t)
                if first < 0 or th < th_best:
                    first, th_best, y_best = i, th, yy
        if 0.0 < th_best < h_step:
            th_best, y_best = _restep(model, deriv, y, k1, th_best, y_best, first, control, tol_t)
        if observe is not None:
            observe(t, t + th_best, _interpolant(step.dense, t, h_step))
        if first < 0:
            y = step.y1
            t += h_step
            g0 = g1
            h = h_next
            k1 = step.k7
            if accept is not None:
                accept(y, t)  # observes only: the mode is unchanged, so k7 stays valid
                if getattr(model, "halted", False):
                    break
            continue
        y = y_best
        t += th_best
        if th_best > 0.0 and accept is not None:
            accept(y, t)
        y, fired, g0 = _fire_at_instant(model, y, first, t, g0)
        k1 = deriv(y)
        t_event = t
        if t_first < 0.0:
            t_first = t
        n_events += fired
        recent.append(first)
        if n_events > max_events:
            which = ", ".join(str(i) for i in sorted(set(recent[-20:])))
            raise ComponentError(
                f"too many events inside one step (chattering: indicators {which}, "
                f"{t:.6g} s into the step)"
            )
        h = h_next
        if getattr(model, "halted", False):
            break
    return Advanced(y, t_first, t_event, n_events, h_next, steps, rejected)


#: the compiled loops (components.kernels), tried in turn: each returns None for a model it
#: does not know
_COMPILED: list[Callable[..., tuple | None]] = []


def use_compiled_loop(kernel: ModuleType) -> None:
    """Let a kernel's ``advance`` run the models it knows (it is given the helpers its
    loop calls back)."""
    kernel.use_integration(ComponentError, StepBudgetSpent, _fire_at_instant, _first_step)
    _COMPILED.append(kernel.advance)


_KERNEL = load_kernel("m739_kernel")
if _KERNEL is not None:  # the compiled twins (components.kernels): the same results
    _KERNEL.use_step_type(_Step, _dp5_step)
    use_compiled_loop(_KERNEL)
    _dp5_step = _KERNEL.dp5_step
    dense_state = _KERNEL.dense_state
