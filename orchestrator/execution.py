"""The execution loop every master shares: macro steps until the stop rule ends the run.

The master (orchestrator/masters/) only steps; the stop rule says when the run ends (its
stop time, or its ``stop_when`` condition after the step that meets it); the observers
(orchestrator/observers.py: the time series, the regime log, the step counter, the energy
balance, any other) are told the start and every step, all alike.  The loop reports
progress and, on an interruption, tells the observers where the run stopped.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

from orchestrator.interrupt import Interrupted
from orchestrator.masters.macro_step import Master
from orchestrator.observers import Observer, regime_changes
from orchestrator.system import CoupledSystem

#: relative: a run this close to its stop time has reached it
STOP_SLACK = 1e-15


def end_time(stop: float) -> float:
    """The instant from which a run has reached its stop time (within rounding)."""
    return stop - STOP_SLACK * max(1.0, abs(stop))


def condition_met(system: CoupledSystem) -> bool:
    """The scene's ``stop_when`` condition holds now."""
    indicator = system.stop_indicator()
    return indicator is not None and indicator <= 0.0


@dataclass(frozen=True)
class StopRule:
    """When a run ends: at ``stop``, or after the step that meets the system's stop
    condition (the scene's ``stop_when``, if any)."""

    start: float
    stop: float
    system: CoupledSystem

    def met(self) -> bool:
        return condition_met(self.system)


def execute(
    master: Master,
    rule: StopRule,
    observers: Sequence[Observer],
    progress: Callable[[float], None],
) -> None:
    """Run ``master`` (set up and started on an initialized system) from the rule's start
    until it says stop.

    ``progress(t)`` is called after every step, between FMU calls: it may raise
    ``Interrupted``, and the observers are then told where the run stopped."""
    system = master.system
    t, stop = rule.start, rule.stop
    end = end_time(stop)
    for observer in observers:
        observer.start(t)
    regimes = system.regimes()
    while t < end:
        step = master.step(t, stop)
        t = step.end
        now = system.regimes()
        before = regimes if step.regimes_before is None else step.regimes_before
        step.changes = regime_changes(system, before, now)
        regimes = now
        done = rule.met()
        step.last = done or t >= end
        for observer in observers:
            observer.step(step)
        if step.failure is not None:
            raise step.failure
        try:
            progress(t)
        except Interrupted:
            for observer in observers:
                observer.interrupted(t)
            raise
        if done:  # the step that met the condition is the last
            master.stats.stopped_by_condition = True
            return
