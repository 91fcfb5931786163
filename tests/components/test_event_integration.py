"""The shared event-locating integrator: order, error control, dense output, events."""

from __future__ import annotations

import math

import pytest

from components.base import ComponentError
from components.event_integration import (
    StepControl,
    _dp5_step,
    advance,
    dense_state,
)


class Oscillator:
    """x'' = -x from x = 1, with the indicator x + 1/2 (crosses down at 2 pi / 3 + 2 pi k)."""

    def __init__(self) -> None:
        self.events: list[float] = []

    def deriv(self, y: list[float]) -> list[float]:
        return [y[1], -y[0]]

    def indicators(self, y: list[float]) -> tuple[float]:
        return (y[0] + 0.5,)

    def event(self, y: list[float], index: int, t: float) -> list[float]:
        self.events.append(t)
        return y


class BouncingBall:
    """Height and speed under gravity; restitution 0.8 at the floor (an event changing y,
    left just below the floor where it was located, as the integrator's contract says)."""

    def __init__(self) -> None:
        self.bounces: list[float] = []

    def deriv(self, y: list[float]) -> list[float]:
        return [y[1], -9.81]

    def indicators(self, y: list[float]) -> tuple[float]:
        return (y[0],)

    def event(self, y: list[float], index: int, t: float) -> list[float]:
        self.bounces.append(t)
        return [y[0], -0.8 * y[1]]


def test_error_follows_the_tolerance() -> None:
    errors = []
    for rtol in (1e-6, 1e-8, 1e-10):
        done = advance(Oscillator(), [1.0, 0.0], 10.0, StepControl(rtol, (1.0, 1.0)))
        errors.append(abs(done.y[0] - math.cos(10.0)))
        assert errors[-1] < 100 * rtol
    # Each hundredfold tightening buys about a hundredfold (the global error is ~ rtol).
    assert errors[1] < errors[0] / 30 and errors[2] < errors[1] / 30


def test_events_located_to_the_time_tolerance() -> None:
    model = Oscillator()
    done = advance(model, [1.0, 0.0], 10.0, StepControl(1e-10, (1.0, 1.0)))
    exact = [2.0 * math.pi / 3.0, 2.0 * math.pi / 3.0 + 2.0 * math.pi]
    assert done.events == 2
    assert model.events == pytest.approx(exact, abs=1e-9)
    assert done.t_first_event == model.events[0] and done.t_last_event == model.events[1]


def test_dense_output_is_fifth_order_locally() -> None:
    model = Oscillator()
    errs = []
    for h in (0.2, 0.1, 0.05):
        y = [1.0, 0.0]
        step = _dp5_step(model.deriv, y, model.deriv(y), h, StepControl(1e-6, (1.0, 1.0)))
        errs.append(abs(dense_state(step.dense, 0.37)[0] - math.cos(0.37 * h)))
    assert errs[0] / errs[1] > 30 and errs[1] / errs[2] > 30


def test_bounces_match_the_closed_form() -> None:
    ball = BouncingBall()
    # A parabola has no error to control, so the steps would grow over a whole flight and
    # never see a sign change at a step end: h_max bounds that.
    advance(ball, [1.0, 0.0], 2.0, StepControl(1e-10, (1.0, 1.0), 0.05), max_events=50)
    t1 = math.sqrt(2.0 / 9.81)
    expected = [t1 + sum(2.0 * 0.8**k * t1 for k in range(1, n + 1)) for n in range(3)]
    assert ball.bounces[:3] == pytest.approx(expected, rel=1e-9)


def test_step_size_carries_over_and_output_is_observed() -> None:
    seen: list[tuple[float, float]] = []
    control = StepControl(1e-8, (1.0, 1.0))
    first = advance(Oscillator(), [1.0, 0.0], 1.0, control)
    again = advance(
        Oscillator(),
        first.y,
        1.0,
        control,
        first.h_next,
        observe=lambda t0, t1, at: seen.append((t1, at(t1)[0])),
    )
    assert again.rejected == 0 and again.steps <= first.steps
    assert seen[-1][0] == pytest.approx(1.0)
    assert seen[-1][1] == pytest.approx(again.y[0], abs=1e-12)


def test_bad_controls_are_refused() -> None:
    for rtol, h_max in ((0.0, 1.0), (2.0, 1.0), (1e-6, 0.0), (math.nan, 1.0)):
        with pytest.raises(ComponentError):
            StepControl(rtol, (1.0,), h_max)
