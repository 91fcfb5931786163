"""Running a piece of code on both kernel paths, as the compiled-kernel tests do: the
compiled kernels here, in the test's process, where they are loaded; the Python code
(``MECHCOSIM_PURE_PYTHON=1``) in a process of its own, since the kernels are bound when the
physics is imported."""

from __future__ import annotations

import contextlib
import io
import os
import subprocess
import sys
from pathlib import Path

import pytest

from components.kernels import path_environment, pure_python
from fmus.kernel_build import kernel_plan

PROJECT = Path(__file__).resolve().parents[1]
needs_kernels = pytest.mark.skipif(
    kernel_plan().compiler is None or pure_python(),
    reason="no Cython or C compiler, or MECHCOSIM_PURE_PYTHON set: no compiled kernels here",
)


def path_env(pure: bool) -> dict[str, str]:
    """This environment for a process of one path, the project importable."""
    return {**path_environment(pure), "PYTHONPATH": str(PROJECT)}


def printed_by(script: str, argv: list[str], pure: bool, name: str = "<kernel run>") -> str:
    """What ``script`` prints when run with ``argv`` on one path, from the project root."""
    if pure:
        run = subprocess.run(
            [sys.executable, "-c", script, *argv],
            env=path_env(True),
            capture_output=True,
            text=True,
            cwd=PROJECT,
            check=False,
        )
        assert run.returncode == 0, run.stderr[-2000:]
        return run.stdout
    saved, cwd = sys.argv, Path.cwd()
    sys.argv = ["-c", *argv]
    printed = io.StringIO()
    try:
        os.chdir(PROJECT)
        with contextlib.redirect_stdout(printed):
            exec(compile(script, name, "exec"), {"__name__": "__kernel_run__"})
    finally:
        sys.argv = saved
        os.chdir(cwd)
    return printed.getvalue()


def spent_budgets_alike(compiled: list, python: list) -> list:
    """Check the outcomes of a verge run under the integration's budget (7 steps) and the
    verge's own (40 indicator evaluations) are the same on both paths and refuse the next
    step or evaluation with the budget's words; the third, unbounded outcome returned."""
    assert compiled == python
    steps, evaluations, unbounded = compiled
    # The integration's budget: 7 steps, then the 8th is refused with the step's numbers.
    assert steps[0] == "components.event_integration"
    assert steps[1].startswith("spent its budget of 7 internal steps (max_internal_steps)")
    # The verge's own budget counts indicator evaluations: 40 and the 41st is refused.
    assert evaluations == ["components.verge_escapement", "internal step budget spent", -1]
    return unbounded
