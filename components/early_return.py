"""Early return: a component that ends its step at its first event after the step start.

A master that lands on every switch would otherwise retake a step that crossed one, and
every FMU with it.  With the Integer input ``early_return`` set to 1 the component's step
stops just after its first event (a regime change, an impact, a friction sign or a branch:
any event after which an exchanged output jumps) and ``t_reached`` says where; the next
step starts there.  This is FMI 3.0's early return; in FMI 2.0 the host asks for it through
the input and reads the output.  With 0 (the default) every step reaches its end, as FMI
2.0 hosts expect.
"""

from __future__ import annotations

from typing import Any

from .base import Role, Variable

EARLY_RETURN_VARIABLES = (
    Variable(
        "early_return",
        "input",
        "1",
        0,
        "1: end a step at its first event after the step start (see t_reached)",
        "Integer",
        sampled=True,
        role=Role("early_return"),
    ),
    Variable(
        "t_reached",
        "output",
        "s",
        0.0,
        "where the last step ended (early return)",
        role=Role("reached_time"),
    ),
)


class UntilFirstEvent:
    """A model as :func:`components.event_integration.advance` sees it when the step is to
    end at its first event after the start: the integration halts there.  An event at the
    very start (the inputs crossed an indicator), or closer to it than the resolution of
    the start time, does not end the step."""

    def __init__(self, model: Any, start: float = 0.0) -> None:
        self.model = model
        self.start = start  # the step's start time: an event must move it to end there
        self.deriv = model.deriv
        self.indicators = model.indicators
        self.accept = getattr(model, "accept", None)
        self.stopped_at = -1.0  # offset from the step start where the step ended early

    @property
    def halted(self) -> bool:
        return self.model_halted or self.stopped_at >= 0.0

    @property
    def model_halted(self) -> bool:
        """The model itself halted (not just the step): the other events of the instant
        the step ends at still fire unless this is true."""
        return getattr(self.model, "halted", False)

    def event(self, y: list[float], index: int, t: float) -> list[float]:
        y = self.model.event(y, index, t)
        if self.start + t > self.start:  # not at the start (nor below its resolution)
            self.stopped_at = t
        return y


def reached(t: float, h: float, model: Any) -> float:
    """Where a step from t of length h ended: at the event ``model`` (an UntilFirstEvent, or
    the bare model when no early return was asked) stopped at, else at its end."""
    stopped = getattr(model, "stopped_at", -1.0)
    return t + stopped if stopped >= 0.0 else t + h
