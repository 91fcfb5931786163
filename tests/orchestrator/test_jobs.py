"""The job runner: how pool workers start, and which scenes are loaded before jobs go out."""

from __future__ import annotations

import multiprocessing as mp
import threading
from pathlib import Path

import numpy as np

from orchestrator.run import run_scene
from orchestrator.scenario import load_scene
from orchestrator.studies import jobs as job_runner
from orchestrator.studies.jobs import Job, run_jobs

SCENE = Path(__file__).resolve().parents[2] / "scenarios" / "two_inertias.toml"


def two_jobs(tmp_path: Path, tag: str) -> list[Job]:
    return [
        Job(str(SCENE), {"master.step": h, "scene.stop": "0.02 s"}, str(tmp_path / f"{tag}{h}"))
        for h in (2e-4, 1e-4)
    ]


def test_a_run_leaves_no_thread_behind(tmp_path: Path, fmu_cache, monkeypatch) -> None:
    # A thread left running (tqdm's monitor did) would make every later pool spawn its
    # workers, each importing everything again, instead of forking them.
    monkeypatch.setenv("MECHCOSIM_FMU_CACHE", str(fmu_cache))
    before = set(threading.enumerate())
    scene = load_scene(SCENE, {"scene.stop": "0.01 s"})
    run_scene(scene, output_dir=tmp_path / "run", show_progress=True, plots=False)
    assert set(threading.enumerate()) == before


def test_forked_and_spawned_workers_give_the_same_numbers(
    tmp_path: Path, fmu_cache, monkeypatch
) -> None:
    monkeypatch.setenv("MECHCOSIM_FMU_CACHE", str(fmu_cache))
    results = {}
    for method in ("fork", "spawn"):
        monkeypatch.setattr(job_runner, "_pool_context", lambda m=method: mp.get_context(m))
        results[method] = run_jobs(two_jobs(tmp_path, method), workers=2)
    for a, b in zip(results["fork"], results["spawn"], strict=True):
        assert a.status == b.status == "completed"
        assert np.array_equal(a.data, b.data)
        assert a.headline == b.headline


def test_only_overrides_that_choose_an_fmu_are_loaded_beforehand() -> None:
    def choice(overrides: dict) -> dict:
        return job_runner._fmu_choice(Job("s.toml", overrides, "out"))

    assert choice({"fmus.b.parameters.k": 2.0, "master.step": 1e-4}) == {}
    swapped = {"fmus.b.component": "Inertia", "fmus.c.fmu": "c.fmu", "fmus.d": {"fmu": "d.fmu"}}
    assert choice({**swapped, "fmus.b.inputs.tau": 1.0}) == swapped
