"""A scene's ``stop_when`` condition beside its reference (scenarios/README.md, [scene]):

- a condition that already holds when the FMUs are initialized is refused: the run would
  end after one step and compare that step with a reference at ``scene.stop``;
- a reference that gives its headline where the condition is met says so
  (``Reference.at_stop_when``); ``reference_crossing`` finds that instant in a reference's
  signals, for a family whose reference is a closed form over time;
- a run that stopped on the condition is compared only with such a reference: otherwise
  its headline errors are left out, with a note saying why.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from orchestrator.errors import RunError

#: Samples of a reference's signal over the run, to bracket the first crossing.
_SAMPLES = 4097
#: Bisections of the bracket: 2^-60 of a sample interval, below double precision.
_BISECTIONS = 60


def describe(cond: Any) -> str:
    """``a.phi above 1`` as the scene wrote it (SI)."""
    side = "above" if cond.rising else "below"
    return f"{'.'.join(cond.signal)} {side} {cond.threshold:g}"


def refuse_if_met_at_start(system: Any, scene: Any) -> None:
    """RunError when the initialized system already meets the scene's stop condition."""
    cond = scene.stop_when
    indicator = system.stop_indicator()
    if cond is None or indicator is None or indicator > 0.0:
        return
    value = cond.threshold - indicator if cond.rising else cond.threshold + indicator
    raise RunError(
        f"scene.stop_when: {describe(cond)} already holds at the start "
        f"({'.'.join(cond.signal)} = {value:.9g}): the run would end after its first step; "
        "expected a condition the run reaches",
        scene.start,
    )


def reference_crossing(signals: Any, cond: Any, start: float, stop: float) -> float | None:
    """First time in (start, stop] a reference's ``signals(times)`` meets ``cond``; None if
    it never does there, or the reference has no such signal."""
    name = ".".join(cond.signal)
    times = np.linspace(start, stop, _SAMPLES)
    values = signals(times).get(name)
    if values is None:
        return None

    def met(v: Any) -> Any:
        return np.asarray(v) >= cond.threshold if cond.rising else np.asarray(v) <= cond.threshold

    hit = np.nonzero(met(values))[0]
    if not len(hit):
        return None
    k = int(hit[0])
    if k == 0:
        return start
    lo, hi = float(times[k - 1]), float(times[k])
    for _ in range(_BISECTIONS):
        mid = 0.5 * (lo + hi)
        if met(signals(np.array([mid]))[name][0]):
            hi = mid
        else:
            lo = mid
    return hi


def keep_comparable(
    scene: Any,
    stats: Any,
    reference: Any,
    accuracy: dict[str, float],
    notes: list[str],
    time_reached: float,
) -> None:
    """Drop the headline errors of a run that stopped on its condition when the reference
    gives its headline at ``scene.stop`` instead, and say so in ``notes``."""
    stopped = stats.stopped_by_condition
    if not stopped or getattr(reference, "at_stop_when", False):
        return
    dropped = [k for k in accuracy if k.startswith("headline_error")]
    if not dropped:
        return
    for k in dropped:
        del accuracy[k]
    notes.append(
        f"headline error not computed: the run stopped on scene.stop_when "
        f"({describe(scene.stop_when)}) at t = {time_reached:.9g} s, while reference "
        f"{scene.reference!r} gives its headline at scene.stop = {scene.stop:g} s"
    )
