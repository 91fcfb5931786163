"""What the compiled kernels buy a tolerance study: ``mechcosim study`` of the M739 on 2
workers, once with the compiled kernels and once with ``MECHCOSIM_PURE_PYTHON=1``, each a
command of its own, in turn; wall times and their ratio, and the same samples from both.

A study is where a user waits longest (a 100,000-sample M739 study is hours of CPU), so its
time is measured as a user sees it: the whole command, worker start-up and all.
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from components.kernels import path_environment
from orchestrator.studies.timing import print_targets

PROJECT = Path(__file__).resolve().parents[2]
SCENE = PROJECT / "scenarios" / "m739_study.toml"
SAMPLES = 64
WORKERS = 2
ROUNDS = 2


def _study(pure: bool, out: Path, samples: int = SAMPLES) -> float:
    """Wall time [s] of one study command, its samples written under ``out``."""
    env = path_environment(pure)
    command = [sys.executable, "-m", "orchestrator", "study", str(SCENE)]
    command += ["--samples", str(samples), "--workers", str(WORKERS), "--no-progress"]
    command += ["--output", str(out)]
    start = time.perf_counter()
    done = subprocess.run(command, env=env, capture_output=True, text=True, cwd=PROJECT)
    wall = time.perf_counter() - start
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(command)} failed: {done.stderr.strip()[-400:]}")
    return wall


def _samples(out: Path) -> str:
    return (out / "samples.csv").read_text()


def study_rows() -> list[tuple[str, float, str]]:
    """The study target: the compiled path's wall time against the fallback's (medians of
    ``ROUNDS`` commands each, run in turn), after checking both gave the same samples."""
    times: dict[bool, list[float]] = {False: [], True: []}
    with tempfile.TemporaryDirectory(prefix="mechcosim_study_speed_") as tmp:
        _study(False, Path(tmp) / "warm", samples=WORKERS)  # FMUs and kernels built: untimed
        for k in range(ROUNDS):
            for pure in (False, True):
                times[pure].append(_study(pure, Path(tmp) / f"{pure}-{k}"))
        same = _samples(Path(tmp) / "False-0") == _samples(Path(tmp) / "True-0")
    fast, slow = statistics.median(times[False]), statistics.median(times[True])
    print(
        f"M739 study, {SAMPLES} samples on {WORKERS} workers, wall time: {fast:.1f} s compiled, "
        f"{slow:.1f} s Python; the same samples: {'yes' if same else 'NO'}"
    )
    if not same:
        print("the two paths' samples.csv differ: the ratio below compares different work")
    return [(f"M739 study ({SAMPLES} samples, {WORKERS} workers): Python / compiled",
             slow / fast, ">= 2.5")]  # fmt: skip


def print_study_speed() -> None:
    print_targets(study_rows())
