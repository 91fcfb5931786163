"""Fixed-step Jacobi and Gauss–Seidel masters: what every co-simulation tool offers.

Inputs are held over each macro step (zero-order hold).  Jacobi steps every FMU with the
outputs of the previous communication point; Gauss–Seidel steps them in the scene's
order, each with the newest outputs of those already stepped.  Both are first order in
the macro step for a generic coupling; they are the baseline the regime-aware master beats.
"""

from __future__ import annotations

import math

from orchestrator.master_settings import FixedStepSettings
from orchestrator.recorder import Recorder, RegimeLog, StepStats
from orchestrator.scenario import Scene
from orchestrator.system import CoupledSystem


def _grid(start: float, stop: float, h: float) -> int:
    """Number of macro steps of h; the last step is shortened to land on stop."""
    return math.ceil((stop - start) / h - 1e-9)


def run_fixed_step(
    system: CoupledSystem,
    h: float,
    start: float,
    stop: float,
    record_every: int,
    recorder: Recorder,
    stats: StepStats,
    progress,
    sequential: bool,
) -> None:
    """Macro steps of h from start to stop, a row recorded every ``record_every`` steps."""
    n = _grid(start, stop, h)
    m = len(system.instances)
    every = record_every
    recorder.row(system.record_row(start))
    log = RegimeLog(system, recorder)
    t = start
    signals = system.signals if system.signals else None
    k = 0  # grid steps done
    while k < n:
        grid = start + (k + 1) * h if k < n - 1 else stop
        t_end = grid if signals is None else signals.land(t, grid)  # a signal's breakpoint
        on_grid = grid - t_end <= 1e-9 * h  # ends a step too
        hk = (h if k < n - 1 else stop - t) if signals is None else t_end - t
        if sequential:  # Gauss–Seidel: each FMU sees the newest outputs
            for i in range(m):
                system.feed(i)
                system.step(i, t, hk)
                system.read(i)
        else:  # Jacobi: all FMUs see the outputs of the last communication point
            for i in range(m):
                system.feed(i)
                system.step(i, t, hk)
            system.read_all()
        t = t_end
        k += on_grid
        stats.steps += 1
        stats.do_steps += m
        stats.events += log.update(t)
        stop_indicator = system.stop_indicator()
        done = stop_indicator is not None and stop_indicator <= 0.0
        if k % every == 0 or k == n or done or not on_grid:
            recorder.row(system.record_row(t))
        progress(t)
        if done:  # a fixed-step master stops at the first step past the condition
            stats.extra["stopped_by_condition"] = True
            return


def run_fixed_step_scene(
    system: CoupledSystem,
    scene: Scene,
    step: float,
    recorder: Recorder,
    stats: StepStats,
    progress,
    sequential: bool,
) -> None:
    """``run_fixed_step`` over the scene's span at its record interval."""
    run_fixed_step(
        system,
        step,
        scene.start,
        scene.stop,
        scene.record_every,
        recorder,
        stats,
        progress,
        sequential,
    )


def _run(system, scene: Scene, recorder, stats, progress, sequential: bool) -> None:
    settings: FixedStepSettings = scene.master.settings
    run_fixed_step_scene(system, scene, settings.step, recorder, stats, progress, sequential)


def run_jacobi(
    system: CoupledSystem, scene: Scene, recorder: Recorder, stats: StepStats, progress
) -> None:
    _run(system, scene, recorder, stats, progress, sequential=False)


def run_gauss_seidel(
    system: CoupledSystem, scene: Scene, recorder: Recorder, stats: StepStats, progress
) -> None:
    _run(system, scene, recorder, stats, progress, sequential=True)
