"""A model's output integrated over a step with its first moment: the impulse a partner
takes, and how it is spread over the step.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from .augmented_model import AugmentedModel


class WithMoments(AugmentedModel):
    """``model`` with three states appended: the time since the step start s, the integral
    of ``value`` over the step and that of s times it."""

    def __init__(self, model: Any, value: Callable[[list[float]], float], n: int) -> None:
        super().__init__(model, n)
        self.value = value

    def start(self, y: list[float]) -> list[float]:
        return [*y, 0.0, 0.0, 0.0]

    def extra_deriv(self, y: list[float], own: list[float]) -> list[float]:
        v = self.value(own)
        return [1.0, v, y[self.n] * v]

    def mean_and_rate(self, y: list[float]) -> tuple[float, float]:
        """The value's mean over the step that ended at y and its rate about the step's
        middle: the line with the same integral and first moment."""
        n = self.n
        dt, integral, moment = y[n], y[n + 1], y[n + 2]
        if dt <= 0.0:
            return 0.0, 0.0
        return integral / dt, 12.0 * (moment - 0.5 * dt * integral) / dt**3
