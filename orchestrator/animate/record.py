"""A run's results read back for drawing its motion: the time series, the located switches,
and the scene with the parameters it ran with.

The scene file named in ``summary.json`` gives the family and the FMUs; the parameters are
the ones recorded in the summary's metadata (``--set`` overrides applied), so the design
drawn is the design that ran.  A run written before the metadata held its parameters is
drawn from the scene file as it is now.
"""

from __future__ import annotations

import csv
import dataclasses
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from orchestrator.errors import ScenarioError
from orchestrator.plotting import Event, regime_names


@dataclass
class RunRecord:
    """One run's results: columns by name, events, the scene."""

    directory: Path
    summary: dict[str, Any]
    header: list[str]
    data: np.ndarray
    events: list[Event]
    scene: Any
    notes: list[str]

    @property
    def time(self) -> np.ndarray:
        return self.data[:, 0]

    def has(self, column: str) -> bool:
        return column in self.header

    def column(self, name: str) -> np.ndarray:
        """A recorded column; a one-line error naming it when the run did not record it."""
        if name not in self.header:
            raise ScenarioError(
                self.directory / "timeseries.csv",
                name,
                f"not recorded; the animation of a {self.scene.family} scene needs it "
                "(add it to the scene's output.record and run again)",
            )
        return self.data[:, self.header.index(name)]

    def regime_at(self, instance: str) -> RegimeTimeline:
        """The regimes of one FMU over the run, switched at their located instants."""
        names = regime_names(self.scene, instance)
        column = f"{instance}.regime"
        first = names.get(int(self.column(column)[0]), "") if self.has(column) else ""
        switches = [(t, to) for t, who, _, to in self.events if who == instance]
        return RegimeTimeline(first, switches)


@dataclass
class RegimeTimeline:
    first: str
    switches: list[tuple[float, str]]  # (time, regime entered), in time order

    def __post_init__(self) -> None:
        self._times = np.array([t for t, _ in self.switches])

    def at(self, t: float) -> str:
        """The regime holding at t (a switch at t has happened)."""
        i = int(np.searchsorted(self._times, t, side="right"))
        return self.switches[i - 1][1] if i else self.first

    def entered(self, regime_prefix: str) -> list[float]:
        """The instants a regime whose name starts with ``regime_prefix`` was entered."""
        return [t for t, to in self.switches if to.startswith(regime_prefix)]


class Track:
    """A recorded angle (or any continuous quantity) between its records: linear in time,
    unwrapped so that an angle wrapped to (-pi, pi] does not spin back a turn."""

    def __init__(self, t: np.ndarray, y: np.ndarray, wrapped: bool = False) -> None:
        self.t = t
        self.y = np.unwrap(y) if wrapped else y

    def __call__(self, t: float | np.ndarray) -> Any:
        return np.interp(t, self.t, self.y)


def read_run(run_dir: Path) -> RunRecord:
    """The run in ``run_dir``; a one-line error for a directory that is not a run's."""
    run_dir = Path(run_dir)
    summary_file = run_dir / "summary.json"
    series = run_dir / "timeseries.csv"
    for f in (summary_file, series):
        if not f.is_file():
            raise ScenarioError(f, "", "not found: expected a run's results directory")
    try:
        summary = json.loads(summary_file.read_bytes().decode("utf-8"))
    except (ValueError, UnicodeDecodeError) as exc:
        raise ScenarioError(summary_file, "", f"not a readable summary: {exc}") from None
    meta = summary.get("metadata", {}) if isinstance(summary, dict) else {}
    if not isinstance(meta, dict) or "scene_file" not in meta:
        raise ScenarioError(summary_file, "metadata.scene_file", "missing: not a run summary")
    header, data = _read_series(series)
    scene, notes = _scene_as_run(Path(meta["scene_file"]), meta, summary_file)
    events_file = run_dir / "events.csv"
    events: list[Event] = []
    if events_file.is_file():
        with open(events_file, newline="") as f:
            rows = list(csv.reader(f))[1:]
        events = sorted((float(r[0]), r[1], r[2], r[3]) for r in rows if len(r) == 4)
    return RunRecord(run_dir, summary, header, data, events, scene, notes)


def _read_series(path: Path) -> tuple[list[str], np.ndarray]:
    with open(path, newline="") as f:
        reader = csv.reader(f)
        header = next(reader, None)
        rows = [r for r in reader if r]
    if not header or header[0] != "time":
        raise ScenarioError(path, "", "no header starting with 'time': not a run's time series")
    if len(rows) < 2:
        raise ScenarioError(path, "", f"{len(rows)} recorded rows: nothing moves to animate")
    try:
        data = np.array(rows, dtype=float)
    except ValueError as exc:
        raise ScenarioError(path, "", f"not numeric: {exc}") from None
    return header, data


def _scene_as_run(path: Path, meta: dict[str, Any], summary_file: Path) -> tuple[Any, list[str]]:
    """The scene file, loaded, with each FMU's parameters replaced by those it ran with."""
    from orchestrator.file_hash import file_sha256
    from orchestrator.scenario import load_scene

    if not path.is_file():
        raise ScenarioError(
            summary_file, "metadata.scene_file", f"{path} not found (run from the directory "
            "the run was started in)"
        )  # fmt: skip
    scene = load_scene(path)
    notes: list[str] = []
    ran = meta.get("parameters")
    if isinstance(ran, dict):
        fmus = {
            name: dataclasses.replace(spec, parameters=_plain(ran.get(name, spec.parameters)))
            for name, spec in scene.fmus.items()
        }
        scene = dataclasses.replace(scene, fmus=fmus)
    elif meta.get("scene_sha256") and file_sha256(path) != meta["scene_sha256"]:
        notes.append(f"{path} changed since the run: drawn as it is now")
    elif not isinstance(ran, dict):
        notes.append("the summary holds no parameters (an older run): drawn from the scene file")
    return scene, notes


def _plain(values: dict[str, Any]) -> dict[str, Any]:
    return {k: v for k, v in values.items() if not (isinstance(v, float) and math.isnan(v))}
