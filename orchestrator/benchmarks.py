"""Benchmarks (not tests): costs measured against a baseline taken in the same run.

``mechcosim bench overhead``: the cost of one FMU doStep through fmpy and of one master
macro step, against the same physics stepped as plain Python objects.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

from components.rotational import Inertia, SpringDamperInertia
from fmus.build import build_fmu
from orchestrator.fmu_instance import FmuInstance
from orchestrator.run import run_scene
from orchestrator.scenario import load_scene

SCENARIOS = Path(__file__).resolve().parent.parent / "scenarios"


def _best_per_call(fn: Callable[[int], None], n: int, repeats: int = 5) -> float:
    """Best-of-repeats seconds per call of a loop of n calls."""
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn(n)
        best = min(best, (time.perf_counter() - t0) / n)
    return best


def overhead(n: int = 20000) -> dict[str, float]:
    """Seconds per call: plain component step, FMU doStep, master macro step (2 FMUs)."""
    body = Inertia(J=2e-4, w0=10.0)
    body.initialize(0.0)

    def plain(count: int) -> None:
        for _ in range(count):
            body.step(0.0, 1e-5)

    fmu = FmuInstance("bench", build_fmu("Inertia"))
    fmu.initialize(0.0, 1.0, {"J": 2e-4, "w0": 10.0})
    tau_ref, out_refs = fmu.refs(["tau"]), fmu.refs(["phi", "w"])

    def through_fmu(count: int) -> None:
        step = fmu.do_step
        for _ in range(count):
            step(0.0, 1e-5)

    def exchange_and_step(count: int) -> None:
        for _ in range(count):
            fmu.set_real(tau_ref, [0.0])
            fmu.do_step(0.0, 1e-5)
            fmu.get_real(out_refs)

    # Coupled pair stepped as plain Python (the master's work without FMI) ...
    a, b = Inertia(J=2e-4, w0=10.0), SpringDamperInertia(J=1e-4, k=2.0, d=2e-3)
    a.initialize(0.0)
    b.initialize(0.0)

    def plain_pair(count: int) -> None:
        for _ in range(count):
            a.tau = b.tau
            b.phi_in, b.w_in = a.phi, a.w
            b.update_outputs()
            a.step(0.0, 1e-5)
            b.step(0.0, 1e-5)

    # ... and through the master with the FMUs, recording every step.
    scene = load_scene(
        SCENARIOS / "two_inertias.toml", {"master.step": 1e-5, "scene.stop": n * 1e-5}
    )

    def master(count: int) -> None:
        run_scene(scene, output_dir=Path("runs") / "bench_overhead", show_progress=False)

    results = {
        "component step (plain Python)": _best_per_call(plain, n),
        "FMU doStep through fmpy": _best_per_call(through_fmu, n),
        "FMU setReal + doStep + getReal": _best_per_call(exchange_and_step, n),
        "coupled pair, plain Python, per macro step": _best_per_call(plain_pair, n),
        "coupled pair, Jacobi master + FMUs + recording, per macro step": _best_per_call(
            master, n, repeats=3
        ),
    }
    fmu.close()
    return results


def print_overhead() -> None:
    results = overhead()
    base = results["component step (plain Python)"]
    pair = results["coupled pair, plain Python, per macro step"]
    print(f"{'what':66s} {'us/call':>9s} {'ratio':>8s}")
    for name, seconds in results.items():
        ref = pair if name.startswith("coupled") else base
        print(f"{name:66s} {seconds * 1e6:9.2f} {seconds / ref:8.1f}x")
    print("ratios: against the plain-Python step of the same physics, measured in this run")


BENCHMARKS: dict[str, Callable[[], None]] = {"overhead": print_overhead}
