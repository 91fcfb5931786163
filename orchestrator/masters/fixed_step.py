"""Fixed-step Jacobi and Gauss–Seidel masters: what every co-simulation tool offers.

Inputs are held over each macro step (zero-order hold).  Jacobi steps every FMU with the
outputs of the previous communication point; Gauss–Seidel steps them in the scene's
order, each with the newest outputs of those already stepped.  Both are first order in
the macro step for a generic coupling; they are the baseline the regime-aware master beats.
"""

from __future__ import annotations

import math

from orchestrator.capabilities import check_fixed_step
from orchestrator.master_settings import FixedStepSettings
from orchestrator.masters.macro_step import MacroStep
from orchestrator.recorder import StepStats
from orchestrator.system import CoupledSystem


def _grid(start: float, stop: float, h: float) -> int:
    """Number of macro steps of h; the last step is shortened to land on stop."""
    return math.ceil((stop - start) / h - 1e-9)


class FixedStepMaster:
    """Macro steps of h on the grid start + k h; the last one shortened to land on stop."""

    def __init__(
        self,
        settings: FixedStepSettings,
        system: CoupledSystem,
        sequential: bool,
        stats: StepStats | None = None,
    ) -> None:
        self.settings, self.system, self.sequential = settings, system, sequential
        self.name = "gauss-seidel" if sequential else "jacobi"
        self.stats = StepStats() if stats is None else stats
        self.h = settings.step
        self.start_time, self.stop, self.n = 0.0, 0.0, 0
        self.k = 0  # steps taken

    def setup(self) -> None:
        pass  # the FMUs' own integration tolerance

    def start(self, t: float, stop: float) -> None:
        check_fixed_step(self.system, t, stop, self.h)
        self.start_time, self.stop = t, stop
        self.n = _grid(t, stop, self.h)

    def step(self, t: float, stop: float) -> MacroStep:
        system, k, n = self.system, self.k, self.n
        m = len(system.instances)
        last = k >= n - 1
        # On the grid (no accumulated rounding), the last step on stop itself.
        grid = self.stop if last else self.start_time + (k + 1) * self.h
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


def jacobi(settings: FixedStepSettings, system: CoupledSystem) -> FixedStepMaster:
    return FixedStepMaster(settings, system, sequential=False)


def gauss_seidel(settings: FixedStepSettings, system: CoupledSystem) -> FixedStepMaster:
    return FixedStepMaster(settings, system, sequential=True)
