"""Headline quantities of a run: simple reductions of recorded signals, and scene analyses.

A scene analysis is a function (scene, header, data, options) -> {name: value} registered
in ANALYSES under the name a scenario's ``report.analysis`` uses.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from orchestrator.lazy import LazyRegistry
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


#: Scene analyses: (scene, header, data, options) -> {name: {"value", "unit"}}.
ANALYSES = LazyRegistry(
    {
        "m739": "orchestrator.scenes.m739:analyse",
        "press_feed": "orchestrator.scenes.press_feed:analyse",
        "detached_lever": "orchestrator.scenes.detached_lever:analyse",
        "gear_mesh": "orchestrator.scenes.gear_mesh:analyse",
        "clock_train": "orchestrator.scenes.clock_train:analyse",
    }
)
#: Scene plots, drawn after a completed run when the scene names the analysis:
#: (scene, header, data, path) -> None, writing a PNG at path.
PLOTS = LazyRegistry(
    {
        "m739": "orchestrator.scenes.m739:plot",
        "press_feed": "orchestrator.scenes.press_feed:plot",
        "detached_lever": "orchestrator.scenes.detached_lever:plot",
        "gear_mesh": "orchestrator.scenes.gear_mesh:plot",
        "clock_train": "orchestrator.scenes.clock_train:plot",
    }
)


@dataclass(frozen=True)
class Role:
    """An FMU instance an analysis works on: named by ``option`` in [report.options], else
    the instance called ``default``, else the scene's only instance of ``component``."""

    component: str
    default: str | None = None
    option: str | None = None
    signals: tuple[str, ...] = ()  # variables the analysis reads (they must be recorded)


@dataclass(frozen=True)
class Needs:
    """What an analysis (and the reference of the same name) reads: its [report.options]
    keys and the recorded signals, checked when the scene is loaded."""

    options: tuple[str, ...] = ()
    roles: tuple[Role, ...] = field(default_factory=tuple)

    def instance(self, role: Role, scene_fmus: dict[str, Any], options: dict[str, Any]):
        """The instance playing ``role`` (None when the scene does not say which)."""
        if role.option and role.option in options:
            name = options[role.option]
            return name if isinstance(name, str) and name in scene_fmus else None
        if role.default and role.default in scene_fmus:
            return role.default
        found = [n for n, spec in scene_fmus.items() if spec.component == role.component]
        return found[0] if len(found) == 1 else None

    def missing_signals(
        self, scene_fmus: dict[str, Any], options: dict[str, Any], recorded: set[str]
    ) -> list[str]:
        out = []
        for role in self.roles:
            name = self.instance(role, scene_fmus, options)
            if name is None:
                continue
            out.extend(f"{name}.{v}" for v in role.signals if f"{name}.{v}" not in recorded)
        return out


_ESCAPEMENT_FORCES = ("phi", "phi_dot", "regime", "F12", "F23", "FF12", "FF23")
_VERGE = ("regime", "PN", "impact_count")

#: What each analysis (and reference) of ANALYSES/REFERENCES needs from a scene.
NEEDS: dict[str, Needs] = {
    "m739": Needs(
        options=("train", "verge"),
        roles=(
            Role("GearTrain", "train", "train", _ESCAPEMENT_FORCES),
            Role("VergeEscapement", "verge", "verge", _VERGE),
        ),
    ),
    "clock_train": Needs(
        options=("train", "verge"),
        roles=(
            Role("ClockGearTrain", "train", "train", _ESCAPEMENT_FORCES),
            Role("VergeEscapement", "verge", "verge", _VERGE),
        ),
    ),
    "press_feed": Needs(
        options=("startup_cycles", "decay_ratios"),
        roles=(
            Role("CrankCouplerDrive", signals=("regime",)),
            Role("SpragClutch", signals=("regime", "windup")),
            Role("BrakeLoad", signals=("regime", "feed_length")),
        ),
    ),
    "detached_lever": Needs(
        options=("lever", "nominal_period", "load_step"),
        roles=(
            Role(
                "DetachedLever",
                option="lever",
                signals=("theta", "amplitude", "beat_count", "period", "regime"),
            ),
        ),
    ),
    "gear_mesh": Needs(
        roles=(
            Role(
                "GearMesh",
                signals=(
                    "driver_angle",
                    "efficiency",
                    "regime",
                    "input_work",
                    "output_work",
                    "dissipated_work",
                ),  # fmt: skip
            ),
        )
    ),
    "two_inertias": Needs(),
}


def missing_column(exc: KeyError, header: list[str]) -> str | None:
    """The recorded signal a KeyError from ``col[...]`` was after, when it looks like one."""
    key = exc.args[0] if exc.args else None
    if isinstance(key, str) and "." in key and key not in header:
        return key
    return None
