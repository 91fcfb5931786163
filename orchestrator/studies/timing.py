"""What the benchmarks share: where the scenes are, a best-of-repeats per-call time, and the
table of measured ratios against their targets."""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"


def print_targets(rows: list[tuple[str, float, str]]) -> None:
    """One line a row: what was measured, its value and its target ('' for none)."""
    width = max(len(what) for what, _, _ in rows)
    print(f"\n{'ratio':{width}s} {'measured':>9s} {'target':>7s}")
    for what, value, target in rows:
        print(f"{what:{width}s} {value:9.2f} {target:>7s}")


def best_per_call(fn: Callable[[int], None], n: int, repeats: int = 5) -> float:
    """Best-of-repeats seconds per call of a loop of n calls."""
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn(n)
        best = min(best, (time.perf_counter() - t0) / n)
    return best
