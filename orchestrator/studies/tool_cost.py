"""What fixed-step coupling in another tool costs in accuracy: M739 turns to arm from
libcosim's fixed-step run of the exported system, against the monolithic reference,
beside our own fixed-step Jacobi and the regime-aware master.

Turns to arm are the M739 analysis's (``orchestrator.scenes.m739.report``): the arming
time is where the escape-wheel angle first reaches the arming angle (Lowen & Tepper 1982:
1485 deg of escape wheel), interpolated linearly within the step that crosses it.

``python -m orchestrator.studies.tool_cost [SCENE] [--steps 1e-6,1e-5]`` prints the table.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from orchestrator.run import RunResult, reference_of, run_scene
from orchestrator.scenario import load_scene, read_toml, scene_from_table
from orchestrator.scene_model import Scene
from orchestrator.scenes.m739.report import arming_time, instance_names, turns_to_arm
from orchestrator.studies.crosscheck import grid_steps, run_tool

SCENE = Path(__file__).resolve().parents[2] / "scenarios" / "m739.toml"


@dataclass
class CostRow:
    how: str  # "libcosim fixed step", "mechcosim Jacobi", "mechcosim regime-aware"
    step: float | None  # the fixed macro step (None: the master chooses)
    turns: float | None  # None: did not arm within the span
    error: float | None  # relative to the reference's turns
    wall_time: float


def turns(scene: Scene, t: np.ndarray, phi: np.ndarray) -> float | None:
    """Turns to arm from an escape-wheel angle history (None: the angle is not reached)."""
    t_arm = arming_time(scene, t, phi)
    return None if t_arm is None else turns_to_arm(scene, t_arm)


def measure(
    path: Path = SCENE, steps: tuple[float, ...] = (1e-6, 1e-5), span: float = 0.056
) -> tuple[float, list[CostRow]]:
    """(reference turns, rows): libcosim and our Jacobi at each fixed step over ``span``
    seconds, and the regime-aware master as the scene sets it."""
    base = load_scene(path)
    wheel = f"{instance_names(base)[0]}.phi"  # the escape-wheel angle
    reference = reference_of(base).headline["turns_to_arm"]
    rows = []

    def row(how: str, step: float | None, turns: float | None, wall: float) -> CostRow:
        error = None if turns is None else abs(turns - reference) / reference
        return CostRow(how, step, turns, error, wall)

    with tempfile.TemporaryDirectory(prefix="mechcosim-tool-cost-") as scratch:
        for h in steps:
            # Only the angle is recorded (and so no analysis): the runs time the coupling.
            raw = read_toml(path)
            raw.pop("report", None)
            raw["output"]["record"] = [wheel]
            fixed = {"master.algorithm": "jacobi", "master.step": h, "scene.stop": span}
            scene = scene_from_table(path, raw, fixed)
            theirs = run_tool(scene, "libcosim", grid_steps(scene, span), Path(scratch) / f"{h}")
            t, phi = theirs.data[:, 0], theirs.data[:, 1]
            rows.append(row("libcosim fixed step", h, turns(base, t, phi), theirs.wall_time))
            started = time.perf_counter()
            ours = run_scene(
                scene,
                output_dir=Path(scratch) / f"jacobi-{h}",
                show_progress=False,
                compare_reference=False,
            )
            wall = time.perf_counter() - started
            rows.append(row("mechcosim Jacobi", h, turns(base, *_wheel(ours, wheel)), wall))
        started = time.perf_counter()
        ours = run_scene(
            base,
            output_dir=Path(scratch) / "regime-aware",
            show_progress=False,
            compare_reference=False,
        )
        wall = time.perf_counter() - started
        rows.append(
            row(f"mechcosim {base.master.algorithm}", None, turns(base, *_wheel(ours, wheel)), wall)
        )
    return reference, rows


def _wheel(result: RunResult, wheel: str) -> tuple[np.ndarray, np.ndarray]:
    return result.signal("time"), result.signal(wheel)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene", nargs="?", type=Path, default=SCENE)
    parser.add_argument("--steps", default="1e-6,1e-5", help="fixed steps, comma-separated")
    args = parser.parse_args(argv)
    steps = tuple(float(s) for s in args.steps.split(","))
    reference, rows = measure(args.scene, steps)
    print(f"monolithic reference: {reference:.6f} turns to arm")
    print("| coupling | step | turns to arm | error | wall time |")
    print("|---|---|---|---|---|")
    for r in rows:
        step = f"{r.step * 1e6:g} µs" if r.step else "adaptive"
        turns = f"{r.turns:.6f}" if r.turns is not None else "not armed"
        error = f"{r.error:.2e}" if r.error is not None else "-"
        print(f"| {r.how} | {step} | {turns} | {error} | {r.wall_time:.1f} s |")


if __name__ == "__main__":
    main()
