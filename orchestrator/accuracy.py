"""Error of a run against its scene's reference: headline, trajectory and event times."""

from __future__ import annotations

from typing import Any

import numpy as np

from orchestrator.references import Reference


def compare(
    header: list[str],
    data: np.ndarray,
    events: list[tuple[float, str, str, str]],
    headline: dict[str, dict[str, Any]],
    reference: Reference,
) -> dict[str, float]:
    """Relative headline errors, relative max-norm trajectory error, largest event-time error.

    Keys: ``headline_error.<name>`` for each headline quantity the reference knows,
    ``headline_error`` (the largest of them), ``trajectory_error`` (max over the reference's
    signals of max|run - ref| / max|ref|), ``event_time_error`` [s] (events matched in order
    per subsystem and transition, after merging the switches at one instant: ``observable``).
    """
    out: dict[str, float] = {}
    errors = []
    for name, ref_value in reference.headline.items():
        if name in headline:
            err = abs(headline[name]["value"] - ref_value) / max(abs(ref_value), 1e-300)
            out[f"headline_error.{name}"] = err
            errors.append(err)
    if errors:
        out["headline_error"] = max(errors)
    if len(data):
        times = data[:, 0]
        ref = reference.signals(times)
        worst = 0.0
        for name, ref_values in ref.items():
            if name in header:
                run_values = data[:, header.index(name)]
                scale = max(float(np.max(np.abs(ref_values))), 1e-300)
                worst = max(worst, float(np.max(np.abs(run_values - ref_values))) / scale)
        out["trajectory_error"] = worst
    if reference.events:
        run_events, ref_events = observable(events), observable(reference.events)
        out["event_time_error"] = _event_time_error(run_events, ref_events)
        out["event_count_difference"] = float(len(run_events) - len(ref_events))
    return out


# Switches of one subsystem closer than this are one instant: a regime entered and left at
# once (an impact followed by immediate separation) leaves no trace in a master's outputs.
SAME_INSTANT = 1e-9  # s


def observable(
    events: list[tuple[float, str, str, str]], same_instant: float = SAME_INSTANT
) -> list[tuple[float, str, str, str]]:
    """The events with each subsystem's chains at one instant merged: a -> b, b -> c at (nearly)
    the same time become a -> c at the first time, and vanish when c == a."""
    last: dict[str, int] = {}  # subsystem -> index in out of its latest event
    out: list[tuple[float, str, str, str] | None] = []
    for event in sorted(events, key=lambda e: e[0]):
        t, sub, a, b = event
        k = last.get(sub)
        prev = out[k] if k is not None else None
        if prev is not None and t - prev[0] <= same_instant and prev[3] == a:
            out[k] = (prev[0], sub, prev[2], b) if prev[2] != b else None
            continue
        last[sub] = len(out)
        out.append(event)
    return [e for e in out if e is not None]


def _event_time_error(run_events, ref_events) -> float:
    """Events matched in order within each (subsystem, from, to); NaN when the counts differ
    (then ``event_count_difference`` says by how many)."""
    groups: dict[tuple[str, str, str], list[float]] = {}
    for t, sub, a, b in ref_events:
        groups.setdefault((sub, a, b), []).append(t)
    seen: dict[tuple[str, str, str], list[float]] = {}
    for t, sub, a, b in run_events:
        seen.setdefault((sub, a, b), []).append(t)
    worst = 0.0
    for key, ref_times in groups.items():
        run_times = seen.get(key, [])
        if len(run_times) != len(ref_times):
            return float("nan")
        worst = max(worst, max(abs(x - y) for x, y in zip(run_times, ref_times, strict=True)))
    return worst
