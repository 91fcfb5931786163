"""Fixed-step Jacobi and Gauss–Seidel masters: what every co-simulation tool offers.

Inputs are held over each macro step (zero-order hold).  Jacobi steps every FMU with the
outputs of the previous communication point; Gauss–Seidel steps them in the scene's
order, each with the newest outputs of those already stepped.  Both are first order in
the macro step for a generic coupling; they are the baseline the regime-aware master beats.
"""

from __future__ import annotations

import math

from orchestrator.master_settings import FixedStepSettings
from orchestrator.masters.macro_step import MacroStep
from orchestrator.recorder import StepStats
from orchestrator.scene_model import Scene
from orchestrator.system import CoupledSystem


def _grid(start: float, stop: float, h: float) -> int:
    """Number of macro steps of h; the last step is shortened to land on stop."""
    return math.ceil((stop - start) / h - 1e-9)


class FixedStepMaster:
    """Macro steps of h on the grid start + k h; the last one shortened to land on stop."""

    def __init__(
        self,
        system: CoupledSystem,
        h: float,
        start: float,
        stop: float,
        stats: StepStats,
        sequential: bool,
    ) -> None:
        self.system, self.h, self.stats, self.sequential = system, h, stats, sequential
        self.start, self.stop = start, stop
        self.n = _grid(start, stop, h)
        self.k = 0  # steps taken

    def step(self, t: float, stop: float) -> MacroStep:
        system, k, n = self.system, self.k, self.n
        m = len(system.instances)
        last = k >= n - 1
        # On the grid (no accumulated rounding), the last step on stop itself.
        grid = self.stop if last else self.start + (k + 1) * self.h
        end, on_grid = grid, True
        if system.signals:  # an input signal's jump or kink before the grid point
            end = system.signals.land(t, grid)
            on_grid = grid - end <= 1e-9 * self.h
            end = grid if on_grid else end
        hk = end - t if system.signals else (self.stop - t if last else self.h)
        if self.sequential:  # Gauss–Seidel: each FMU sees the newest outputs
            for i in range(m):
                system.feed(i)
                system.step(i, t, hk)
                system.read(i)
        else:  # Jacobi: all FMUs see the outputs of the last communication point
            for i in range(m):
                system.feed(i)
                system.step(i, t, hk)
            system.read_all()
        self.k += on_grid
        self.stats.do_steps += m
        return MacroStep(end, hk, record=not on_grid)


def fixed_step_master(
    system: CoupledSystem, scene: Scene, stats: StepStats, step: float, sequential: bool
) -> FixedStepMaster:
    """A fixed-step master of macro step ``step`` over the scene's span."""
    return FixedStepMaster(system, step, scene.start, scene.stop, stats, sequential)


def jacobi(system: CoupledSystem, scene: Scene, stats: StepStats) -> FixedStepMaster:
    settings: FixedStepSettings = scene.master.settings
    return fixed_step_master(system, scene, stats, settings.step, sequential=False)


def gauss_seidel(system: CoupledSystem, scene: Scene, stats: StepStats) -> FixedStepMaster:
    settings: FixedStepSettings = scene.master.settings
    return fixed_step_master(system, scene, stats, settings.step, sequential=True)
