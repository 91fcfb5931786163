"""Sweeps run in parallel give the same numbers on a process pool and on a Dask cluster."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from orchestrator.studies.jobs import Job, run_jobs
from orchestrator.studies.work_precision import (
    ONE_PASS,
    START_HOLD,
    observed_order,
    work_precision,
)

SCENE = Path(__file__).resolve().parents[2] / "scenarios" / "two_inertias.toml"


def jobs(tmp_path: Path, tag: str) -> list[Job]:
    return [
        Job(str(SCENE), {"master.step": h, "scene.stop": "0.05 s"}, str(tmp_path / f"{tag}{h}"))
        for h in (2e-4, 1e-4, 5e-5)
    ]


@pytest.mark.slow  # in the slow suite (CI runs it): the default stays under 2 minutes
def test_pool_and_dask_give_identical_results(tmp_path: Path, fmu_cache, monkeypatch) -> None:
    pytest.importorskip("dask.distributed")
    from dask.distributed import LocalCluster

    monkeypatch.setenv("MECHCOSIM_FMU_CACHE", str(fmu_cache))
    local = run_jobs(jobs(tmp_path, "pool"), workers=2)
    with LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster:
        remote = run_jobs(jobs(tmp_path, "dask"), dask_address=cluster.scheduler_address)
    assert [r.status for r in local] == ["completed"] * 3
    for a, b in zip(local, remote, strict=True):
        assert a.header == b.header
        assert np.array_equal(a.data, b.data)
        assert a.headline == b.headline


def test_work_precision_report_for_the_two_inertias(tmp_path: Path, fmu_cache, monkeypatch) -> None:
    monkeypatch.setenv("MECHCOSIM_FMU_CACHE", str(fmu_cache))
    rows = work_precision(
        SCENE,
        tmp_path / "wp",
        step_factors=(4.0, 2.0, 1.0),
        tolerances=(1e-3, 1e-4),
        workers=2,
        start_hold_tolerances=(1e-3,),
    )
    # 3 steps x 2 fixed-step masters, 2 tolerances x (midpoint hold, single pass), 1 baseline
    assert len(rows) == 11 and all(r.result.status == "completed" for r in rows)
    assert [r.value for r in rows if r.master == ONE_PASS] == [1e-3, 1e-4]
    # The baseline (inputs held at the step start) at the same tolerance takes more steps.
    start = next(r for r in rows if r.master == START_HOLD)
    mid = next(r for r in rows if r.master == "regime-aware" and r.value == 1e-3)
    assert start.result.stats["steps"] > 2 * mid.result.stats["steps"]
    for master in ("jacobi", "gauss-seidel"):
        assert observed_order(rows, master) == pytest.approx(1.0, abs=0.15)
    for name in ("work_precision.csv", "work_precision.png", "work_precision.md"):
        assert (tmp_path / "wp" / name).stat().st_size > 0
    # The regime-aware master's error follows its tolerance (the midpoint hold makes the
    # steps grow as tol^-1/2 and the error fall as tol; 1e-2..3e-3 is pre-asymptotic).
    assert observed_order(rows, "regime-aware") == pytest.approx(1.0, abs=0.25)
    text = (tmp_path / "wp" / "work_precision.md").read_text()
    assert "Observed order" in text and "jacobi" in text and "event-time error" in text
    # No monolithic model for this family: the tolerance is held against the headline error.
    assert "x monolithic" not in text and "largest headline error <= tolerance" in text
    assert all(r.within_tolerance in ("yes", "no") for r in rows if r.setting == "tolerance")
