"""Headline quantities of a run: simple reductions of recorded signals, and scene analyses.

A scene analysis is a function (scene, header, data, options) -> {name: value} registered
in ANALYSES under the name a scenario's ``report.analysis`` uses.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from orchestrator.references.two_inertias import two_inertias_exact
from orchestrator.scenario import Scene

_REDUCE: dict[str, Callable[[np.ndarray], float]] = {
    "final": lambda x: x[-1],
    "initial": lambda x: x[0],
    "max": np.max,
    "min": np.min,
    "maxabs": lambda x: np.max(np.abs(x)),
    "mean": np.mean,
}


def headline(scene: Scene, header: list[str], data: np.ndarray) -> dict[str, dict[str, Any]]:
    """The scene's [report.headline] quantities, each with its SI unit."""
    out: dict[str, dict[str, Any]] = {}
    if len(data) == 0:
        return out
    for name, spec in scene.headline.items():
        column = data[:, header.index(".".join(spec.signal))]
        out[name] = {"value": float(_REDUCE[spec.reduce](column)), "unit": spec.unit}
    return out


def energy_residual(header: list[str], data: np.ndarray) -> dict[str, Any] | None:
    """Largest drift of stored + dissipated - external energy, relative to its scale.

    Needs every FMU's stored_energy and dissipated_work recorded (and external_work where a
    component has it); returns None when they are not.
    """
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


def two_inertias(
    scene: Scene, header: list[str], data: np.ndarray, options: dict[str, Any]
) -> dict[str, Any]:
    """Coupling error of the two-inertia scene against its closed form."""
    a, b = options.get("body_a", "a"), options.get("body_b", "b")
    pa, pb = scene.fmus[a].parameters, scene.fmus[b].parameters
    defaults_a = {v.name: v.start for v in scene.component_class(a).VARIABLES}
    defaults_b = {v.name: v.start for v in scene.component_class(b).VARIABLES}
    par_a, par_b = {**defaults_a, **pa}, {**defaults_b, **pb}
    t = _column(header, data, "time")
    exact = two_inertias_exact(
        t - scene.start,
        par_a["J"],
        par_b["J"],
        par_b["k"],
        par_b["d"],
        par_a["phi0"],
        par_a["w0"],
        par_b["phi0"],
        par_b["w0"],
    )
    err_a = _column(header, data, f"{a}.phi") - exact["phi_a"]
    err_b = _column(header, data, f"{b}.phi") - exact["phi_b"]
    twist_scale = max(float(np.max(np.abs(exact["phi_a"] - exact["phi_b"]))), 1e-300)
    return {
        "max_angle_error": {
            "value": float(max(np.max(np.abs(err_a)), np.max(np.abs(err_b)))),
            "unit": "rad",
        },
        "final_angle_error_a": {"value": float(abs(err_a[-1])), "unit": "rad"},
        "relative_twist_error": {
            "value": float(np.max(np.abs(err_a - err_b)) / twist_scale),
            "unit": "1",
        },
    }


ANALYSES: dict[str, Callable[..., dict[str, Any]]] = {
    "two_inertias": two_inertias,
}
