"""What a scene family declares: the reference it measures runs against, and what its
analysis and reference read from a scene (options and recorded signals).

This module is a leaf: the scene loader imports it to check a scene's [report] at load,
without importing any family's analysis or models.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, TypedDict

import numpy as np


class Quantity(TypedDict):
    """A headline value of a run or a reference, with its SI unit (as summary.json holds it)."""

    value: float
    unit: str


def quantity(value: float, unit: str) -> Quantity:
    """A headline value; numpy scalars become plain floats (for JSON)."""
    return {"value": float(value), "unit": unit}


@dataclass
class Reference:
    """What a reference knows: headline values, signals at any time, located events."""

    headline: dict[str, float]
    signals: Callable[[np.ndarray], dict[str, np.ndarray]]  # "inst.var" -> values at times
    events: list[tuple[float, str, str, str]] = field(default_factory=list)
    wall_time: float = 0.0
    #: times the signals are known for (None: any time); outside, they are not compared
    t_range: tuple[float, float] | None = None
    #: the headline is where the scene's stop_when condition is met (else at scene.stop):
    #: a run that stopped on its condition is compared with it (orchestrator.stop_condition)
    at_stop_when: bool = False


@dataclass(frozen=True)
class Option:
    """A [report.options] key a family reads, and what its value must be: ``instance`` (an FMU
    instance of the scene), ``count`` (a whole number >= 0), ``flag`` (true/false) or
    ``quantity`` (a positive value in ``unit``)."""

    name: str
    kind: str = "instance"
    unit: str = ""


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

    options: tuple[Option, ...] = ()
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


@dataclass(frozen=True)
class SharedParameter:
    """A parameter that is one physical quantity for several of a family's FMUs (the fuze
    spin rate of a gear train and its escapement).  A scene states it once, in its
    [parameters] table, and every instance of ``components`` gets that value; a value
    given in one instance's own parameters is refused."""

    name: str
    components: frozenset[str]  # our FMUs (fmus.registry) that take it, each by this name
    meaning: str


@dataclass(frozen=True)
class Headline:
    """The one quantity a family's runs are judged by against its monolithic model (its
    work-precision curve, its benchmarks), and the words that name it in tables and texts."""

    quantity: str  # the headline key, e.g. "turns_to_arm"
    error_column: str  # the study table's column of its relative error, e.g. "turns_error"
    word: str  # what it counts, in texts: "turns" ("turns error", "|turns - truth|")


@dataclass(frozen=True)
class Outcome:
    """One monolithic run, as the work-precision curve and the benchmarks read it."""

    value: float  # the headline quantity (NaN: the run never reached it)
    reason: str  # why the run ended


@dataclass(frozen=True)
class SceneFamily:
    """One family of scenes (``[report] family`` / ``reference`` name it): what it reads,
    and where its analysis, plot and reference live ("module:function", imported when used).

    analysis: (scene, header, data, options) -> {name: Quantity}
    plot: (scene, header, data, path) -> None, writing a PNG at path
    reference: (scene) -> Reference, the monolithic yardstick of the coupling error
    shared: the parameters its FMUs share (they hold in every scene with those FMUs)
    drawing: (scene, path) -> None, writing a PNG of the scene's design to scale
    design_check: (scene) -> [message], every broken consistency rule of the scene's design
        (checked when the scene is loaded: a broken design never runs)
    monolithic: (scene) -> ((tolerance) -> Outcome), the family's whole mechanism as one
        model, run at a relative tolerance with the scene's physics (where it has one)
    headline: the quantity its monolithic model and its co-simulations are compared by
    """

    needs: Needs = field(default_factory=Needs)
    analysis: str | None = None
    plot: str | None = None
    reference: str | None = None
    shared: tuple[SharedParameter, ...] = ()
    drawing: str | None = None
    design_check: str | None = None
    monolithic: str | None = None
    headline: Headline | None = None
