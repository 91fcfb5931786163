"""Run one scene: build/load its FMUs, run the master, record, report.

A failure anywhere after loading (an FMU step that fails, a diverging master) ends the
run with status "failed" and a message naming the FMU and time; everything recorded up
to then is kept on disk and in the result.
"""

from __future__ import annotations

import platform
import subprocess
import time
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

from fmus.build import build_fmu
from orchestrator.accuracy import compare
from orchestrator.analyses import ANALYSES, PLOTS, energy_residual, headline
from orchestrator.errors import RunError
from orchestrator.fmu_instance import file_sha256
from orchestrator.masters import MASTERS
from orchestrator.recorder import Recorder, StepStats
from orchestrator.references import REFERENCES, Reference
from orchestrator.scenario import Scene
from orchestrator.system import CoupledSystem

PROJECT_DIR = Path(__file__).resolve().parent.parent


@dataclass
class RunResult:
    scene: Scene
    status: str  # "completed" or "failed"
    message: str
    header: list[str]
    data: np.ndarray
    events: list[tuple[float, str, str, str]]
    stats: StepStats
    headline: dict[str, dict[str, Any]]
    output_dir: Path
    accuracy: dict[str, float] = field(default_factory=dict)
    metadata: dict[str, Any] = field(default_factory=dict)

    def signal(self, name: str) -> np.ndarray:
        """Recorded column by name ('time' or '<instance>.<variable>')."""
        return self.data[:, self.header.index(name)]

    def value(self, quantity: str) -> float:
        return self.headline[quantity]["value"]


def run_scene(
    scene: Scene,
    output_dir: Path | None = None,
    cache_dir: Path | None = None,
    show_progress: bool = True,
    compare_reference: bool = True,
) -> RunResult:
    """Run ``scene`` and write its results under ``output_dir`` (default: the scene's)."""
    out = Path(output_dir) if output_dir else scene.output_dir
    fmu_paths = fmu_files(scene, cache_dir)
    system = CoupledSystem(scene, fmu_paths)
    recorder = Recorder(out, system.record_header)
    stats = StepStats()
    meta = _metadata(scene, fmu_paths)
    status, message = "completed", ""
    bar = tqdm(
        total=scene.stop - scene.start,
        unit="s(sim)",
        delay=1.0,  # only runs longer than a moment show a bar
        disable=not show_progress,
        leave=False,
        bar_format="{l_bar}{bar}| {n:.4g}/{total:.4g} s [{elapsed}<{remaining}]",
    )
    last = [scene.start, time.perf_counter()]

    def progress(t: float) -> None:
        now = time.perf_counter()
        if now - last[1] > 0.2:  # keep the bar off the hot path
            bar.update(t - last[0])
            last[0], last[1] = t, now

    start = time.perf_counter()
    try:
        system.initialize()
        MASTERS[scene.master.algorithm](system, scene, recorder, stats, progress)
    except RunError as exc:
        status, message = "failed", str(exc)
    finally:
        stats.wall_time = time.perf_counter() - start
        bar.close()
        system.close()
    data = recorder.array()
    quantities = headline(scene, recorder.header, data)
    residual = energy_residual(recorder.header, data)
    if residual is not None:
        quantities["energy_residual"] = residual
    if scene.analysis and status == "completed":
        quantities.update(
            ANALYSES[scene.analysis](scene, recorder.header, data, scene.analysis_options)
        )
        if scene.analysis in PLOTS and len(data) > 1:
            PLOTS[scene.analysis](scene, recorder.header, data, out / f"{scene.name}.png")
    accuracy: dict[str, float] = {}
    if scene.reference and status == "completed" and compare_reference:
        ref = reference_of(scene)
        accuracy = compare(recorder.header, data, recorder.events, quantities, ref)
        accuracy["reference_wall_time"] = ref.wall_time
    recorder.close(
        {
            "scene": scene.name,
            "status": status,
            "message": message,
            "headline": quantities,
            "accuracy": accuracy,
            "stats": stats.as_dict(),
            "metadata": meta,
        }
    )
    return RunResult(
        scene,
        status,
        message,
        recorder.header,
        data,
        recorder.events,
        stats,
        quantities,
        out,
        accuracy,
        meta,
    )


def fmu_files(scene: Scene, cache_dir: Path | None = None) -> dict[str, Path]:
    """Instance -> FMU file: the scene's, ours taken from ``cache_dir`` when one is given
    (the same build: the file name is its content hash)."""
    return {
        name: build_fmu(spec.component, cache_dir) if spec.component and cache_dir else spec.path
        for name, spec in scene.fmus.items()
    }


def reference_of(scene: Scene) -> Reference:
    """The scene's reference, timed (wall_time is filled in)."""
    start = time.perf_counter()
    ref = REFERENCES[scene.reference](scene)
    ref.wall_time = time.perf_counter() - start
    return ref


def _metadata(scene: Scene, fmu_paths: dict[str, Path]) -> dict[str, Any]:
    versions = {}
    for package in ("fmpy", "pythonfmu", "numpy", "scipy", "pint"):
        try:
            versions[package] = metadata.version(package)
        except metadata.PackageNotFoundError:
            versions[package] = None
    return {
        "scene_file": str(scene.path),
        "scene_sha256": file_sha256(scene.path),
        "fmus": {
            name: {"file": p.name, "sha256": file_sha256(p), "model": scene.fmus[name].fmu}
            for name, p in fmu_paths.items()
        },
        "master": {
            "algorithm": scene.master.algorithm,
            "step": scene.master.step,
            "order": list(scene.master.order),
            **scene.master.options,
        },
        "start": scene.start,
        "stop": scene.stop,
        "python": platform.python_version(),
        "versions": versions,
        "commit": _git_commit(),
        "date": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
    }


def _git_commit() -> str | None:
    try:
        out = subprocess.run(
            ["git", "rev-parse", "HEAD"], cwd=PROJECT_DIR, capture_output=True, text=True, timeout=5
        )
    except (OSError, subprocess.TimeoutExpired):
        return None
    return out.stdout.strip() or None
