"""The angle-switched detached lever (Monday 1965) run from extreme to extreme by its own
closed-form segments, without macro steps: the yardstick of a coupled run.  It takes the
scene's whole deck, each segment's friction R(n) and each window's forcing X(n) as given."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from components.detached_lever import (
    STOPPED,
    DetachedLever,
)
from orchestrator.scenes.detached_lever.lever import LeverScene


@dataclass(frozen=True)
class BeatRun:
    """Extremes of the angle-switched model run extreme to extreme, without macro steps."""

    times: np.ndarray  # s, the start and every extreme
    angles: np.ndarray  # rad, signed theta there
    amplitudes: np.ndarray  # rad, the component's amplitude output from there on
    stopped: bool


def beat_run(lever: LeverScene) -> BeatRun:
    """The component's closed-form segments advanced from extreme to extreme until stop."""
    comp = DetachedLever(**lever.component_params())
    comp.drive_torque = lever.drive_torque
    comp.initialize(lever.start)
    times, angles, amplitudes = [lever.start], [comp.theta], [comp.amplitude]
    t = lever.start
    while t < lever.stop and comp.regime != STOPPED:
        seen = comp.beat_count
        t = comp.advance_to_next_beat(t, lever.stop)
        if comp.beat_count > seen:
            times.append(t)
            angles.append(comp.theta)
            amplitudes.append(comp.amplitude)
    return BeatRun(np.array(times), np.array(angles), np.array(amplitudes), comp.regime == STOPPED)
