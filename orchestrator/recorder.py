"""Recording a run to files: time series (CSV), events, statistics, metadata, headline.

Rows are written as they come, so a failed run keeps everything recorded up to the
failure; ``close`` always writes the summary files, with the run's status.
"""

from __future__ import annotations

import csv
import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from orchestrator.errors import RunError


@dataclass
class StepStats:
    """Counters every master keeps; a master with statistics of its own keeps them in a
    subclass (``masters.regime_aware.RegimeAwareStats``)."""

    steps: int = 0  # accepted macro steps
    do_steps: int = 0  # FMU doStep calls, all instances
    rejections: int = 0  # steps rejected by an error or event test
    rollbacks: int = 0  # restores of FMU state
    iterations: int = 0  # coupling iterations beyond the first pass
    events: int = 0  # located regime switches
    wall_time: float = 0.0  # seconds, whole run
    warnings: list[str] = field(default_factory=list)  # what the master gave up, and why
    stopped_by_condition: bool = False  # the scene's stop_when ended the run

    def as_dict(self) -> dict[str, Any]:
        """The summary's "stats": the counters, then what the master chose, its warnings,
        its own counts (those that are not zero) and the stop by a condition."""
        d: dict[str, Any] = {k: getattr(self, k) for k in _COUNTERS}
        d.update(self.choices())
        if self.warnings:
            d["warnings"] = list(self.warnings)
        d.update(self.counts())
        if self.stopped_by_condition:
            d["stopped_by_condition"] = True
        return d

    def choices(self) -> dict[str, Any]:
        """What the master chose as it started (none here)."""
        return {}

    def counts(self) -> dict[str, Any]:
        """The master's own counts (none here)."""
        return {}


_COUNTERS = ("steps", "do_steps", "rejections", "rollbacks", "iterations", "events", "wall_time")


class Recorder:
    """Writes ``timeseries.csv`` and ``events.csv`` under ``directory`` while a run goes on."""

    def __init__(self, directory: Path, header: list[str]) -> None:
        self.directory = Path(directory)
        self.directory.mkdir(parents=True, exist_ok=True)
        self.header = ["time", *header]
        self.rows: list[list[float]] = []
        self.events: list[tuple[float, str, str, str]] = []
        # Line-buffered: each row reaches the file as it is recorded, so a process that
        # crashes loses at most the step under way (docs/cli.md, "A crashing FMU").
        self._file = open(self.directory / "timeseries.csv", "w", newline="", buffering=1)  # noqa: SIM115
        self._writer = csv.writer(self._file)
        self._writer.writerow(self.header)
        self._events_file = open(self.directory / "events.csv", "w", newline="", buffering=1)  # noqa: SIM115
        self._events_writer = csv.writer(self._events_file)
        self._events_writer.writerow(["time", "subsystem", "from", "to"])

    def row(self, values: list[float]) -> None:
        """Record one row; a value that is not finite is recorded, then ends the run."""
        self.rows.append(values)
        self._writer.writerow(values)  # a float's str is its repr: every digit
        try:
            finite = math.isfinite(math.fsum(values))
        except (OverflowError, ValueError):  # an overflowing sum, or inf - inf: look closer
            finite = False
        if not finite:
            self._refuse_non_finite(values)

    def _refuse_non_finite(self, values: list[float]) -> None:
        bad = [
            (name, v) for name, v in zip(self.header, values, strict=True) if not math.isfinite(v)
        ]
        if bad:
            name, value = bad[0]
            more = f" (and {len(bad) - 1} more)" if len(bad) > 1 else ""
            raise RunError(f"{name} is {value!r}, not finite{more}", values[0])

    def event(self, time: float, subsystem: str, before: str, after: str) -> None:
        self.events.append((time, subsystem, before, after))
        self._events_writer.writerow([repr(time), subsystem, before, after])

    def array(self) -> np.ndarray:
        return np.array(self.rows, dtype=float).reshape(-1, len(self.header))

    def flush(self) -> None:
        for f in (self._file, self._events_file):
            if not f.closed:
                f.flush()

    def close(self, summary: dict[str, Any]) -> None:
        """Flush the series and write ``summary.json`` (status, stats, metadata, headline).

        The summary is written to a temporary file and renamed, so a reader never sees half
        of one.  Non-finite numbers are written as null (strict JSON has no NaN)."""
        for f in (self._file, self._events_file):
            if not f.closed:
                f.close()
        target = self.directory / "summary.json"
        partial = self.directory / "summary.json.part"
        with open(partial, "w") as f:
            json.dump(_finite_or_none(summary), f, indent=2, default=_jsonable, allow_nan=False)
        os.replace(partial, target)


def _finite_or_none(value: Any) -> Any:
    """``value`` with every non-finite float (NaN, inf) replaced by None."""
    if isinstance(value, dict):
        return {k: _finite_or_none(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_finite_or_none(v) for v in value]
    if isinstance(value, float | np.floating) and not math.isfinite(value):
        return None
    if isinstance(value, np.generic):
        return value.item()
    return value


def _jsonable(value: Any) -> Any:
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, Path):
        return str(value)
    return str(value)
