"""``mechcosim bench supervision``: what surviving a crashing FMU costs a run.

Three costs, each against its baseline measured in the same run: the flight record written
around every FMI call (a prepared doStep with and without it), the CSV row written through
at once (line-buffered against block-buffered), and the supervised child process of
``mechcosim run`` (a whole short run, supervised against ``--in-process``).
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

from fmus.build import build_fmu
from orchestrator.fmu_instance import FmuInstance
from orchestrator.recorder import Recorder
from orchestrator.studies.timing import SCENARIOS, best_per_call


def _do_step_costs(n: int) -> tuple[float, float]:
    """Seconds per prepared doStep of the Inertia FMU: (the call with its status check, as
    before the flight record; the same with the flight record around it)."""
    fmu = FmuInstance("bench", build_fmu("Inertia"))
    fmu.initialize(0.0, 1.0, {"J": 2e-4, "w0": 10.0})
    raw, component = fmu.fmu._functions["fmi2DoStep"], fmu.fmu.component
    noted = fmu._do_step

    def checked(component: object, t: float, h: float, last: int) -> int:
        status = raw(component, t, h, last)
        if status > 1:
            raise RuntimeError(status)
        return status

    def unrecorded(count: int) -> None:
        for _ in range(count):
            checked(component, 0.0, 1e-5, 1)

    def recorded(count: int) -> None:
        for _ in range(count):
            noted(component, 0.0, 1e-5, 1)

    best = [float("inf"), float("inf")]
    for _ in range(3):  # interleaved: a loaded machine drifts
        best[0] = min(best[0], best_per_call(unrecorded, n))
        best[1] = min(best[1], best_per_call(recorded, n))
    fmu.close()
    return best[0], best[1]


def _row_costs(n: int, columns: int = 8) -> tuple[float, float]:
    """Seconds per recorded row: (block-buffered file, line-buffered as the Recorder)."""
    row = [0.1234567890123 * (k + 1) for k in range(columns + 1)]
    with tempfile.TemporaryDirectory() as tmp:
        rec = Recorder(Path(tmp), [f"x{k}" for k in range(columns)])

        def line_buffered(count: int) -> None:
            for _ in range(count):
                rec.row(row)

        line = best_per_call(line_buffered, n)
        rec._file.close()
        # The same writer on a block-buffered file: the baseline.
        rec._file = open(Path(tmp) / "block.csv", "w", newline="")  # noqa: SIM115
        import csv

        rec._writer = csv.writer(rec._file)
        rec.rows.clear()
        block = best_per_call(line_buffered, n)
        rec.close({})
    return block, line


def _run_costs(steps: int = 2000, repeats: int = 5) -> tuple[float, float]:
    """Seconds per whole ``mechcosim run`` command of two_inertias (``steps`` macro steps),
    each a fresh process as a user starts it: (--in-process, supervised)."""
    scene = SCENARIOS / "two_inertias.toml"
    best = {True: float("inf"), False: float("inf")}
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(repeats):  # interleaved: a loaded machine drifts
            for in_process in (True, False):
                args = [sys.executable, "-m", "orchestrator", "run", str(scene), "--no-progress"]
                args += ["--output", tmp, "--set", f"scene.stop={steps * 1e-5}"]
                args += ["--set", "master.step=1e-5"] + (["--in-process"] if in_process else [])
                t0 = time.perf_counter()
                done = subprocess.run(args, capture_output=True, text=True)
                best[in_process] = min(best[in_process], time.perf_counter() - t0)
                if done.returncode != 0:
                    raise RuntimeError(f"{' '.join(args)} ended with {done.returncode}")
    return best[True], best[False]


def print_supervision_cost() -> None:
    bare, recorded = _do_step_costs(20000)
    block, line = _row_costs(20000)
    alone, supervised = _run_costs()
    print(f"{'what':52s} {'baseline':>12s} {'with':>12s} {'ratio':>7s}")
    rows = (
        ("doStep of Inertia, flight record around it [us]", bare * 1e6, recorded * 1e6),
        ("CSV row of 9 numbers, written through [us]", block * 1e6, line * 1e6),
        ("mechcosim run two_inertias, 2000 steps, whole command [s]", alone, supervised),
    )
    for what, base, with_ in rows:
        print(f"{what:52s} {base:12.3f} {with_:12.3f} {with_ / base:7.3f}")
    print(
        "baselines: the doStep call without the record, a block-buffered file, "
        "--in-process; best of interleaved repeats, measured in this run"
    )
