"""Headline quantities every run has: the [report.headline] reductions of recorded signals
and the energy residual.  A scene family's own analysis lives in its package
(``orchestrator.scenes.<family>.report``).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from orchestrator.scene_model import Scene
from orchestrator.scenes.family import Quantity, quantity

_REDUCE: dict[str, Callable[[np.ndarray], float]] = {
    "final": lambda x: x[-1],
    "initial": lambda x: x[0],
    "max": np.max,
    "min": np.min,
    "maxabs": lambda x: np.max(np.abs(x)),
    "mean": np.mean,
}


def headline(scene: Scene, header: list[str], data: np.ndarray) -> dict[str, Quantity]:
    """The scene's [report.headline] quantities, each with its SI unit."""
    out: dict[str, Quantity] = {}
    if len(data) == 0:
        return out
    for name, spec in scene.headline.items():
        column = data[:, header.index(".".join(spec.signal))]
        out[name] = quantity(_REDUCE[spec.reduce](column), spec.unit)
    return out


def energy_residual(header: list[str], data: np.ndarray) -> dict[str, Any] | None:
    """Largest drift of stored + dissipated - external energy, relative to its scale.

    Needs every FMU's stored_energy and dissipated_work recorded (and external_work where a
    component has it); returns None when they are not.
    """
    if len(data) == 0:  # nothing recorded (e.g. an FMU failed to initialize)
        return None
    instances = {h.split(".")[0] for h in header[1:]}
    total = np.zeros(len(data))
    scale = 0.0
    for inst in sorted(instances):
        try:
            stored = _column(header, data, f"{inst}.stored_energy")
            dissipated = _column(header, data, f"{inst}.dissipated_work")
        except ValueError:
            return None
        total += stored + dissipated
        scale = max(scale, float(np.max(np.abs(stored))))
        if f"{inst}.external_work" in header:
            external = _column(header, data, f"{inst}.external_work")
            total -= external
            scale = max(scale, float(np.max(np.abs(external))))
    if len(data) == 0 or scale == 0.0:
        return None
    return {"value": float(np.max(np.abs(total - total[0])) / scale), "unit": "1"}


def _column(header: list[str], data: np.ndarray, name: str) -> np.ndarray:
    return data[:, header.index(name)]


def missing_column(exc: KeyError, header: list[str]) -> str | None:
    """The recorded signal a KeyError from ``col[...]`` was after, when it looks like one."""
    key = exc.args[0] if exc.args else None
    if isinstance(key, str) and "." in key and key not in header:
        return key
    return None
