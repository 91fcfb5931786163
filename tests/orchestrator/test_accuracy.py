"""Comparison of a run's event log with its reference's."""

from __future__ import annotations

import math

import numpy as np

from orchestrator.accuracy import compare, observable
from orchestrator.scenes.family import Reference


def test_a_regime_entered_and_left_at_one_instant_is_not_an_observable_switch() -> None:
    events = [
        (0.10, "verge", "free", "coupled"),
        (0.10 + 1e-12, "verge", "coupled", "free"),  # impact, then separation at once
        (0.20, "verge", "free", "coupled"),
        (0.20, "train", "forward", "stuck"),  # another subsystem at the same instant
        (0.20 + 1e-12, "verge", "coupled", "stuck"),  # a chain: free -> stuck
        (0.30, "verge", "stuck", "free"),
    ]
    assert observable(events) == [
        (0.20, "verge", "free", "stuck"),
        (0.20, "train", "forward", "stuck"),
        (0.30, "verge", "stuck", "free"),
    ]


def test_switches_apart_in_time_are_kept() -> None:
    events = [(0.1, "v", "a", "b"), (0.1 + 1e-6, "v", "b", "a")]
    assert observable(events) == events


def test_event_time_error_ignores_zero_duration_visits_in_either_log() -> None:
    ref = Reference(
        headline={},
        signals=lambda times: {},
        events=[(1.0, "v", "free", "exit"), (1.0, "v", "exit", "free"), (2.0, "v", "free", "en")],
    )
    run = [(2.0 + 3e-6, "v", "free", "en")]
    out = compare(["time"], np.zeros((0, 1)), run, {}, ref)
    assert math.isclose(out["event_time_error"], 3e-6, rel_tol=1e-9)
    assert out["event_count_difference"] == 0.0
    # A switch the run really missed still shows: counts differ, the time error is NaN.
    out = compare(["time"], np.zeros((0, 1)), [], {}, ref)
    assert math.isnan(out["event_time_error"])
    assert out["event_count_difference"] == -1.0
