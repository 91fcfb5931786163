"""How long a user waits for ``mechcosim run scenarios/m739.toml``: the whole command as a
process, against the co-simulation inside it (the phase ``--debug`` prints).

The command runs once untimed (FMUs built, reference and plot kept in the FMU cache, as
after a user's first run of the scene), then ``ROUNDS`` times as written and as many times
with ``--no-plot --no-reference``, in turn.  Medians of the wall times; the ratio of each
process to its own co-simulation; and the median of each phase of the runs as written.
"""

from __future__ import annotations

import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from orchestrator.studies.timing import print_targets

PROJECT = Path(__file__).resolve().parents[2]
SCENE = "scenarios/m739.toml"
ROUNDS = 5
_PHASE = re.compile(r"^  (.+?)\s{2,}([0-9.]+) s$")


def _command(out: Path, *options: str) -> tuple[float, dict[str, float]]:
    """Wall time [s] of one ``mechcosim --debug run`` and the phases it printed."""
    command = [sys.executable, "-m", "orchestrator", "--debug", "run", SCENE]
    command += ["--output", str(out), "--no-progress", *options]
    start = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True, cwd=PROJECT)
    wall = time.perf_counter() - start
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(command)} failed: {done.stderr.strip()[-400:]}")
    phases = {}
    for line in done.stderr.splitlines():
        found = _PHASE.match(line)
        if found:
            phases[found.group(1)] = float(found.group(2))
    return wall, phases


def answer_rows() -> list[tuple[str, float, str]]:
    """The time-to-answer targets, measured here."""
    runs: dict[str, list[tuple[float, dict[str, float]]]] = {"as written": [], "bare": []}
    with tempfile.TemporaryDirectory(prefix="mechcosim_answer_") as tmp:
        _command(Path(tmp) / "warm")
        for k in range(ROUNDS):
            runs["as written"].append(_command(Path(tmp) / f"a{k}"))
            runs["bare"].append(_command(Path(tmp) / f"b{k}", "--no-plot", "--no-reference"))
    rows = []
    for label, options in (("as written", ""), ("bare", " --no-plot --no-reference")):
        wall = statistics.median(w for w, _ in runs[label])
        cosim = statistics.median(p["co-simulation (initialize, step)"] for _, p in runs[label])
        print(f"mechcosim run {SCENE}{options}: {wall:.2f} s as a process, "
              f"co-simulation {cosim:.2f} s (medians of {ROUNDS})")  # fmt: skip
        rows.append((f"run {SCENE}{options}: process [s]", wall, "<= 1.2" if not options else ""))
        rows.append((f"run {SCENE}{options}: process / its co-simulation", wall / cosim,
                     "<= 2.5" if not options else ""))  # fmt: skip
    names = list(runs["as written"][0][1])
    print("phases of the runs as written (medians):")
    for name in names:
        seconds = statistics.median(p.get(name, 0.0) for _, p in runs["as written"])
        print(f"  {name:<44s} {seconds:6.3f} s")
    return rows


def print_answer_time() -> None:
    print_targets(answer_rows())
