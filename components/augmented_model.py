"""A model as :func:`components.event_integration.advance` sees it with states appended to
its own: the appended ones move by a rule of the wrapper, every event leaves them as they
are, and the model sees only its own states.
"""

from __future__ import annotations

from typing import Any


class AugmentedModel:
    """``model`` (n states) with states appended.  A subclass gives the appended states'
    derivatives (``extra_deriv``) and may pass them to the model first (``enter``)."""

    def __init__(self, model: Any, n: int) -> None:
        self.model, self.n = model, n
        self.accept = None if getattr(model, "accept", None) is None else self._accept

    @property
    def halted(self) -> bool:
        return getattr(self.model, "halted", False)

    def enter(self, y: list[float]) -> None:
        """Give the model what it takes from the appended states (nothing by default)."""

    def extra_deriv(self, y: list[float], own: list[float]) -> list[float]:
        """The appended states' derivatives at y (``own``: the model's states)."""
        raise NotImplementedError

    def deriv(self, y: list[float]) -> list[float]:
        self.enter(y)
        own = y[: self.n]
        return [*self.model.deriv(own), *self.extra_deriv(y, own)]

    def indicators(self, y: list[float]) -> tuple[float, ...]:
        self.enter(y)
        return self.model.indicators(y[: self.n])

    def event(self, y: list[float], index: int, t: float) -> list[float]:
        self.enter(y)
        n = self.n
        return [*self.model.event(y[:n], index, t), *y[n:]]

    def _accept(self, y: list[float], t: float) -> None:
        self.enter(y)
        self.model.accept(y[: self.n], t)
