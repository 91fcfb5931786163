"""Many runs of a scene with different settings, on a local process pool or a Dask cluster.

Each job is (scene file, overrides, results directory).  Workers load the scene, run it
and send back numbers only (status, headline, statistics, recorded series), so results
are the same wherever they ran.  FMUs are built once, before the jobs go out.
"""

from __future__ import annotations

import multiprocessing as mp
import os
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from orchestrator.run import run_scene
from orchestrator.scenario import load_scene


@dataclass(frozen=True)
class Job:
    scene: str  # path of the scenario file
    overrides: dict[str, Any]
    output_dir: str
    label: str = ""
    #: compare with the scene's reference inside the run; a study that shares one
    #: reference among its jobs computes it once itself and says False
    compare_reference: bool = True


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


def run_job(job: Job) -> JobResult:
    """Run one job (in whatever process it lands in)."""
    scene = load_scene(job.scene, job.overrides)
    result = run_scene(
        scene,
        output_dir=Path(job.output_dir),
        show_progress=False,
        compare_reference=job.compare_reference,
    )
    return JobResult(
        job,
        result.status,
        result.message,
        result.headline,
        result.stats.as_dict(),
        result.header,
        result.data,
        result.events,
    )


def run_jobs(
    jobs: list[Job], workers: int | None = None, dask_address: str | None = None
) -> list[JobResult]:
    """Run ``jobs`` in parallel and return their results in job order."""
    if not jobs:
        return []
    for job in jobs:  # loading builds (or finds cached) FMUs: once, here, not in every worker
        load_scene(job.scene, job.overrides)
    if dask_address:
        from dask.distributed import Client

        with Client(dask_address) as client:
            futures = client.map(run_job, jobs, pure=False)
            return client.gather(futures)
    workers = workers or min(len(jobs), os.cpu_count() or 1)
    # Spawned workers: pythonfmu's runtime must not inherit a parent's loaded FMUs.
    with ProcessPoolExecutor(max_workers=workers, mp_context=mp.get_context("spawn")) as pool:
        return list(pool.map(run_job, jobs))
