"""Monolithic references: the physics of a scene assembled into one ODE with exact events.

A scene names its reference in ``[report] reference``; ``REFERENCES[name](scene)`` returns a
``Reference``, the yardstick for the coupling error of every co-simulated run of the scene.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from orchestrator.lazy import LazyRegistry


@dataclass
class Reference:
    """What a reference knows: headline values, signals at any time, located events."""

    headline: dict[str, float]
    signals: Callable[[np.ndarray], dict[str, np.ndarray]]  # "inst.var" -> values at times
    events: list[tuple[float, str, str, str]] = field(default_factory=list)
    wall_time: float = 0.0
    #: times the signals are known for (None: any time); outside, they are not compared
    t_range: tuple[float, float] | None = None


#: Scene references: (scene) -> Reference.
REFERENCES = LazyRegistry(
    {
        "two_inertias": "orchestrator.references.two_inertias:two_inertias_reference",
        "m739": "orchestrator.scenes.m739:reference",
        "press_feed": "orchestrator.scenes.press_feed:reference",
        "detached_lever": "orchestrator.scenes.detached_lever:reference",
        "gear_mesh": "orchestrator.scenes.gear_mesh:reference",
        "clock_train": "orchestrator.scenes.clock_train:reference",
    }
)
