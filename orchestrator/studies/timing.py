"""What the benchmarks share: where the scenes are, and a best-of-repeats per-call time."""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"


def best_per_call(fn: Callable[[int], None], n: int, repeats: int = 5) -> float:
    """Best-of-repeats seconds per call of a loop of n calls."""
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn(n)
        best = min(best, (time.perf_counter() - t0) / n)
    return best
