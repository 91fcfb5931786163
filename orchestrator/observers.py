"""Observers of a run: what the execution loop records after each macro step.

The time series (every n-th step, ``output.every``), the regime log (events), the step
statistics and the energy balance (over every step, the series thinned or not).  They
read the system and write through the ``Recorder``; none of them changes the system, so
what a master computes does not depend on what is recorded.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from orchestrator.errors import RunError
from orchestrator.recorder import Recorder, StepStats

if TYPE_CHECKING:  # the masters import regime_changes from here
    from orchestrator.masters.macro_step import MacroStep


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
    logged time is that communication point, not the switching instant.
    """

    def __init__(self, system: Any, recorder: Recorder) -> None:
        self.system, self.recorder = system, recorder
        self.last = system.regimes()

    def update(self, t: float, before: list[int | None] | None = None) -> int:
        """Log the changes since ``before`` (default: the regimes last seen) at ``t``."""
        now = self.system.regimes()
        changes = regime_changes(self.system, self.last if before is None else before, now)
        for name, a, b in changes:
            self.recorder.event(t, name, a, b)
        self.last = now
        return len(changes)


class TimeSeries:
    """Records the values at the start, after every ``every``-th macro step and after the
    last one; a recorded step that ends on a switch records the values just before it too."""

    def __init__(self, system: Any, recorder: Recorder, every: int) -> None:
        self.system, self.recorder, self.every = system, recorder, every

    def start(self, t: float) -> None:
        self.recorder.row(self.system.record_row(t))

    def step(self, count: int, step: MacroStep, last: bool) -> None:
        """After the ``count``-th step (from 1); ``last``: the run ends with it."""
        if count % self.every == 0 or last or step.record:
            if step.left_row is not None:
                self.recorder.row(step.left_row)
            self.recorder.row(self.system.record_row(step.end))

    def keep(self, t: float) -> None:
        """The run stops at t (interrupted): record the values there if a thinned record
        lacks them."""
        rows = self.recorder.rows
        if rows and rows[-1][0] < t:
            try:
                self.recorder.row(self.system.record_row(t))
            except RunError:
                pass


class StepCounter:
    """Counts the accepted steps and the switches into the run's ``StepStats``."""

    def __init__(self, stats: StepStats) -> None:
        self.stats = stats

    def step(self, step: MacroStep, logged: int) -> None:
        self.stats.steps += 1
        self.stats.events += max(logged, 1) if step.switched else logged


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

    def residual(self) -> dict[str, Any] | None:
        """The residual as a headline quantity; None without a balance or a scale."""
        if not self.tracked or self.first is None or self.scale == 0.0:
            return None
        return {"value": self.drift / self.scale if self.finite else math.nan, "unit": "1"}
