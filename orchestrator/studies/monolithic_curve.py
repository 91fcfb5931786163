"""The monolithic model's own work–precision curve, and the time it needs for an accuracy.

For the scene families with a monolithic model of the whole mechanism (the family's
``monolithic`` and ``headline``; M739 and the clock-train S&A), the model runs with the
scene's physics over its own tolerances, each run timed (best of a few repeats: this
machine's timings of one run vary by 15-40 % with other load).  Every error is the relative
error of the family's headline quantity (the S&As' turns to arm) against one truth, the same
model at tolerance 1e-12 (turns move by a few 1e-9 relative between 1e-9 and 1e-10), so that
master runs and monolithic runs are measured against the same value.

The time the monolithic model needs for an accuracy ``e`` is read off the curve's lower
envelope as measured: the least wall time among the monolithic runs whose error is <= e
(a step function; no interpolation, so every time it returns is a run's own).  A report
that also times co-simulation runs times the curve again between their rounds
(``retime``), so that both see the same slow and fast spells of a shared machine.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any

from orchestrator.lazy import resolve
from orchestrator.scene_model import Scene
from orchestrator.scenes import family
from orchestrator.scenes.family import Headline, Outcome

#: Tolerance of the truth run (relative local error of the monolithic integrator).
TRUTH_TOLERANCE = 1e-12
#: The monolithic model's tolerances: M739's turns error falls from 0.1 (at 1e-4 the model
#: takes another path through the escapement) through 1e-3 .. 1e-6 to about 1e-9.
CURVE_TOLERANCES = (1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)
#: Timed runs of each monolithic tolerance (the least is kept).
REPEATS = 3
#: The accuracy window of the comparison (issue target: turns error 1e-6 .. 1e-3) and the
#: largest ratio master time / monolithic time at the same accuracy it asks for.
WINDOW = (1e-6, 1e-3)
TARGET_RATIO = 2.0


@dataclass(frozen=True)
class MonolithicPoint:
    tolerance: float
    wall_time: float  # s, best of the repeats
    error: float  # relative error against the truth (NaN: the model gave no value)


@dataclass
class MonolithicCurve:
    truth: float  # the headline quantity at TRUTH_TOLERANCE
    truth_wall_time: float
    points: list[MonolithicPoint]

    def relative_error(self, value: float) -> float:
        """Relative error of a value against this curve's truth."""
        return abs(value - self.truth) / abs(self.truth)

    def time_for(self, error: float) -> float:
        """Monolithic wall time needed for ``error`` (lower envelope; NaN: never reached)."""
        return envelope_time([(p.error, p.wall_time) for p in self.points], error)


def envelope_time(points: Iterable[tuple[float, float]], error: float) -> float:
    """The least time among the (error, time) points whose error is <= ``error``.

    NaN when ``error`` is not finite or no point is that accurate.  Points with a NaN
    error (runs that did not reach the quantity) never count.
    """
    if not math.isfinite(error):
        return math.nan
    times = [t for e, t in points if math.isfinite(e) and e <= error]
    return min(times) if times else math.nan


def time_in_window(
    curve: MonolithicCurve | None, error: float, window: tuple[float, float] = WINDOW
) -> float:
    """The monolithic time for ``error`` when it lies in ``window`` (the accuracies the
    comparison is about), else NaN; NaN too when the curve does not reach that accuracy."""
    if curve is None or not (window[0] <= error <= window[1]):
        return math.nan
    return curve.time_for(error)


def _timed(fn: Callable[[], Any]) -> tuple[float, Any]:
    t0 = time.perf_counter()
    result = fn()
    return time.perf_counter() - t0, result


def monolithic_curve(
    model: Callable[[float], Outcome], tolerances: Sequence[float] = CURVE_TOLERANCES
) -> MonolithicCurve | str:
    """Run ``model(tolerance)`` at the truth's tolerance and at each of ``tolerances``, each
    timed once (``retime`` times them again), errors against the truth.  When the truth
    gives no value (e.g. a stop before arming), why, instead of a curve."""
    truth_time, truth = _timed(lambda: model(TRUTH_TOLERANCE))
    if not math.isfinite(truth.value):
        return f"gave no value at tolerance {TRUTH_TOLERANCE:g} ({truth.reason}): no error"
    curve = MonolithicCurve(truth.value, truth_time, [])
    for tol in tolerances:
        wall, result = _timed(lambda tol=tol: model(tol))
        err = curve.relative_error(result.value) if math.isfinite(result.value) else math.nan
        curve.points.append(MonolithicPoint(tol, wall, err))
    return curve


def retime(curve: MonolithicCurve, model: Callable[[float], Any]) -> MonolithicCurve:
    """The curve with each tolerance run once more, its least time kept (the model is
    deterministic: its errors stay)."""
    points = [
        MonolithicPoint(
            p.tolerance, min(p.wall_time, _timed(lambda p=p: model(p.tolerance))[0]), p.error
        )
        for p in curve.points
    ]
    return MonolithicCurve(curve.truth, curve.truth_wall_time, points)


def monolithic_model(scene: Scene) -> tuple[Headline, Callable[[float], Outcome]] | None:
    """The monolithic model of the scene's reference family as a function of its tolerance,
    with the headline quantity it is judged by; None where the family has none."""
    declared = family(scene.reference) if scene.reference else None
    if declared is None or declared.monolithic is None or declared.headline is None:
        return None
    return declared.headline, resolve(declared.monolithic)(scene)
