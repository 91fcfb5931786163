"""Integration of a piecewise-smooth model with its discrete mode frozen inside a step, and
exact location of the sign changes of its indicators (events).

A model changes its mode only in ``event`` (after an indicator crossing) or ``accept``
(after an accepted step); between those its right-hand side is smooth.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Protocol

from .base import ComponentError


class EventModel(Protocol):
    """What :func:`advance` needs from a model (the mode lives inside the model)."""

    def deriv(self, y: list[float]) -> list[float]: ...

    def indicators(self, y: list[float]) -> Sequence[float]: ...

    def event(self, y: list[float], index: int, t: float) -> list[float]: ...

    def accept(self, y: list[float], t: float) -> None: ...


def rk4(deriv: Callable[[list[float]], list[float]], y: list[float], h: float) -> list[float]:
    """One classical Runge-Kutta step (the mode is frozen during the step)."""
    n = len(y)
    k1 = deriv(y)
    k2 = deriv([y[i] + 0.5 * h * k1[i] for i in range(n)])
    k3 = deriv([y[i] + 0.5 * h * k2[i] for i in range(n)])
    k4 = deriv([y[i] + h * k3[i] for i in range(n)])
    h6 = h / 6.0
    return [y[i] + h6 * (k1[i] + 2.0 * (k2[i] + k3[i]) + k4[i]) for i in range(n)]


def _locate(
    model: EventModel, y: list[float], h: float, idx: int, g_lo: float, g_hi: float, tol: float
) -> tuple[float, list[float]]:
    """Illinois root search on the step length for indicator idx (g_lo >= 0 > g_hi).

    Returns the first point found with the indicator < 0, i.e. just past the crossing,
    so that the event handler always sees the new side.
    """
    lo, hi = 0.0, h
    y_hi = None
    side = 0
    for _ in range(60):
        if hi - lo <= tol:
            break
        th = hi - g_hi * (hi - lo) / (g_hi - g_lo)
        if not (lo < th < hi):
            th = 0.5 * (lo + hi)
        yt = rk4(model.deriv, y, th)
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
        y_hi = rk4(model.deriv, y, hi)
    return hi, y_hi


def advance(
    model: EventModel,
    y: list[float],
    h_total: float,
    h_max: float,
    tol_t: float = 1e-14,
    max_events: int = 2000,
) -> tuple[list[float], float, float, int]:
    """Integrate over h_total in RK4 steps <= h_max, stopping exactly at indicator crossings.

    An indicator fires when it goes from >= 0 to < 0.  The model's ``event`` changes its
    mode (and may change y); the integration then continues from the event point.
    Returns (y, offsets of the first and of the last event from the start (-1.0 if
    none), number of events).
    """
    t = 0.0
    g0 = model.indicators(y)
    n_events = 0
    t_first = t_event = -1.0
    end = h_total * (1.0 - 1e-14)
    while t < end:
        h = min(h_max, h_total - t)
        y1 = rk4(model.deriv, y, h)
        g1 = model.indicators(y1)
        first = -1
        th_best = h
        y_best = y1
        for i, (a, b) in enumerate(zip(g0, g1, strict=True)):
            if a >= 0.0 and b < 0.0:
                if a == 0.0:
                    th, yy = 0.0, y
                else:
                    th, yy = _locate(model, y, h, i, a, b, tol_t)
                if first < 0 or th < th_best:
                    first, th_best, y_best = i, th, yy
        if first < 0:
            y = y1
            t += h
            model.accept(y, t)
            g0 = g1
            continue
        y = y_best
        t += th_best
        if th_best > 0.0:
            model.accept(y, t)
        y = model.event(y, first, t)
        g0 = model.indicators(y)
        t_event = t
        if t_first < 0.0:
            t_first = t
        n_events += 1
        if n_events > max_events:
            raise ComponentError("too many events inside one step (chattering)")
        if getattr(model, "halted", False):
            break
    return y, t_first, t_event, n_events
