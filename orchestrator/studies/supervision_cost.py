"""``mechcosim bench supervision``: what surviving a crashing FMU costs a run.

Three costs, each against its baseline measured in the same run: the flight record written
around every FMI call (a prepared doStep with and without it), the CSV row written through
at once (line-buffered against block-buffered), and the supervised child process of
``mechcosim run`` (a whole short run, supervised against ``--in-process``).
"""

from __future__ import annotations

import contextlib
import io
import tempfile
import time
from pathlib import Path

from fmus.build import build_fmu
from orchestrator.fmu_instance import FmuInstance
from orchestrator.recorder import Recorder
from orchestrator.studies.benchmarks import SCENARIOS, _best_per_call


def _do_step_costs(n: int) -> tuple[float, float]:
    """Seconds per doStep of the Inertia FMU: (bare FMI call, with the flight record)."""
    fmu = FmuInstance("bench", build_fmu("Inertia"))
    fmu.initialize(0.0, 1.0, {"J": 2e-4, "w0": 10.0})
    raw, component = fmu.fmu._functions["fmi2DoStep"], fmu.fmu.component
    noted = fmu._do_step

    def bare(count: int) -> None:
        for _ in range(count):
            raw(component, 0.0, 1e-5, 1)

    def recorded(count: int) -> None:
        for _ in range(count):
            noted(component, 0.0, 1e-5, 1)

    costs = _best_per_call(bare, n), _best_per_call(recorded, n)
    fmu.close()
    return costs


def _row_costs(n: int, columns: int = 8) -> tuple[float, float]:
    """Seconds per recorded row: (block-buffered file, line-buffered as the Recorder)."""
    row = [0.1234567890123 * (k + 1) for k in range(columns + 1)]
    with tempfile.TemporaryDirectory() as tmp:
        rec = Recorder(Path(tmp), [f"x{k}" for k in range(columns)])

        def line_buffered(count: int) -> None:
            for _ in range(count):
                rec.row(row)

        line = _best_per_call(line_buffered, n)
        rec._file.close()
        # The same writer on a block-buffered file: the baseline.
        rec._file = open(Path(tmp) / "block.csv", "w", newline="")  # noqa: SIM115
        import csv

        rec._writer = csv.writer(rec._file)
        rec.rows.clear()
        block = _best_per_call(line_buffered, n)
        rec.close({})
    return block, line


def _run_costs(steps: int = 2000, repeats: int = 3) -> tuple[float, float]:
    """Seconds per whole ``mechcosim run`` of two_inertias (``steps`` macro steps):
    (--in-process, supervised)."""
    from orchestrator.cli import main

    scene = SCENARIOS / "two_inertias.toml"
    times = {}
    with tempfile.TemporaryDirectory() as tmp:
        for how in ("--in-process", None):
            best = float("inf")
            for _ in range(repeats):
                args = ["run", str(scene), "--no-progress", "--output", tmp]
                args += ["--set", f"scene.stop={steps * 1e-5}", "--set", "master.step=1e-5"]
                args += [how] if how else []
                t0 = time.perf_counter()
                with contextlib.redirect_stdout(io.StringIO()):
                    code = main(args)
                best = min(best, time.perf_counter() - t0)
                if code != 0:
                    raise RuntimeError(f"mechcosim {' '.join(args)} ended with {code}")
            times[how] = best
    return times["--in-process"], times[None]


def print_supervision_cost() -> None:
    bare, recorded = _do_step_costs(20000)
    block, line = _row_costs(20000)
    alone, supervised = _run_costs()
    print(f"{'what':52s} {'baseline':>12s} {'with':>12s} {'ratio':>7s}")
    rows = (
        ("doStep of Inertia, flight record around it [us]", bare * 1e6, recorded * 1e6),
        ("CSV row of 9 numbers, written through [us]", block * 1e6, line * 1e6),
        ("mechcosim run two_inertias, 2000 steps, supervised [s]", alone, supervised),
    )
    for what, base, with_ in rows:
        print(f"{what:52s} {base:12.3f} {with_:12.3f} {with_ / base:7.3f}")
    print("baselines: bare FMI call, block-buffered file, --in-process; measured in this run")
