"""What a run prints: the same lines for ``mechcosim run`` as it ends and for
``mechcosim report RUN_DIR`` afterwards, both from the run's summary (``summary.json``).

Status first (completed, failed, interrupted, crashed), then the headline quantities with
their units, the errors against the reference, notes and warnings, where an interrupted
run stopped, the step statistics and where the results are.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any


def summary_lines(summary: dict[str, Any], output_dir: Path | str) -> list[str]:
    """The lines that tell a run from its summary (as written to ``summary.json``; a key a
    run that ended early did not write is left out, a null number prints as nan)."""
    status = summary.get("status", "unknown")
    full = str(summary.get("message") or "")
    message = one_line(full)
    if message != full.strip():
        message += " (full message in summary.json)"
    lines = [f"scene {summary.get('scene')}: {status}" + (f" — {message}" if message else "")]
    for name, q in (summary.get("headline") or {}).items():
        lines.append(headline_line(name, q))
    for name, value in (summary.get("accuracy") or {}).items():
        lines.append(f"  {name:32s} {_number(value):.4g}")
    for note in summary.get("notes") or []:  # what the analyses could not compute
        lines.append(f"  note: {note}")
    stats = summary.get("stats") or {}
    for warning in stats.get("warnings") or []:  # what the master gave up
        lines.append(f"  warning: {warning}")
    if status == "interrupted" and summary.get("time_reached") is not None:
        lines.append(f"  interrupted at t = {_number(summary['time_reached']):.9g} s (simulated)")
    lines.append(_stats_line(stats))
    lines.append(f"  results in {output_dir}")
    return lines


def headline_line(name: str, quantity: dict) -> str:
    """One headline quantity as the run prints it; a dimensionless one (a count, a ratio)
    without a unit."""
    value = quantity["value"]
    text = value if isinstance(value, str) else f"{_number(value):.10g}"
    unit = "" if quantity["unit"] in ("1", "") else f" {quantity['unit']}"
    return f"  {name:32s} {text}{unit}"


def one_line(text: str) -> str:
    """The first line of a message (an FMU's failure may carry a traceback after it)."""
    text = text.strip()
    return text.splitlines()[0] if text else ""


def _stats_line(stats: dict[str, Any]) -> str:
    """The step counts (a run that crashed or never started has only its wall time)."""
    counts = (
        ("steps", "steps"),
        ("do_steps", "doSteps"),
        ("rejections", "rejections"),
        ("rollbacks", "rollbacks"),
        ("events", "events"),
    )
    parts = [f"{label} {stats[key]}" for key, label in counts if key in stats]
    for key, label in (("rows_recorded", "rows recorded"), ("events_recorded", "events recorded")):
        if key in stats:  # a summary rebuilt from the series (orchestrator.run_state)
            parts.append(f"{label} {stats[key]}")
    if "wall_time" in stats:
        parts.append(f"wall time {_number(stats['wall_time']):.3f} s")
    return "  " + (", ".join(parts) if parts else "no steps taken")


def _number(value: Any) -> float:
    """A number as the summary holds it: null (a non-finite value) is nan."""
    return math.nan if value is None else float(value)
