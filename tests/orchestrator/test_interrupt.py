"""SIGINT/SIGTERM at any moment of ``mechcosim run``: the run stops at a step boundary,
writes summary.json with status "interrupted" and the simulated time reached, keeps its
CSV files readable and exits 130 / 143, never crashing in an FMU."""

from __future__ import annotations

import csv
import json
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from orchestrator import entry
from orchestrator.interrupt import Interrupted, SignalGuard, catching_signals
from orchestrator.output_lock import LOCK_NAME

PROJECT_DIR = Path(__file__).resolve().parents[2]
M739 = PROJECT_DIR / "scenarios" / "m739.toml"


def _catches_sigterm(pid: int) -> bool | None:
    """Whether process ``pid`` has a handler for SIGTERM (None where /proc cannot say)."""
    try:
        status = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return None
    for line in status.splitlines():
        if line.startswith("SigCgt:"):
            return bool(int(line.split()[1], 16) >> (signal.SIGTERM - 1) & 1)
    return None


def _wait_for_handlers(proc: subprocess.Popen, timeout: float = 60.0) -> None:
    """Wait until the command has taken over SIGINT and SIGTERM (its first line does).
    Before that the interpreter is still starting (about 0.05 s on an idle machine,
    several times that on a loaded one) and no Python program can answer a signal yet."""
    end = time.perf_counter() + timeout
    while time.perf_counter() < end and proc.poll() is None:
        caught = _catches_sigterm(proc.pid)
        if caught is None or caught:
            return
        time.sleep(0.005)


def interrupt_run(out: Path, delay: float, sig: int) -> tuple[int, str]:
    """Start ``mechcosim run scenarios/m739.toml``, send ``sig`` ``delay`` seconds after
    it has taken over the signals; (exit code, stderr).  A command that does not exit
    within 120 s of the signal fails the test (a hang, not a slow machine)."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "orchestrator", "run", str(M739), "--no-progress"]
        + ["--output", str(out)],
        cwd=PROJECT_DIR,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    _wait_for_handlers(proc)
    time.sleep(delay)
    proc.send_signal(sig)
    try:
        _, err = proc.communicate(timeout=120)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.communicate()
        raise AssertionError(f"no exit within 120 s of {signal.Signals(sig).name}") from None
    return proc.returncode, err


def assert_interrupted(
    out: Path, code: int, err: str, sig: int, delay: float, started: bool = True
) -> float | None:
    """Check an interrupted run; its simulated time reached.  With ``started`` false the
    signal may also have come before the run began (its modules still loading): then the
    command ends with one line and leaves no results (None)."""
    what = f"{signal.Signals(sig).name} after {delay:.2f} s"
    assert code == 128 + sig, f"{what}: exit {code}; stderr: {err[-2000:]}"
    assert "Traceback" not in err, f"{what}: {err[-2000:]}"
    if not started and not (out / "summary.json").exists():
        assert err.strip().splitlines()[-1] == f"interrupted by {signal.Signals(sig).name}", err
        assert not out.exists() or not any(out.iterdir()), what
        return None
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "interrupted", what
    assert signal.Signals(sig).name in summary["message"], summary["message"]
    reached = summary["time_reached"]
    assert 0.0 <= reached <= 0.2, what
    with open(out / "timeseries.csv", newline="") as f:
        rows = list(csv.reader(f))
    assert rows and rows[0][0] == "time", what
    data = np.array(rows[1:], dtype=float).reshape(-1, len(rows[0]))
    if len(data):  # every row whole and in time order, the last at the time reached
        assert np.all(np.diff(data[:, 0]) >= 0.0), what
        assert data[-1, 0] == pytest.approx(reached, abs=1e-12), what
    with open(out / "events.csv", newline="") as f:
        assert next(csv.reader(f)) == ["time", "subsystem", "from", "to"], what
    assert not (out / LOCK_NAME).exists(), what
    return reached


def test_guard_turns_a_signal_into_a_flag_checked_between_steps() -> None:
    with catching_signals() as guard:
        os.kill(os.getpid(), signal.SIGTERM)  # delivered at once to this (main) thread
        assert guard.signum == signal.SIGTERM
        with pytest.raises(Interrupted) as info:
            guard.check()
    assert info.value.exit_code == 143
    assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL  # restored


def test_command_sigterm_raises_in_the_command_and_ends_a_forked_worker_quietly() -> None:
    previous = signal.signal(signal.SIGTERM, entry._raise_interrupted)
    try:
        with pytest.raises(Interrupted) as info:
            os.kill(os.getpid(), signal.SIGTERM)
        assert info.value.exit_code == 143
        pid = os.fork()
        if pid == 0:  # a pool worker forked from the command
            try:
                os.kill(os.getpid(), signal.SIGTERM)
            finally:
                os._exit(3)  # reached only if SIGTERM did not end the worker
        _, status = os.waitpid(pid, 0)
        assert os.WIFSIGNALED(status) and os.WTERMSIG(status) == signal.SIGTERM, status
    finally:
        signal.signal(signal.SIGTERM, previous)


def test_guard_raises_at_once_only_when_asked() -> None:
    guard = SignalGuard()
    guard.handle(signal.SIGINT, None)  # flag only
    guard = SignalGuard()
    with pytest.raises(Interrupted), guard.raise_at_once():
        guard.handle(signal.SIGINT, None)


@pytest.mark.parametrize(
    "sig", [signal.SIGINT, pytest.param(signal.SIGTERM, marks=pytest.mark.slow)]
)
def test_run_interrupted_at_a_random_moment(tmp_path: Path, sig: int) -> None:
    # Within the run's first 2.5 s (the whole command takes about 4 s on the 2-core
    # machine); a signal after the run has completed leaves it completed, with exit 0.
    delay = random.uniform(0.0, 2.5)
    out = tmp_path / "out"
    code, err = interrupt_run(out, delay, sig)
    if code == 0:
        assert "Traceback" not in err, err[-2000:]
        assert json.loads((out / "summary.json").read_text())["status"] == "completed"
    else:
        assert_interrupted(out, code, err, sig, delay, started=False)


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_run_interrupted_while_its_modules_load(tmp_path: Path, sig: int) -> None:
    """A signal in the first 0.15 s, while the command imports its modules: one line and
    exit 130 / 143, never a traceback, never swallowed (the run going on to the end)."""
    for k, delay in enumerate((0.0, 0.02, 0.05, 0.1, 0.15)):
        out = tmp_path / f"run{k}"
        code, err = interrupt_run(out, delay, sig)
        assert_interrupted(out, code, err, sig, delay, started=False)


@pytest.mark.slow
def test_run_interrupted_twenty_times(tmp_path: Path) -> None:
    """20 interrupts at random moments of a run of about 7 s (loading, initialization, the
    run, the reference and analyses, the end), alternately SIGINT and SIGTERM.  A signal
    after the run has completed leaves it completed, with exit 0."""
    seed = random.randrange(1 << 30)
    rng = random.Random(seed)
    reached = []
    for k in range(20):
        sig = signal.SIGINT if k % 2 == 0 else signal.SIGTERM
        delay = rng.uniform(0.0, 9.0)
        out = tmp_path / f"run{k}"
        code, err = interrupt_run(out, delay, sig)
        if code == 0:  # the run had ended when the signal came
            assert "Traceback" not in err, err[-2000:]
            assert json.loads((out / "summary.json").read_text())["status"] == "completed"
            reached.append(None)
        else:
            reached.append(assert_interrupted(out, code, err, sig, delay, started=False))
    print(f"seed {seed}: simulated times reached {reached}")
