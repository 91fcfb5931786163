"""Monolithic references: the physics of a scene assembled into one ODE with exact events.

A scene names its reference in ``[report] reference``; ``REFERENCES[name](scene)`` returns a
``Reference``, the yardstick for the coupling error of every co-simulated run of the scene.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np


@dataclass
class Reference:
    """What a reference knows: headline values, signals at any time, located events."""

    headline: dict[str, float]
    signals: Callable[[np.ndarray], dict[str, np.ndarray]]  # "inst.var" -> values at times
    events: list[tuple[float, str, str, str]] = field(default_factory=list)
    wall_time: float = 0.0


def _registry() -> dict[str, Callable[..., Reference]]:
    from orchestrator.references.two_inertias import two_inertias_reference

    return {"two_inertias": two_inertias_reference}


REFERENCES = _registry()
