"""Fixed-step Jacobi and Gauss–Seidel masters: what every co-simulation tool offers.

Inputs are held over each macro step (zero-order hold).  Jacobi steps every FMU with the
outputs of the previous communication point; Gauss–Seidel steps them in the scene's
order, each with the newest outputs of those already stepped.  Both are first order in
the macro step for a generic coupling; they are the baseline the regime-aware master beats.
"""

from __future__ import annotations

import math

from orchestrator.recorder import Recorder, RegimeLog, StepStats
from orchestrator.scenario import Scene
from orchestrator.system import CoupledSystem


def _grid(scene: Scene) -> tuple[int, float]:
    """Number of macro steps and the step; the last step is shortened to land on stop."""
    h = scene.master.step
    n = math.ceil((scene.stop - scene.start) / h - 1e-9)
    return n, h


def _run(
    system: CoupledSystem,
    scene: Scene,
    recorder: Recorder,
    stats: StepStats,
    progress,
    sequential: bool,
) -> None:
    n, h = _grid(scene)
    m = len(system.instances)
    every = scene.record_every
    recorder.row(system.record_row(scene.start))
    log = RegimeLog(system, scene, recorder)
    t = scene.start
    for k in range(n):
        hk = h if k < n - 1 else scene.stop - t
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
        t = scene.start + (k + 1) * h if k < n - 1 else scene.stop
        stats.steps += 1
        stats.do_steps += m
        stats.events += log.update(t)
        stop = system.stop_indicator()
        done = stop is not None and stop <= 0.0
        if (k + 1) % every == 0 or k == n - 1 or done:
            recorder.row(system.record_row(t))
        progress(t)
        if done:  # a fixed-step master stops at the first step past the condition
            stats.extra["stopped_by_condition"] = True
            return


def run_jacobi(
    system: CoupledSystem, scene: Scene, recorder: Recorder, stats: StepStats, progress
) -> None:
    _run(system, scene, recorder, stats, progress, sequential=False)


def run_gauss_seidel(
    system: CoupledSystem, scene: Scene, recorder: Recorder, stats: StepStats, progress
) -> None:
    _run(system, scene, recorder, stats, progress, sequential=True)
