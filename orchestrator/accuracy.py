"""Error of a run against its scene's reference: headline, trajectory and event times."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from orchestrator.scenes.family import Reference


def compare(
    header: list[str],
    data: np.ndarray,
    events: list[tuple[float, str, str, str]],
    headline: dict[str, dict[str, Any]],
    reference: Reference,
    notes: list[str] | None = None,
) -> dict[str, float]:
    """Relative headline errors, relative max-norm trajectory error, largest event-time error.

    Keys: ``headline_error.<name>`` for each headline quantity the reference knows,
    ``headline_error`` (the largest of them), ``trajectory_error`` (max over the reference's
    signals of max|run - ref| / max|ref|), ``event_time_error`` [s] (events matched in order
    per subsystem and transition, after merging the switches at one instant: ``observable``).

    Every error is NaN-aware: a NaN anywhere makes the error it enters NaN (never dropped by
    a max).  The trajectory is compared only over the time range both the run and the
    reference cover (``reference.t_range``); where they do not overlap, or the reference
    signal is zero throughout (no scale for a relative error), it is NaN.  Each such case
    appends a line saying why to ``notes``.
    """
    notes = notes if notes is not None else []
    out: dict[str, float] = {}
    errors = []
    for name, ref_value in reference.headline.items():
        if name in headline:
            value = headline[name]["value"]
            if isinstance(value, str):
                continue
            err = abs(float(value) - ref_value) / max(abs(ref_value), 1e-300)
            if not math.isfinite(ref_value):
                err = math.nan
            out[f"headline_error.{name}"] = err
            errors.append(err)
    if errors:
        out["headline_error"] = nan_max(errors)
    if len(data):
        out["trajectory_error"] = _trajectory_error(header, data, reference, notes)
    if reference.events:
        run_events, ref_events = observable(events), observable(reference.events)
        out["event_time_error"] = _event_time_error(run_events, ref_events)
        out["event_count_difference"] = float(len(run_events) - len(ref_events))
    return out


def nan_max(values) -> float:
    """The largest value; NaN if any is NaN (Python's max drops NaN depending on order)."""
    values = [float(v) for v in values]
    if not values:
        return math.nan
    if any(math.isnan(v) for v in values):
        return math.nan
    return max(values)


def _trajectory_error(
    header: list[str], data: np.ndarray, reference: Reference, notes: list[str]
) -> float:
    times = data[:, 0]
    if reference.t_range is not None:
        lo, hi = reference.t_range
        # Ends that differ by round-off (both stop at the same event) still count as shared.
        slack = 1e-6 * max(hi - lo, times[-1] - times[0]) + 1e-12
        inside = (times >= lo - slack) & (times <= hi + slack)
        if not inside.any() or (hi - lo <= slack and times[-1] - times[0] > slack):
            notes.append(
                f"trajectory error not computed: the reference covers t = {lo:.6g} .. {hi:.6g} s, "
                f"the run {times[0]:.6g} .. {times[-1]:.6g} s: no common time range"
            )
            return math.nan
        if not inside.all():
            notes.append(
                f"trajectory error over t = {max(lo, times[0]):.6g} .. {min(hi, times[-1]):.6g} s "
                f"only: the reference covers {lo:.6g} .. {hi:.6g} s, "
                f"the run {times[0]:.6g} .. {times[-1]:.6g} s"
            )
        data, times = data[inside], times[inside]
    ref = reference.signals(times)
    errors = []
    for name, ref_values in ref.items():
        if name not in header:
            continue
        run_values = data[:, header.index(name)]
        ref_values = np.asarray(ref_values, dtype=float)
        scale = float(np.max(np.abs(ref_values)))
        diff = float(np.max(np.abs(run_values - ref_values)))
        if math.isnan(scale) or math.isnan(diff):
            errors.append(math.nan)
        elif scale == 0.0:
            notes.append(
                f"trajectory error of {name} not computed: the reference is zero throughout "
                f"(largest |run - reference| {diff:.3g})"
            )
            errors.append(math.nan)
        else:
            errors.append(diff / scale)
    return nan_max(errors) if errors else math.nan


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
    errors = [0.0]
    for key, ref_times in groups.items():
        run_times = seen.get(key, [])
        if len(run_times) != len(ref_times):
            return float("nan")
        errors.extend(abs(x - y) for x, y in zip(run_times, ref_times, strict=True))
    return nan_max(errors)
