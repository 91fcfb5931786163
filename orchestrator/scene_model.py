"""The scene model: what a scenario file says, validated and in SI units.

Plain records only; ``orchestrator.scenario`` reads and checks the files that make them.
Everything above (masters, runs, studies, families) reads scenes through these types.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from orchestrator.master_settings import Settings

if TYPE_CHECKING:
    from components.base import Component
    from orchestrator.model_info import ModelInfo
    from orchestrator.signals import Signal
    from orchestrator.studies.study_table import StudySpec


@dataclass(frozen=True)
class FmuSpec:
    instance: str
    fmu_name: str  # our component's name in fmus.registry, or the FMU file's model name
    path: Path  # the FMU file (ours: built and cached; another tool's: as the scene names it)
    model: ModelInfo  # everything the orchestrator knows of the FMU, read from the file
    parameters: dict[str, Any]  # SI values (int for Integer, bool for Boolean)
    inputs: dict[str, Any]  # start values of inputs
    component: str | None = None  # name in fmus.registry when the scene names one of ours
    signals: dict[str, Signal] = field(default_factory=dict)  # inputs that vary in time


@dataclass(frozen=True)
class Connection:
    source: tuple[str, str]  # (instance, output variable)
    target: tuple[str, str]  # (instance, input variable)


@dataclass(frozen=True)
class MasterSpec:
    algorithm: str
    # The fixed macro step: master.step, else the first step the scene gives (what a
    # fixed-step master, an exported archive's base step and crosscheck step at).
    step: float
    order: tuple[str, ...]
    options: dict[str, Any] = field(default_factory=dict)  # as the scene wrote them (SI)
    settings: Settings | None = None  # the algorithm's, defaults filled in

    @property
    def own_step(self) -> tuple[str, float]:
        """The step key this master reads (step or first_step) and the step it takes."""
        key = type(self.settings).STEP_KEY
        return key, getattr(self.settings, key, self.step)


@dataclass(frozen=True)
class HeadlineSpec:
    signal: tuple[str, str]
    reduce: str
    unit: str


@dataclass(frozen=True)
class StopCondition:
    """End the run when a signal first reaches a threshold (e.g. an S&A arming angle)."""

    signal: tuple[str, str]
    threshold: float  # in the signal's SI unit
    rising: bool  # True: stop when the signal rises to the threshold; False: falls to it


@dataclass(frozen=True)
class SweepSeries:
    label: str
    overrides: dict[str, Any]  # dotted keys, as with --set


@dataclass(frozen=True)
class SweepSpec:
    """One run per (series, value): the scene with ``parameter`` set to each value."""

    parameter: str  # dotted key, e.g. "fmus.verge.parameters.center_distance"
    values: tuple[Any, ...]  # as written (a unit string or a number)
    si_values: tuple[float, ...]  # the same in SI, for tables and plots
    unit: str  # SI unit of the swept value ("1" when plain)
    label: str
    quantities: tuple[str, ...]  # headline quantities tabulated and plotted; () = all
    series: tuple[SweepSeries, ...]


@dataclass(frozen=True)
class Scene:
    path: Path
    name: str
    description: str
    start: float
    stop: float
    fmus: dict[str, FmuSpec]
    connections: tuple[Connection, ...]
    master: MasterSpec
    record: tuple[tuple[str, str], ...]
    record_every: int
    output_dir: Path
    headline: dict[str, HeadlineSpec]
    family: str | None  # [report] family: the scene family whose analysis and plot run
    report_options: dict[str, Any]  # [report.options], read by the family and the reference
    reference: str | None = None
    stop_when: StopCondition | None = None
    error_bound: float = math.inf  # the error against the reference the scene claims
    sweep: SweepSpec | None = None  # run by ``mechcosim sweep``; ``run`` ignores it
    study: StudySpec | None = None  # run by ``mechcosim study``; ``run`` ignores it

    def component_class(self, instance: str) -> type[Component]:
        """The physics behind one of our FMUs (for scene analyses and references only:
        masters, recorder and system know the FMUs through their files)."""
        component = self.fmus[instance].component
        if component is None:
            raise ValueError(f"FMU instance {instance!r} is not one of this project's components")
        from fmus.registry import FMU_RECORDS  # the FMU build layer, loaded when asked

        return FMU_RECORDS[component].component_class
