"""A model's output integrated over a step with its first moment: the impulse a partner
takes, and how it is spread over the step.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any


class WithMoments:
    """``model`` as :func:`components.event_integration.advance` sees it, with three states
    appended: the time since the step start s, the integral of ``value`` over the step and
    that of s times it.  An event leaves them as they are."""

    def __init__(self, model: Any, value: Callable[[list[float]], float], n: int) -> None:
        self.model, self.value, self.n = model, value, n
        self.accept = None if getattr(model, "accept", None) is None else self._accept

    @property
    def halted(self) -> bool:
        return getattr(self.model, "halted", False)

    def start(self, y: list[float]) -> list[float]:
        return [*y, 0.0, 0.0, 0.0]

    def deriv(self, y: list[float]) -> list[float]:
        n = self.n
        d = self.model.deriv(y[:n])
        v = self.value(y[:n])
        return [*d, 1.0, v, y[n] * v]

    def indicators(self, y: list[float]) -> tuple[float, ...]:
        return self.model.indicators(y[: self.n])

    def event(self, y: list[float], index: int, t: float) -> list[float]:
        n = self.n
        return [*self.model.event(y[:n], index, t), *y[n:]]

    def _accept(self, y: list[float], t: float) -> None:
        self.model.accept(y[: self.n], t)

    def mean_and_rate(self, y: list[float]) -> tuple[float, float]:
        """The value's mean over the step that ended at y and its rate about the step's
        middle: the line with the same integral and first moment."""
        n = self.n
        dt, integral, moment = y[n], y[n + 1], y[n + 2]
        if dt <= 0.0:
            return 0.0, 0.0
        return integral / dt, 12.0 * (moment - 0.5 * dt * integral) / dt**3
