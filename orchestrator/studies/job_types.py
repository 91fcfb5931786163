"""A job (one run of a scene with overrides, into a results directory) and its result:
numbers only, so that they travel between processes."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np


@dataclass(frozen=True)
class Job:
    scene: str  # path of the scenario file
    overrides: dict[str, Any]
    output_dir: str
    label: str = ""
    #: compare with the scene's reference inside the run; a study that shares one
    #: reference among its jobs computes it once itself and says False
    compare_reference: bool = True
    plots: bool = True  # draw the scene analysis's plot


@dataclass
class JobResult:
    job: Job
    status: str
    message: str
    headline: dict[str, dict[str, Any]]
    stats: dict[str, Any]
    header: list[str]
    data: np.ndarray
    events: list[tuple[float, str, str, str]]
    notes: list[str] = field(default_factory=list)  # what the analyses could not compute
