"""What a results directory holds, for ``mechcosim report``: the summary a run wrote, or
one rebuilt from what a run in progress or a killed one leaves (docs/cli.md, "report").

- a run in progress holds the directory's lock (orchestrator.output_lock): "running",
  with the rows recorded so far (a summary.json beside it is an earlier run's);
- a finished run wrote ``summary.json``: that;
- a run killed while writing its summary left only ``summary.json.part``: that, if it is
  whole, with a note;
- a run killed with its supervisor (SIGKILL to both) left ``timeseries.csv`` and the lock
  file, which names its scene and process: "incomplete", rebuilt from the two.
"""

from __future__ import annotations

import errno
import fcntl
import json
import os
from pathlib import Path
from typing import Any

from orchestrator.errors import RunError
from orchestrator.output_lock import LOCK_NAME
from orchestrator.regular_files import CSV_LIMIT, SUMMARY_LIMIT, NotARegularFile, read_regular

RUNNING = "running"
INCOMPLETE = "incomplete"


class NotARunDirectory(RunError):
    """A directory with nothing a run writes."""


def run_summary(directory: Path) -> dict[str, Any]:
    """The summary of the run in ``directory``, written or rebuilt (see the module)."""
    directory = Path(directory)
    if directory.exists() and not directory.is_dir():
        raise NotARunDirectory(f"{directory} is a file: expected a run's results directory")
    owner = _lock_owner(directory)
    if owner is not None and _locked(directory):
        return _rebuilt(directory, owner, RUNNING)
    written = directory / "summary.json"
    if written.exists() or written.is_symlink():
        return read_summary(written)
    partial = directory / "summary.json.part"
    if partial.exists():
        try:
            summary = read_summary(partial)
        except RunError:
            summary = None  # cut short: rebuilt from the series below
        if summary is not None:
            note = (
                "only summary.json.part was found: the run ended while writing its summary, "
                "which is read as it stands"
            )
            return {**summary, "notes": [*(summary.get("notes") or []), note]}
    if (directory / "timeseries.csv").exists():
        return _rebuilt(directory, owner or {}, INCOMPLETE)
    raise NotARunDirectory(f"{written} not found: not a run directory")


def read_summary(path: Path) -> dict[str, Any]:
    """A summary file, a regular file below SUMMARY_LIMIT holding a JSON object with a
    status; RunError naming the file otherwise."""
    try:
        summary = json.loads(read_regular(path, SUMMARY_LIMIT).decode("utf-8"))
    except NotARegularFile as exc:
        raise RunError(f"{path} {exc.strerror}") from None
    except (ValueError, UnicodeDecodeError) as exc:
        raise RunError(f"{path} is not a readable summary: {exc}") from None
    if not isinstance(summary, dict) or not isinstance(summary.get("status"), str):
        raise RunError(f"{path} is not a run summary (no status)")
    return summary


def _lock_owner(directory: Path) -> dict[str, Any] | None:
    try:
        owner = json.loads(read_regular(directory / LOCK_NAME, 1 << 16))
    except (OSError, ValueError, UnicodeDecodeError):
        return None
    return owner if isinstance(owner, dict) else {}


def _locked(directory: Path) -> bool:
    """The lock is held by a live process (the OS drops it when its process ends)."""
    try:
        fd = os.open(directory / LOCK_NAME, os.O_RDONLY | os.O_NONBLOCK)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
    except OSError as exc:
        return exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES)
    else:
        fcntl.flock(fd, fcntl.LOCK_UN)
        return False
    finally:
        os.close(fd)


def series_rows(path: Path) -> tuple[int, float | None]:
    """(whole data rows, time of the last) of a series being written or cut short: a last
    line without its newline is a row cut in the middle, not counted."""
    try:
        data = read_regular(path, CSV_LIMIT)
    except NotARegularFile as exc:
        raise RunError(f"{path} {exc.strerror}") from None
    lines = data.split(b"\n")
    whole = lines[1:-1]  # after the header; the last piece is "" or a cut row
    whole = [line for line in whole if line.strip()]
    if not whole:
        return 0, None
    try:
        return len(whole), float(whole[-1].split(b",", 1)[0])
    except ValueError:
        return len(whole), None


def _rebuilt(directory: Path, owner: dict[str, Any], status: str) -> dict[str, Any]:
    rows, last = (
        series_rows(directory / "timeseries.csv")
        if (directory / "timeseries.csv").exists()
        else (0, None)
    )
    events = 0
    if (directory / "events.csv").exists():
        events = max(0, series_rows(directory / "events.csv")[0])
    who = f"pid {owner['pid']} on {owner.get('host', '?')}" if "pid" in owner else "its process"
    stop = owner.get("stop")
    where = f"t = {last:.9g} s" if last is not None else "no row yet"
    if stop is not None and last is not None:
        where += f" of {float(stop):.9g} s"
    if status == RUNNING:
        message = f"in progress ({who}): {rows} rows recorded so far, {where}"
        notes = [
            "the run is still going: its summary, headline and reference comparison come "
            "when it ends (an earlier run's summary.json here is not this run's)"
        ]
    else:
        message = (
            f"incomplete: the run ({who}) ended without a summary, killed with its "
            f"supervisor; {rows} rows recorded, {where}"
        )
        notes = [
            "rebuilt from timeseries.csv, events.csv and the lock file the run left: no "
            "headline quantities, analyses or reference comparison"
        ]
    return {
        "scene": owner.get("scene", directory.name),
        "status": status,
        "message": message,
        "time_reached": last,
        "headline": {},
        "accuracy": {},
        "notes": notes,
        "stats": {"rows_recorded": rows, "events_recorded": events},
        "metadata": {k: owner[k] for k in ("scene_file",) if k in owner},
        "rebuilt": True,
    }
