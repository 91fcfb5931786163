"""Observers of a run: what the execution loop tells the start and every macro step.

The time series (every n-th step, ``output.every``), the regime log (events), the step
statistics and the energy balance (over every step, the series thinned or not) are equals:
each follows ``Observer``.  They read the system and write through the ``Recorder``; none
of them changes the system, so what a master computes does not depend on what is recorded.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, Protocol

from orchestrator.errors import RunError
from orchestrator.recorder import Recorder, StepStats

if TYPE_CHECKING:  # the masters import regime_changes from here
    from orchestrator.masters.macro_step import MacroStep


class Observer(Protocol):
    """What watches a run: told the start, every step (the loop has filled in its regime
    changes and whether it is the last) and where an interrupted run stopped."""

    def start(self, t: float) -> None: ...

    def step(self, step: MacroStep) -> None: ...

    def interrupted(self, t: float) -> None: ...


def regime_changes(
    system: Any, before: list[int | None], after: list[int | None]
) -> list[tuple[str, str, str]]:
    """(FMU, from, to) for every FMU whose regime output differs between ``before`` and
    ``after``, the regimes by the names of each FMU's Enumeration type (else numbers)."""
    changes = []
    for i, (a, b) in enumerate(zip(before, after, strict=True)):
        if a != b:
            names = system.models[i].regime_names
            changes.append((system.names[i], names.get(a, str(a)), names.get(b, str(b))))
    return changes


class RegimeLog:
    """Logs every change of an FMU's ``regime`` output as an event (time, FMU, from, to).

    A fixed-step master sees a switch only at the end of the step it happened in, so the
    logged time is that communication point, not the switching instant; a regime-aware
    step that changed a regime without a located switch logs it at its start.
    """

    def __init__(self, recorder: Recorder) -> None:
        self.recorder = recorder

    def start(self, t: float) -> None:
        pass

    def step(self, step: MacroStep) -> None:
        t = step.end if step.changes_at is None else step.changes_at
        for name, a, b in step.changes:
            self.recorder.event(t, name, a, b)

    def interrupted(self, t: float) -> None:
        pass


class TimeSeries:
    """Records the values at the start, after every ``every``-th macro step and after the
    last one; a recorded step that ends on a switch records the values just before it too."""

    def __init__(self, system: Any, recorder: Recorder, every: int) -> None:
        self.system, self.recorder, self.every = system, recorder, every
        self.count = 0  # steps seen

    def start(self, t: float) -> None:
        self.recorder.row(self.system.record_row(t))

    def step(self, step: MacroStep) -> None:
        self.count += 1
        if self.count % self.every == 0 or step.last or step.record:
            if step.left_row is not None:
                self.recorder.row(step.left_row)
            self.recorder.row(self.system.record_row(step.end))

    def interrupted(self, t: float) -> None:
        """The run stops at t: record the values there if a thinned record lacks them."""
        rows = self.recorder.rows
        if rows and rows[-1][0] < t:
            try:
                self.recorder.row(self.system.record_row(t))
            except RunError:
                pass


class StepCounter:
    """Counts the accepted steps and the switches into the master's ``StepStats``."""

    def __init__(self, stats: StepStats) -> None:
        self.stats = stats

    def start(self, t: float) -> None:
        pass

    def step(self, step: MacroStep) -> None:
        logged = len(step.changes)
        self.stats.steps += 1
        self.stats.events += max(logged, 1) if step.switched else logged

    def interrupted(self, t: float) -> None:
        pass


class EnergyBalance:
    """The energy residual of ``orchestrator.analyses.energy_residual`` over every step,
    however thinned the record is: the largest drift of stored + dissipated - external
    energy (every FMU's, where each has them recorded) from its start value, relative to
    the largest stored or external energy seen.  The same arithmetic as that function on a
    record of every step, so an unthinned run gives the same number bit for bit."""

    def __init__(self, system: Any, header: list[str]) -> None:
        self.system = system
        # Per instance (sorted by name): header indices of stored, dissipated, external.
        columns: list[tuple[int, int, int | None]] | None = []
        for inst in sorted({h.split(".")[0] for h in header[1:]}):
            if f"{inst}.stored_energy" not in header or f"{inst}.dissipated_work" not in header:
                columns = None  # an FMU without its energy recorded: no balance
                break
            external = f"{inst}.external_work"
            columns.append(
                (
                    header.index(f"{inst}.stored_energy"),
                    header.index(f"{inst}.dissipated_work"),
                    header.index(external) if external in header else None,
                )
            )
        self.columns = columns
        self.first: float | None = None  # the balance at the start
        self.drift = 0.0
        self.scale = 0.0
        self.finite = True

    @property
    def tracked(self) -> bool:
        return self.columns is not None

    def start(self, t: float) -> None:
        if self.tracked:
            self._add(self.system.record_row(t))

    def step(self, step: MacroStep) -> None:
        if self.tracked:
            if step.left_row is not None:
                self._add(step.left_row)
            self._add(self.system.record_row(step.end))

    def _add(self, row: list[float]) -> None:
        total = 0.0
        for stored, dissipated, external in self.columns:
            total += row[stored] + row[dissipated]
            self.scale = max(self.scale, abs(row[stored]))
            if external is not None:
                total -= row[external]
                self.scale = max(self.scale, abs(row[external]))
        if self.first is None:
            self.first = total
        drift = abs(total - self.first)
        self.finite = self.finite and math.isfinite(drift)
        self.drift = max(self.drift, drift)

    def interrupted(self, t: float) -> None:
        pass

    def residual(self) -> dict[str, Any] | None:
        """The residual as a headline quantity; None without a balance or a scale."""
        if not self.tracked or self.first is None or self.scale == 0.0:
            return None
        return {"value": self.drift / self.scale if self.finite else math.nan, "unit": "1"}
