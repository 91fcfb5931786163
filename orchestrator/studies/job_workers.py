"""Jobs in supervised worker processes: an FMU that crashes, stops or hangs ends its job only.

Each worker is a process forked from this one (so it starts with every module imported)
that runs one job at a time, sent and answered through a pipe, and keeps a flight record
in memory it shares with this process (``orchestrator.flight``).  This process watches
each worker as ``mechcosim run`` watches its run (``orchestrator.child_watch``): a worker
that dies, stops, or stays in one FMI call longer than its scene's ``master.call_timeout``
is killed and its job answered with status "crashed" or "timed out", the FMU, the call and
the time reached, its ``summary.json`` written and its recorded series read back; a new
worker takes the next job.  Workers have their own process group (a Ctrl-C at the
terminal reaches this process only) and end with this process.
"""

from __future__ import annotations

import contextlib
import csv
import faulthandler
import multiprocessing.connection as mpc
import os
import signal
import sys
import time
from collections import deque
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from multiprocessing import Pipe
from pathlib import Path
from typing import Any

import numpy as np

from orchestrator import child_watch, flight, interrupt
from orchestrator.studies.job_types import Job, JobResult


def can_supervise_jobs() -> bool:
    """Forking is there (Linux, macOS)."""
    return hasattr(os, "fork")


@dataclass
class _Worker:
    pid: int
    conn: Any  # this process's end of the pipe
    record: flight.Flight
    watch: child_watch.ChildWatch
    job: int | None = None  # the index of the job under way
    started: float = 0.0  # when it began [s, perf_counter]


def iter_supervised(
    jobs: list[Job],
    workers: int,
    stop: Callable[[], bool],
    run: Callable[[Job], JobResult],
) -> Iterator[tuple[int, JobResult | Exception]]:
    """Run ``jobs`` on ``workers`` supervised processes; yield (index, result) as each
    finishes, an exception in place of a result for a job that raised.  When ``stop()``
    turns true no further job starts and those under way finish (a second SIGINT/SIGTERM
    of the command's signal guard interrupts them at their next step boundary; one that
    does not stop within child_watch.SIGNAL_GRACE is killed)."""
    queue = deque(range(len(jobs)))
    pool: list[_Worker] = []
    forwarded = False
    try:
        while queue or any(w.job is not None for w in pool):
            if queue and stop():
                queue.clear()
            if not forwarded and _second_signal() is not None:
                forwarded = True
                queue.clear()
                for w in pool:
                    if w.job is not None:
                        w.watch.ask_to_stop(_second_signal() or signal.SIGTERM)
            for w in pool:
                if w.job is None and queue:
                    _hand_out(w, queue.popleft(), jobs)
            while queue and len(pool) < workers:
                pool.append(_start_worker(pool, run))
                _hand_out(pool[-1], queue.popleft(), jobs)
            busy = [w for w in pool if w.job is not None]
            ready = mpc.wait([w.conn for w in busy], timeout=2 * child_watch.POLL)
            for w in busy:
                if w.conn in ready:
                    try:
                        k, outcome = w.conn.recv()
                    except (EOFError, OSError):
                        pass  # it died: below
                    else:
                        w.job = None
                        yield k, outcome
                        continue
                status = w.watch.poll()
                if status is None:
                    continue
                k, w.job = w.job, None
                pool.remove(w)
                w.conn.close()
                yield k, _ended_job(jobs[k], w, status)
    finally:
        _end_workers(pool)


def _second_signal() -> int | None:
    """The signal of the command's guard once it has come twice (the first only stops
    handing out jobs), else None."""
    guard = interrupt._ACTIVE  # noqa: SLF001 - the command's guard, shared on purpose
    if guard is not None and guard.count >= 2:
        return guard.signum
    return None


def _hand_out(worker: _Worker, k: int, jobs: list[Job]) -> None:
    worker.job, worker.started = k, time.perf_counter()
    worker.record.reset()
    worker.watch = child_watch.ChildWatch(worker.pid, worker.record)
    worker.conn.send((k, jobs[k]))


def _start_worker(pool: list[_Worker], run: Callable[[Job], JobResult]) -> _Worker:
    record = flight.shared()
    mine, theirs = Pipe()
    parent = os.getpid()
    child_watch.prepare_children()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    pid = os.fork()
    if pid == 0:
        _worker(theirs, [mine, *(w.conn for w in pool)], record, parent, run)
    theirs.close()
    return _Worker(pid, mine, record, child_watch.ChildWatch(pid, record))


def _worker(
    conn: Any,
    others: list[Any],
    record: flight.Flight,
    parent: int,
    run: Callable[[Job], JobResult],
) -> None:
    """The worker's life: jobs until its pipe closes; never returns."""
    from orchestrator.supervisor import _exit_at_once_on_exit
    from orchestrator.unpacked_fmus import remove_unpacked, unpacked_files

    code = 0
    inherited = unpacked_files()  # the parent's, left to it
    try:
        for other in others:
            other.close()
        os.setpgid(0, 0)
        faulthandler.disable()  # a crash is reported by this process's parent, in one line
        child_watch.die_with_parent(parent)
        _exit_at_once_on_exit()
        flight.use(record)
        while (message := _receive(conn)) is not None:
            k, job = message
            try:
                outcome: Any = run(job)
            except Exception as exc:  # noqa: BLE001 - the job's outcome
                outcome = exc
            try:
                conn.send((k, outcome))
            except Exception as exc:  # noqa: BLE001 - an error that does not pickle
                conn.send((k, RuntimeError(f"{type(outcome).__name__}: {exc}")))
    except BaseException:  # noqa: BLE001 - the worker ends here, whatever happened
        code = 1
    finally:
        with contextlib.suppress(Exception):
            remove_unpacked(keep=inherited)
        os._exit(code)


def _receive(conn: Any) -> Any:
    try:
        return conn.recv()
    except (EOFError, OSError):
        return None


def _end_workers(pool: list[_Worker]) -> None:
    """Close every pipe (an idle worker then ends); a worker still in a job is asked to
    stop and killed after the grace period: none outlives this call."""
    for w in pool:
        w.conn.close()
        if w.job is not None:
            w.watch.ask_to_stop(signal.SIGTERM)
    for w in pool:
        w.watch.wait()


def _ended_job(job: Job, worker: _Worker, status: int) -> JobResult:
    """The result of a job whose worker died, stopped or hung: what its flight record
    says, its summary written, the series it recorded read back."""
    wall = time.perf_counter() - worker.started
    ending = worker.watch.ending(status)
    summary = child_watch.ended_summary(worker.record, ending, wall)
    if summary is None:  # before the run began (loading the scene)
        ended, message, _ = child_watch.outcome(worker.record, ending)
        message = f"the job's process ended before its run began: {message}"
        notes: list[str] = []
    else:
        child_watch.write_ended_summary(summary)
        ended, message, notes = summary["status"], summary["message"], summary["notes"]
    header, data, events = recorded(Path(job.output_dir))
    headline = summary.get("headline", {}) if summary else {}  # a run that had ended
    stats = summary.get("stats", {}) if summary and headline else {"wall_time": wall}
    return JobResult(job, ended, message, headline, stats, header, data, events, notes)


def recorded(out: Path) -> tuple[list[str], np.ndarray, list[tuple[float, str, str, str]]]:
    """(header, rows, events) a run wrote into ``out`` before its process ended."""
    header: list[str] = []
    data = np.empty((0, 0))
    events: list[tuple[float, str, str, str]] = []
    with contextlib.suppress(OSError, ValueError):
        with open(out / "timeseries.csv") as f:
            header = f.readline().strip().split(",")
            rows = [line.split(",") for line in f if line.count(",") == len(header) - 1]
        data = np.array(rows, dtype=float).reshape(len(rows), len(header))
    with contextlib.suppress(OSError, ValueError), open(out / "events.csv", newline="") as f:
        for row in list(csv.reader(f))[1:]:
            if len(row) == 4:
                events.append((float(row[0]), row[1], row[2], row[3]))
    return header, data, events


def call_supervised(fn: Callable[[], Any]) -> Any:
    """``fn()`` in a supervised worker process: its value, or its exception raised here; a
    RunError saying how it ended if its process crashed, stopped or hung in an FMI call."""
    from orchestrator.errors import RunError

    worker = _start_worker([], lambda _job: fn())
    _hand_out(worker, 0, [None])  # type: ignore[list-item]  # fn takes no job
    try:
        while True:
            if worker.conn.poll(2 * child_watch.POLL):
                try:
                    _, outcome = worker.conn.recv()
                except (EOFError, OSError):
                    pass  # it died: below
                else:
                    worker.job = None
                    if isinstance(outcome, BaseException):
                        raise outcome
                    return outcome
            status = worker.watch.poll()
            if status is not None:
                worker.job = None
                _, message, _ = child_watch.outcome(worker.record, worker.watch.ending(status))
                raise RunError(message)
    finally:
        _end_workers([worker])
