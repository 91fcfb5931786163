"""The execution loop every master shares: macro steps until the run ends.

The master (orchestrator/masters/) only steps; this loop decides when the run ends (the
scene's stop time, or its ``stop_when`` condition after the step that meets it), hands each
step to the observers (orchestrator/observers.py), reports progress, and on an
interruption keeps the values at the step boundary reached.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Protocol

from orchestrator.interrupt import Interrupted
from orchestrator.masters import MASTERS, MacroStep
from orchestrator.observers import RegimeLog, StepCounter, TimeSeries
from orchestrator.recorder import Recorder, StepStats
from orchestrator.scene_model import Scene
from orchestrator.system import CoupledSystem

#: relative: a run this close to its stop time has reached it
STOP_SLACK = 1e-15


class Observer(Protocol):
    """What else watches a run: told the start and every step, after the record."""

    def start(self, t: float) -> None: ...

    def step(self, step: MacroStep) -> None: ...


def end_time(stop: float) -> float:
    """The instant from which a run has reached its stop time (within rounding)."""
    return stop - STOP_SLACK * max(1.0, abs(stop))


def condition_met(system: CoupledSystem) -> bool:
    """The scene's ``stop_when`` condition holds now."""
    indicator = system.stop_indicator()
    return indicator is not None and indicator <= 0.0


def execute(
    system: CoupledSystem,
    scene: Scene,
    recorder: Recorder,
    stats: StepStats,
    progress: Callable[[float], None],
    observers: Sequence[Observer] = (),
) -> None:
    """Run the scene's master over its span on an initialized ``system``.

    ``progress(t)`` is called after every step, between FMU calls: it may raise
    ``Interrupted``, and the run then ends with the values at t recorded.  ``observers``
    are told the start and every step besides the record, the regime log and the counts."""
    master = MASTERS[scene.master.algorithm](system, scene, stats)
    series = TimeSeries(system, recorder, scene.record_every)
    log = RegimeLog(system, recorder)
    counter = StepCounter(stats)
    t, stop = scene.start, scene.stop
    end = end_time(stop)
    series.start(t)
    for observer in observers:
        observer.start(t)
    count = 0
    while t < end:
        step = master.step(t, stop)
        t = step.end
        count += 1
        logged = log.update(t if step.changes_at is None else step.changes_at, step.regimes_before)
        counter.step(step, logged)
        done = condition_met(system)
        series.step(count, step, last=done or t >= end)
        for observer in observers:
            observer.step(step)
        if step.failure is not None:
            raise step.failure
        try:
            progress(t)
        except Interrupted:
            series.keep(t)
            raise
        if done:  # the step that met the condition is the last
            stats.extra["stopped_by_condition"] = True
            return
