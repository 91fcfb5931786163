"""Many runs of a scene with different settings, on a local process pool or a Dask cluster.

Each job is (scene file, overrides, results directory).  Workers load the scene, run it
and send back numbers only (status, headline, statistics, recorded series), so results
are the same wherever they ran.  FMUs are built once, before the jobs go out.  Local
workers are supervised (``job_workers``): an FMU that crashes, stops or hangs ends its
job with status "crashed" or "timed out", and the others go on.
"""

from __future__ import annotations

import multiprocessing as mp
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from pathlib import Path
from typing import Any

from orchestrator.run import run_scene
from orchestrator.scenario import load_scene
from orchestrator.setting_limits import check_workers
from orchestrator.studies.job_types import Job, JobResult
from orchestrator.studies.job_workers import can_supervise_jobs, iter_supervised


def run_job(job: Job) -> JobResult:
    """Run one job (in whatever process it lands in)."""
    scene = load_scene(job.scene, job.overrides)
    result = run_scene(
        scene,
        output_dir=Path(job.output_dir),
        show_progress=False,
        compare_reference=job.compare_reference,
        plots=job.plots,
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
        result.notes,
    )


def run_jobs(
    jobs: list[Job], workers: int | None = None, dask_address: str | None = None
) -> list[JobResult]:
    """Run ``jobs`` in parallel and return their results in job order (a job that raised
    raises here)."""
    # Loading a scene builds (or finds cached) its FMUs: here, once per distinct set, so
    # that workers never build one at the same time.
    distinct = {(job.scene, repr(_fmu_choice(job))): job for job in jobs}
    for job in distinct.values():
        load_scene(job.scene, _fmu_choice(job))
    results: list[JobResult | None] = [None] * len(jobs)
    for k, outcome in iter_jobs(jobs, workers, dask_address):
        if isinstance(outcome, Exception):
            raise outcome
        results[k] = outcome
    return results  # type: ignore[return-value]  # every index was filled


def _fmu_choice(job: Job) -> dict[str, Any]:
    """The overrides of a job that name an FMU's component or file: with the scene file,
    what decides the FMUs it needs (parameters, inputs and master settings choose none)."""
    return {
        key: value
        for key, value in sorted(job.overrides.items())
        if key.split(".")[0] == "fmus" and key.split(".")[2:3] in ([], ["component"], ["fmu"])
    }


def _ignore_sigint() -> None:
    """Pool workers leave Ctrl-C to the parent, which stops handing out jobs; a job under
    way finishes (run_scene keeps a SIGINT the process ignores ignored)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _pool_context() -> mp.context.BaseContext:
    """How pool workers start.  Forked from this process where that is safe (Linux, and
    no other thread here that could hold a lock at the fork), they begin with its modules
    imported: a spawned worker spends about 2.5 s importing the unit registry and scipy
    before its first job, as long as a dozen lever runs.  Elsewhere: spawned."""
    if sys.platform == "linux" and threading.active_count() == 1:
        return mp.get_context("fork")
    return mp.get_context("spawn")


def iter_jobs(
    jobs: list[Job],
    workers: int | None = None,
    dask_address: str | None = None,
    stop: Callable[[], bool] | None = None,
) -> Iterator[tuple[int, JobResult | Exception]]:
    """Run ``jobs`` in parallel and yield (index, result) as each finishes, an exception in
    place of the result when the job raised (e.g. a sample its scene refuses).  When
    ``stop()`` turns true no further job starts; those under way still report.  The FMUs
    must be built beforehand (load the scene once).  Local jobs run in supervised worker
    processes (``job_workers``), even with one worker."""
    check_workers(workers)
    if not jobs:
        return
    stop = stop or (lambda: False)
    if dask_address:
        yield from _iter_dask(jobs, dask_address, stop)
        return
    workers = min(workers or os.cpu_count() or 1, len(jobs))
    if can_supervise_jobs():
        yield from iter_supervised(jobs, workers, stop, run_job)
        return
    # Without fork (Windows): unsupervised, as a crash there cannot be survived anyway.
    if workers == 1:  # in this process, one after another: no pool to start
        for k, job in enumerate(jobs):
            if stop():
                return
            try:
                yield k, run_job(job)
            except Exception as exc:  # noqa: BLE001 - reported as the job's outcome
                yield k, exc
        return
    # Never more processes than jobs: a fork pool starts all its workers at once.
    with ProcessPoolExecutor(
        min(workers, len(jobs)), mp_context=_pool_context(), initializer=_ignore_sigint
    ) as pool:
        futures = {pool.submit(run_job, job): k for k, job in enumerate(jobs)}
        pending = set(futures)
        stopping = False
        while pending:
            if not stopping and stop():
                stopping = True
                for future in pending:
                    future.cancel()
                pending = {f for f in pending if not f.cancelled()}
            done, pending = wait(pending, timeout=0.25, return_when=FIRST_COMPLETED)
            for future in sorted(done, key=futures.__getitem__):
                if future.cancelled():
                    continue
                error = future.exception()
                yield futures[future], error if error is not None else future.result()


def _iter_dask(
    jobs: list[Job], address: str, stop: Callable[[], bool]
) -> Iterator[tuple[int, JobResult | Exception]]:
    from dask.distributed import Client, as_completed

    with Client(address) as client:
        futures = client.map(run_job, jobs, pure=False)
        index = {f.key: k for k, f in enumerate(futures)}
        finished = as_completed(futures)
        for future in finished:
            error = future.exception() if future.status == "error" else None
            yield index[future.key], error if error is not None else future.result()
            if stop():
                running = [f for f in futures if not f.done()]
                client.cancel(running)
                break
