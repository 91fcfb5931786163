"""What a tolerance study found: one Sample per run, and the StudyResult that the study
(``tolerance_study``) returns and its report (``study_report``) reads."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from orchestrator.scene_model import Scene
from orchestrator.studies.sampling import unit_points
from orchestrator.studies.study_table import StudySpec

OK = "ok"  # every quantity has a value
NOT_ARMED = "not-armed"  # the run ended without arming (the scene analysis says why)
NO_VALUE = "no-value"  # completed, but a quantity could not be computed
FAILED = "failed"  # the run failed, or the scene refused the sample's values


@dataclass
class Sample:
    index: int
    inputs: list[float]  # SI, in the order of the study's inputs
    status: str
    values: dict[str, float]  # quantity -> value (NaN when none)
    reason: str = ""


@dataclass
class StudyResult:
    scene: Scene
    spec: StudySpec
    requested: int  # samples asked for
    samples: list[Sample]  # recorded, in sample order
    output_dir: Path
    wall_time: float  # of this invocation
    ran: int  # samples run by this invocation
    workers: str
    interrupted: int | None = None  # the signal that stopped the study
    units: dict[str, str] = field(default_factory=dict)
    invocations: list[dict[str, Any]] = field(default_factory=list)  # runs.json: every
    # invocation of the study on this directory (samples run, wall time, where)
    notes: list[str] = field(default_factory=list)  # what was adjusted (workers capped)
    stopped: str | None = None  # why the study stopped early (its first samples all failed)

    def values(self, quantity: str) -> np.ndarray:
        """The quantity over the samples that gave every quantity (status ok)."""
        return np.array([s.values[quantity] for s in self.samples if s.status == OK])

    def inputs(self) -> np.ndarray:
        """(samples ok, inputs) input values of the samples that gave every quantity."""
        rows = [s.inputs for s in self.samples if s.status == OK]
        return np.array(rows).reshape(len(rows), len(self.spec.inputs))

    def unit_points(self) -> np.ndarray:
        """The unit-cube points of the samples that gave every quantity (for the
        convergence comparison, which refits the results over them)."""
        spec = self.spec
        count = max([self.requested, *(s.index + 1 for s in self.samples)])
        u = unit_points(count, len(spec.inputs), spec.sampling, spec.seed)
        ok = [s.index for s in self.samples if s.status == OK]
        return u[ok]
