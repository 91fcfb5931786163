"""What a master is to the execution loop: a stepping algorithm.

A factory (orchestrator/masters/registry.py) makes a master from its settings and the
coupled system.  Its ``setup`` then tells the system what it needs of the FMUs (the
integration tolerance they are initialized with), ``start`` is told the initialized
system's span, and from there each call of ``step`` takes one macro step and says what it
took in a ``MacroStep``.  The loop (orchestrator/execution.py) owns everything around the
steps: when the run ends (the stop rule), interruption, progress, and the observers that
record the series, the regime log and the step statistics.  A master counts its FMU calls
(doSteps, rollbacks, rejections, coupling iterations) and what is its own into its typed
``stats``; the step counter counts the steps and the switches there.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Protocol

from orchestrator.errors import RunError
from orchestrator.recorder import StepStats
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
    # Filled in by the execution loop for the observers:
    #: the regime changes the step made, (FMU, from, to)
    changes: list[tuple[str, str, str]] = field(default_factory=list)
    #: the run ends with this step
    last: bool = False


class Master(Protocol):
    """A stepping algorithm over a coupled system; see the module doc."""

    name: str  # the algorithm's, as a scene names it
    system: CoupledSystem
    stats: StepStats  # its statistics, a StepStats or a master's own subclass of it
    settings: Any  # the settings it runs with (the summary records them)

    def setup(self) -> None:
        """Before the FMUs are initialized: set what the master needs of them on the
        system (``system.tolerance``)."""

    def start(self, t: float, stop: float) -> None:
        """The FMUs are initialized at t; the run ends at ``stop`` at the latest."""

    def step(self, t: float, stop: float) -> MacroStep:
        """One macro step from t, never past ``stop``."""
