"""The shared event-locating integrator: order, error control, dense output, events."""

from __future__ import annotations

import math

import pytest

from components.base import ComponentError
from components.event_integration import (
    IntegrationStepControl,
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
        done = advance(Oscillator(), [1.0, 0.0], 10.0, IntegrationStepControl(rtol, (1.0, 1.0)))
        errors.append(abs(done.y[0] - math.cos(10.0)))
        assert errors[-1] < 100 * rtol
    # Each hundredfold tightening buys about a hundredfold (the global error is ~ rtol).
    assert errors[1] < errors[0] / 30 and errors[2] < errors[1] / 30


def test_events_located_to_the_time_tolerance() -> None:
    model = Oscillator()
    done = advance(model, [1.0, 0.0], 10.0, IntegrationStepControl(1e-10, (1.0, 1.0)))
    exact = [2.0 * math.pi / 3.0, 2.0 * math.pi / 3.0 + 2.0 * math.pi]
    assert done.events == 2
    assert model.events == pytest.approx(exact, abs=1e-9)
    assert done.t_first_event == model.events[0] and done.t_last_event == model.events[1]


def test_dense_output_is_fifth_order_locally() -> None:
    model = Oscillator()
    errs = []
    for h in (0.2, 0.1, 0.05):
        y = [1.0, 0.0]
        step = _dp5_step(
            model.deriv, y, model.deriv(y), h, IntegrationStepControl(1e-6, (1.0, 1.0))
        )
        errs.append(abs(dense_state(step.dense, 0.37)[0] - math.cos(0.37 * h)))
    assert errs[0] / errs[1] > 30 and errs[1] / errs[2] > 30


def test_bounces_match_the_closed_form() -> None:
    ball = BouncingBall()
    # A parabola has no error to control, so the steps would grow over a whole flight and
    # never see a sign change at a step end: h_max bounds that.
    advance(ball, [1.0, 0.0], 2.0, IntegrationStepControl(1e-10, (1.0, 1.0), 0.05), max_events=50)
    t1 = math.sqrt(2.0 / 9.81)
    expected = [t1 + sum(2.0 * 0.8**k * t1 for k in range(1, n + 1)) for n in range(3)]
    assert ball.bounces[:3] == pytest.approx(expected, rel=1e-9)


def test_step_size_carries_over_and_output_is_observed() -> None:
    seen: list[tuple[float, float]] = []
    control = IntegrationStepControl(1e-8, (1.0, 1.0))
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
            IntegrationStepControl(rtol, (1.0,), h_max)


class TwoClocks:
    """y' = 1 from 0; indicators 1 - y and 1 - y (one instant, t = 1) and 2 - y (t = 2).
    Each event is logged with its index and time; it changes nothing."""

    def __init__(self) -> None:
        self.fired: list[tuple[int, float]] = []

    def deriv(self, y: list[float]) -> list[float]:
        return [1.0]

    def indicators(self, y: list[float]) -> tuple[float, float, float]:
        return (1.0 - y[0], 1.0 - y[0], 2.0 - y[0])

    def event(self, y: list[float], index: int, t: float) -> list[float]:
        self.fired.append((index, t))
        return y


def test_two_indicators_crossing_at_one_instant_both_fire() -> None:
    model = TwoClocks()
    done = advance(model, [0.0], 3.0, IntegrationStepControl(1e-8, (1.0,)), tol_t=1e-13)
    assert [i for i, _ in model.fired] == [0, 1, 2]  # index order at one instant
    (_, t0), (_, t1), (_, t2) = model.fired
    assert t0 == t1 == pytest.approx(1.0, abs=1e-12)
    assert t2 == pytest.approx(2.0, abs=1e-12)
    assert done.events == 3


class StopOnTheMark:
    """A wheel that runs at unit speed.  Index 0: a mark every 1 (the hand-over, which
    re-indexes the mark and moves a stop indicator 1 - k/2 its change of state leaves past
    zero at t = 2); index 1: the stop."""

    def __init__(self) -> None:
        self.mark = 1.0
        self.stop_at = 5.0
        self.fired: list[tuple[int, float]] = []
        self.halted = False

    def deriv(self, y: list[float]) -> list[float]:
        return [1.0]

    def indicators(self, y: list[float]) -> tuple[float, float]:
        return (self.mark - y[0], self.stop_at - y[0])

    def event(self, y: list[float], index: int, t: float) -> list[float]:
        self.fired.append((index, t))
        if index == 0:
            self.mark += 1.0
            if self.mark > 2.5:  # the hand-over at t = 2 moves the stop behind the wheel
                self.stop_at = 1.9
        else:
            self.halted = True
        return y


def test_an_event_that_leaves_another_indicator_past_zero_fires_it() -> None:
    model = StopOnTheMark()
    done = advance(model, [0.0], 10.0, IntegrationStepControl(1e-8, (1.0,)), tol_t=1e-13)
    assert [i for i, _ in model.fired] == [0, 0, 1]
    assert [t for _, t in model.fired] == pytest.approx([1.0, 2.0, 2.0], abs=1e-12)
    assert model.halted
    assert done.y[0] == pytest.approx(2.0, abs=1e-12)  # stopped where it fired


def test_an_indicator_negative_before_the_step_does_not_fire() -> None:
    """Only indicators armed (>= 0) at the step start can fire at an event's instant."""
    model = StopOnTheMark()
    model.stop_at = -1.0  # behind the wheel from the start: never armed
    advance(model, [0.0], 3.5, IntegrationStepControl(1e-8, (1.0,)), tol_t=1e-13)
    assert [i for i, _ in model.fired] == [0, 0, 0]


def test_an_early_return_still_fires_every_event_of_its_instant() -> None:
    """A step that ends at its first event (early return) ends after the instant's other
    events, not between them: the next step would start with them below zero."""
    from components.early_return import UntilFirstEvent

    model = TwoClocks()
    wrapper = UntilFirstEvent(model, 0.0)
    done = advance(wrapper, [0.0], 3.0, IntegrationStepControl(1e-8, (1.0,)), tol_t=1e-13)
    assert [i for i, _ in model.fired] == [0, 1]  # both of t = 1, not the one at t = 2
    assert done.y[0] == pytest.approx(1.0, abs=1e-12)
    assert wrapper.stopped_at == pytest.approx(1.0, abs=1e-12)


class StuckOnTheSurface:
    """An event that leaves its indicator exactly at zero, moving on: it fires again at
    once, without end (a model error the integrator must name, not hang on)."""

    def deriv(self, y: list[float]) -> list[float]:
        return [1.0]

    def indicators(self, y: list[float]) -> tuple[float, float]:
        return (1.0, 0.5 - y[0])

    def event(self, y: list[float], index: int, t: float) -> list[float]:
        return [0.5]


def test_chattering_names_the_indicator_and_where() -> None:
    with pytest.raises(ComponentError, match=r"chattering: indicators 1, 0\.5 s into the step"):
        advance(
            StuckOnTheSurface(), [0.0], 2.0, IntegrationStepControl(1e-8, (1.0,)), max_events=50
        )
