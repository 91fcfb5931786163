"""What a master is to the execution loop: a stepping algorithm.

Given the coupled system at t, a master takes one macro step and says what it took in a
``MacroStep``.  The loop (orchestrator/execution.py) owns everything around the steps:
when the run ends (``scene.stop``, ``scene.stop_when``), interruption, progress, and the
observers that record the series, the regime log and the step statistics.  A master counts
its FMU calls (doSteps, rollbacks, rejections, coupling iterations) into the run's
``StepStats``; the loop counts the steps and the switches.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

from orchestrator.errors import RunError
from orchestrator.recorder import StepStats
from orchestrator.scene_model import Scene
from orchestrator.system import CoupledSystem


@dataclass(slots=True)
class MacroStep:
    """One accepted macro step: the system is now at ``end`` (values read and exchanged)."""

    end: float  # the instant the step reached [s]
    h: float  # the step's length [s]
    #: the step ends on a located switch (the exchange there settled): it counts as at least
    #: one switch even when no FMU's regime output changed (a jump, an indicator crossing)
    switched: bool = False
    #: the instant the step's regime changes are logged at (None: ``end``)
    changes_at: float | None = None
    #: the regimes at the step start, when the master read them (None: as the log last saw)
    regimes_before: list[int | None] | None = None
    #: recorded values just before the switch the step ends on (time first), if any
    left_row: list[float] | None = None
    #: the step was taken and is recorded, but the run cannot go on (raised after recording)
    failure: RunError | None = None
    #: the step ends on a known instant (an input signal's breakpoint): recorded whatever
    #: ``output.every`` says
    record: bool = False


class Master(Protocol):
    """A stepping algorithm: one macro step from t, never past ``stop``."""

    def step(self, t: float, stop: float) -> MacroStep: ...


#: How the loop makes a master for a run: (system, scene, stats) -> Master.
MasterFactory = Callable[[CoupledSystem, Scene, StepStats], Master]
