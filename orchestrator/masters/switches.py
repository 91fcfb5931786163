"""Switches as the regime-aware master sees them: what it reads at a step start, where a
trial step switched, when a step has landed on a switch, and the exchange there.

An FMU that reports its internal event time (``t_event``) gives the switching instant
exactly; an event indicator (outputs named ``ind_*``, the scene's stop condition among
them) that changed sign gives a secant estimate; a regime that changed without either, the
middle of the step.  A step lands on a switch when it ends within ``event_tolerance`` of
it, or, on an instant an FMU reported, within one instant (``settle_window`` event
tolerances): retaking a step moves the FMU's located instant by the retake's own rounding
and held inputs, and chasing that costs trials for nothing measurable.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, NamedTuple

from orchestrator.errors import RunError
from orchestrator.master_settings import RegimeAwareSettings
from orchestrator.observers import regime_changes
from orchestrator.system import CoupledSystem


@dataclass(frozen=True)
class Readings:
    """Everything read from the FMUs at one instant."""

    values: list[list[float]]
    ints: list[list[int]]
    regimes: list[int | None]
    indicators: list[list[float]]
    stop: float | None  # the scene's stop indicator (> 0 until the condition is met)


def read(system: CoupledSystem) -> Readings:
    """The FMUs' values, regimes and indicators as the system holds them now (copied)."""
    return Readings(
        [list(v) for v in system.values],
        [list(v) for v in system.ints],
        system.regimes(),
        system.indicators(),
        system.stop_indicator(),
    )


@dataclass(frozen=True)
class StepStart:
    """Where a macro step starts: its instant, every FMU's saved state and the readings."""

    t: float
    state: list[Any]
    before: Readings


def back_to_start(system: CoupledSystem, start: StepStart) -> None:
    """Every FMU back to the step start; the values there are those read then."""
    system.set_state(start.state, (start.before.values, start.before.ints))


class Switch(NamedTuple):
    """The earliest switch inside a trial step."""

    at: float  # its instant
    located: bool  # an instant an FMU reported (not an estimate from an indicator)


@dataclass(frozen=True)
class Landing:
    """When a step ends on a switch (see the module doc)."""

    event_tolerance: float
    instant: float  # switches this close are one instant
    min_step: float

    @classmethod
    def of(cls, settings: RegimeAwareSettings) -> Landing:
        instant = settings.control.settle_window * settings.event_tolerance
        return cls(settings.event_tolerance, instant, settings.min_step)

    def window(self, located: bool) -> float:
        """How far before the step end a switch may be for the step to end on it."""
        return self.instant if located else self.event_tolerance

    def lands(self, t: float, h: float, switch: Switch) -> bool:
        """Whether the step [t, t+h] ends on ``switch`` (or cannot be shortened)."""
        return t + h - switch.at <= self.window(switch.located) or h <= self.min_step


def switch_time(
    system: CoupledSystem, t: float, h: float, before: Readings, slack: float
) -> Switch | None:
    """Earliest switch inside (t, t+h] of the step just taken, None if nothing switched.
    ``slack``: how far past the step end (relative to h) a reported event time counts."""
    after_regimes, after_ind = system.regimes(), system.indicators()
    # An input signal's jump where the step ends is a known, located switch.
    best = reported = t + h if system.signals.jump_at(t + h) else None
    g1 = system.stop_indicator()
    if g1 is not None and g1 <= 0.0 < before.stop:
        best = t + h * before.stop / (before.stop - g1)
    for i, watch in enumerate(system.watches):
        fired = after_regimes[i] != before.regimes[i]
        if watch.t_event is not None:
            te = system.values[i][watch.t_event]
            if t < te <= t + h * (1 + slack):
                best = te if best is None else min(best, te)
                reported = te if reported is None else min(reported, te)
                continue
            if fired and te == t:
                # Switched at the step start, on inputs that crossed by t: land on it
                # with a step of event_tolerance / 2, so that the exchange at the switch
                # (an impact's momentum) reaches the others before they move on.
                best = t if best is None else min(best, t)
                continue
        for g0, g1 in zip(before.indicators[i], after_ind[i], strict=True):
            # A crossing leaves one strict sign; an indicator starting at zero (the
            # switch it marks has just happened) does not switch again by leaving it.
            if g0 > 0.0 >= g1 or g0 < 0.0 <= g1:
                te = t + h * g0 / (g0 - g1)
                best = te if best is None else min(best, te)
        if fired and best is None:
            best = t + 0.5 * h
    if best is None:
        return None
    return Switch(best, best == reported)


def settle(system: CoupledSystem, max_iterations: int) -> int:
    """Exchange at one instant until the values stop changing (event iteration): the
    rounds it took."""
    for rounds in range(1, max_iterations + 1):
        old = [list(v) for v in system.values], [list(v) for v in system.ints]
        system.exchange()
        if (system.values, system.ints) == old:
            return rounds
    raise RunError(f"the exchange at a switching instant did not settle in {max_iterations} rounds")


class ChatteringGuard:
    """Ends a run that keeps switching within one instant (chattering, Zeno), naming the
    last regime change it saw."""

    def __init__(self, system: CoupledSystem, instant: float, max_events: int) -> None:
        self.system, self.instant, self.max_events = system, instant, max_events
        self.same_instant = 0  # switches in a row within one instant
        self.last_change: tuple[str, str, str] | None = None  # (FMU, from, to)

    def note_changes(self, before: Readings) -> list[tuple[str, str, str]]:
        """The regime changes since ``before`` (the last one kept for the diagnosis)."""
        changes = regime_changes(self.system, before.regimes, self.system.regimes())
        if changes:
            self.last_change = changes[-1]
        return changes

    def smooth_step(self) -> None:
        """A step that ended on no switch."""
        self.same_instant = 0

    def switch_step(self, h: float, end: float) -> RunError | None:
        """After a step of h onto a switch: the error that ends the run, else None."""
        self.same_instant = self.same_instant + 1 if h <= self.instant else 0
        if self.same_instant <= self.max_events:
            return None
        return RunError(
            f"chattering: {self.same_instant} switches within {self.instant:.1e} s of each "
            f"other; last in {self._last_switch()}",
            end,
        )

    def _last_switch(self) -> str:
        if self.last_change is None:
            return "no FMU"
        sub, a, b = self.last_change
        return f"FMU {sub!r} ({a} -> {b})"
