"""The monolithic model's own work–precision curve, and the time it needs for an accuracy.

For the scene families with a monolithic model of the whole mechanism (M739 and the
clock-train S&A), the model runs with the scene's physics over its own tolerances, each
run timed (best of a few repeats: this machine's timings of one run vary by 15-40 % with
other load).  Every error is the relative turns-to-arm error against one truth, the same
model at tolerance 1e-12 (turns move by a few 1e-9 relative between 1e-9 and 1e-10), so
that master runs and monolithic runs are measured against the same value.

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

from orchestrator.scene_model import Scene

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
#: The headline quantity both the masters and the monolithic model are judged by.
QUANTITY = "turns_to_arm"


@dataclass(frozen=True)
class MonolithicPoint:
    tolerance: float
    wall_time: float  # s, best of the repeats
    error: float  # relative turns error against the truth (NaN: the model did not arm)


@dataclass
class MonolithicCurve:
    truth: float  # turns to arm at TRUTH_TOLERANCE
    truth_wall_time: float
    points: list[MonolithicPoint]

    def relative_error(self, turns: float) -> float:
        """Relative turns error of a value against this curve's truth."""
        return abs(turns - self.truth) / abs(self.truth)

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
    model: Callable[[float], Any], tolerances: Sequence[float] = CURVE_TOLERANCES
) -> MonolithicCurve | str:
    """Run ``model(tolerance)`` (a result with ``armed``, ``turns`` and ``reason``) at the
    truth's tolerance and at each of ``tolerances``, each timed once (``retime`` times them
    again), errors against the truth.  When the truth does not arm (e.g. a stop before
    arming), why, instead of a curve."""
    truth_time, truth = _timed(lambda: model(TRUTH_TOLERANCE))
    if not truth.armed:
        return f"did not arm at tolerance {TRUTH_TOLERANCE:g} ({truth.reason}): no turns error"
    curve = MonolithicCurve(truth.turns, truth_time, [])
    for tol in tolerances:
        wall, result = _timed(lambda tol=tol: model(tol))
        err = curve.relative_error(result.turns) if result.armed else math.nan
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


def _m739(scene: Scene) -> Callable[[float], Any]:
    # The same arguments as the family's reference (orchestrator/scenes/m739/report.py).
    from orchestrator.scenes.m739.monolithic import run_m739
    from orchestrator.scenes.m739.report import monolithic_arguments

    kwargs = monolithic_arguments(scene)
    return lambda tolerance: run_m739(tolerance=tolerance, **kwargs)


def _clock_train(scene: Scene) -> Callable[[float], Any]:
    # The same arguments as the family's reference (orchestrator/scenes/clock_train/report.py).
    from orchestrator.scenes.clock_train.monolithic import run_clock_train
    from orchestrator.scenes.clock_train.report import monolithic_arguments

    kwargs = monolithic_arguments(scene)
    return lambda tolerance: run_clock_train(tolerance=tolerance, **kwargs)


#: Families (by the scene's ``report.reference``) with a monolithic model run over tolerances.
MODELS: dict[str, Callable[[Scene], Callable[[float], Any]]] = {
    "m739": _m739,
    "clock_train": _clock_train,
}


def monolithic_model(scene: Scene) -> Callable[[float], Any] | None:
    """The scene's monolithic model as a function of its tolerance; None if it has none."""
    make = MODELS.get(scene.reference or "")
    return make(scene) if make else None
