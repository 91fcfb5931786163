"""The lower and upper limits of the settings the commands take, checked before any run
starts (docs/cli.md, "Limits"): a value outside them is refused in one line naming the
option, the value and the limit, instead of running for ever or quietly leaving runs out.

The scene's own keys are checked where the scene is read (master_settings, study_table);
this module holds the limits of the command-line options that multiply runs.
"""

from __future__ import annotations

from collections.abc import Iterable

from orchestrator.errors import ScenarioError
from orchestrator.master_settings import MAX_TOLERANCE, MIN_TOLERANCE

#: Local worker processes a command may start: each holds a whole run (its FMUs, its
#: series); more than this many only queue on the cores and the memory.
MAX_WORKERS = 256
#: The fewest samples of a study: a standard deviation needs two.
MIN_SAMPLES = 2
#: Macro steps one run may take, a scene's (orchestrator.scenario) and a sweep's alike:
#: more cannot finish in any sensible time, and are refused unless forced.
MAX_RUN_STEPS = 1e8


def check_workers(workers: int | None, option: str = "--workers") -> None:
    """1 <= workers <= MAX_WORKERS (None: one per core)."""
    if workers is None:
        return
    if workers < 1:
        raise ScenarioError(option, "", f"expected a positive number of workers, got {workers}")
    if workers > MAX_WORKERS:
        raise ScenarioError(option, "", f"{workers} is more than the limit of {MAX_WORKERS}")


def check_tolerances(values: Iterable[float], option: str) -> None:
    """Every tolerance within [MIN_TOLERANCE, MAX_TOLERANCE], the range master.tolerance
    takes: below it steps fall under the resolution of the time, so a run never ends."""
    for value in values:
        if not MIN_TOLERANCE <= value <= MAX_TOLERANCE:
            raise ScenarioError(
                option,
                "",
                f"{value:g} is outside {MIN_TOLERANCE:g} .. {MAX_TOLERANCE:g} (the range of "
                "master.tolerance)",
            )


def check_step_factors(factors: Iterable[float], step: float, duration: float) -> None:
    """Every factor gives a macro step within the run and at most MAX_RUN_STEPS of them;
    a step longer than the run would leave the fixed-step masters out of the report."""
    for f in factors:
        h = step * f
        if h > duration:
            raise ScenarioError(
                "--step-factors",
                "",
                f"{f:g} times the scene's step ({step:g} s) is {h:g} s, longer than the run "
                f"({duration:g} s); the largest factor taken is {duration / step:.6g}",
            )
        if duration / h > MAX_RUN_STEPS:
            raise ScenarioError(
                "--step-factors",
                "",
                f"{f:g} times the scene's step ({step:g} s) is {duration / h:.3g} macro steps, "
                f"more than the limit {MAX_RUN_STEPS:.0e}",
            )


def check_samples(samples: int, option: str = "--samples") -> None:
    """At least MIN_SAMPLES: one sample has no spread to state."""
    if samples < MIN_SAMPLES:
        raise ScenarioError(
            option,
            "",
            f"expected at least {MIN_SAMPLES} samples (a standard deviation needs two), "
            f"got {samples}",
        )
