"""The torque's impulse and first moment integrated over a step as quadratures."""

from __future__ import annotations

import pytest

from components.event_integration import IntegrationStepControl, advance
from components.step_moments import WithMoments


class Ramp:
    """x' = 1 with a value c0 + c1 x: over [0, dt] the line c0 + c1 s."""

    def __init__(self, c0: float, c1: float) -> None:
        self.c0, self.c1 = c0, c1

    def deriv(self, y: list[float]) -> list[float]:
        return [1.0, -0.3 * y[1]]

    def indicators(self, y: list[float]) -> tuple[float, ...]:
        return ()

    def event(self, y: list[float], index: int, t: float) -> list[float]:
        return y

    def value(self, y: list[float]) -> float:
        return self.c0 + self.c1 * y[0]


def test_a_line_gives_back_its_mean_and_rate() -> None:
    ramp = Ramp(2.0, -5.0)
    moments = WithMoments(ramp, ramp.value, 2)
    control = IntegrationStepControl(1e-8, (1.0, 1.0))
    done = advance(moments, moments.start([0.0, 1.0]), 0.4, control, 0.0)
    mean, rate = moments.mean_and_rate(done.y)
    assert done.y[2] == pytest.approx(0.4, rel=1e-12)
    assert mean == pytest.approx(2.0 - 5.0 * 0.2, rel=1e-12)
    assert rate == pytest.approx(-5.0, rel=1e-9)


def test_the_quadratures_leave_the_steps_as_they_were() -> None:
    # The states past the control's scales are not in the error norm: the same steps.
    ramp = Ramp(2.0, -5.0)
    control = IntegrationStepControl(1e-6, (1.0, 1.0))
    plain = advance(ramp, [0.0, 1.0], 3.0, control, 0.0)
    moments = WithMoments(ramp, ramp.value, 2)
    wrapped = advance(moments, moments.start([0.0, 1.0]), 3.0, control, 0.0)
    assert wrapped.steps == plain.steps and wrapped.rejected == plain.rejected
    assert wrapped.y[:2] == plain.y


def test_no_step_no_mean() -> None:
    ramp = Ramp(1.0, 1.0)
    moments = WithMoments(ramp, ramp.value, 2)
    assert moments.mean_and_rate(moments.start([0.0, 0.0])) == (0.0, 0.0)
