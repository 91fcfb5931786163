"""Run a scene's exported system in another tool at a fixed step and compare it with our
Jacobi master: proof that the FMUs and the export are standard.

The tools see only what ``mechcosim export`` writes:

* ``libcosim`` (libcosimpy) loads the SSP archive (unpacked; the OSP annotation gives its
  fixed-step algorithm and step) or the OSP-IS ``OspSystemStructure.xml`` and steps its
  fixed-step algorithm (every FMU steps, then values are transferred: Jacobi).
* ``fmpy`` reads the SSP archive with FMPy's SSD reader (which checks it against the SSP
  schema) and steps FMPy's ``FMU2Slave`` instances in a fixed-step Jacobi loop of its own:
  bound values set in initialization mode, the initial exchange settled once per instance,
  then inputs held over each step.  (FMPy's ``simulate_ssp`` cannot stand in: it starts
  every connection at 0.0 and writes 0.0 over input values bound in the SSD.)

Agreement, per recorded signal, is ``max_k |ours_k - theirs_k| / max_k max(|ours_k|,
|theirs_k|)`` over the common communication points k = 1..n (0 when both are zero
throughout); the agreement of a run is the largest over the signals compared.

libcosim unloads FMU binaries when it is done, which pythonfmu's runtime does not survive
within one process, so each tool runs in a child process (``tool_runs``) and only numbers
come back.
"""

from __future__ import annotations

import importlib.util
import math
import multiprocessing as mp
import tempfile
import time
import zipfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from orchestrator.errors import RunError, ScenarioError
from orchestrator.interrupt import signal_name
from orchestrator.osp_export import export_osp
from orchestrator.run import RunResult, fmu_files, run_scene
from orchestrator.scenario import load_scene
from orchestrator.scene_model import Scene
from orchestrator.signals import libcosim_scenario, scene_signals
from orchestrator.ssp_export import export_ssp
from orchestrator.ssp_import import load_ssp
from orchestrator.studies.job_workers import call_supervised
from orchestrator.studies.tool_runs import fmpy_run, fmpy_simulate_run, libcosim_run

TOOLS = ("libcosim", "fmpy")
#: the agreement ``mechcosim crosscheck`` requires
REQUIRED = 1e-9
#: crosscheck runs stop after this many macro steps unless a stop is given
DEFAULT_MAX_STEPS = 5_000


class ToolCannotRun(RunError):
    """The tool cannot run this scene's system; the message says why, in one line."""


@dataclass
class ToolRun:
    tool: str
    via: str  # what the tool read: "SSP archive" or "OSP-IS file"
    header: list[str]  # "time", then "<instance>.<variable>"
    data: np.ndarray  # one row per communication point k = 1..n
    wall_time: float
    not_compared: dict[str, str] = field(default_factory=dict)  # signal -> why


@dataclass
class Agreement:
    per_signal: dict[str, float]  # relative agreement of each signal compared
    points: int  # communication points compared

    @property
    def worst(self) -> tuple[str, float]:
        name = max(self.per_signal, key=self.per_signal.__getitem__)
        return name, self.per_signal[name]


def grid_steps(scene: Scene, until: float) -> int:
    """Whole macro steps of the scene's master from its start to ``until``."""
    return int(math.floor((until - scene.start) / scene.master.step + 1e-9))


def cannot_run(scene: Scene, tool: str, via: str = "ssp") -> str | None:
    """Why ``tool`` cannot run ``scene``'s exported system (None: it can)."""
    why = _cannot_take_signals(scene, tool, via)
    if why is not None:
        return why
    if tool == "libcosim":
        if importlib.util.find_spec("libcosimpy") is None:
            return "libcosimpy is not installed (pip install libcosimpy)"
        step_ns = scene.master.step * 1e9
        if abs(step_ns - round(step_ns)) > 1e-6 or round(step_ns) < 1:  # round-off only
            return f"libcosim steps in whole nanoseconds; {scene.master.step!r} s is not one"
        for c in scene.connections:
            for instance, var in (c.source, c.target):
                if scene.fmus[instance].model.variables[var].type == "Enumeration":
                    return (
                        f"libcosim ignores FMI 2.0 Enumeration variables, so it cannot make "
                        f"the connection {c.source[0]}.{c.source[1]} -> "
                        f"{c.target[0]}.{c.target[1]}"
                    )
    for c in scene.connections:
        kind = scene.fmus[c.source[0]].model.variables[c.source[1]].type
        if kind == "String":
            return f"{tool}: String connections are not crosschecked ({c.source[0]}.{c.source[1]})"
    return None


def _cannot_take_signals(scene: Scene, tool: str, via: str) -> str | None:
    """Input signals reach libcosim as a scenario file beside the OSP-IS file, and FMPy
    through simulate_fmu's input table for a scene of one FMU."""
    signals = scene_signals(scene)
    if not signals:
        return None
    name = ".".join(next(iter(signals.driven)))
    if tool == "libcosim":
        if via != "osp":
            return f"input signal {name}: run libcosim with --via osp"
        try:
            libcosim_scenario(scene, scene.master.step)
        except ScenarioError as exc:
            return f"{exc.key}: {str(exc).split('] ', 1)[-1]}"
        return None
    if len(scene.fmus) > 1:
        return f"input signal {name}: FMPy's simulate_fmu, which takes signals, runs one FMU"
    for (instance, var), signal in signals.driven.items():
        if signal.breakpoints() != signal.jumps:
            return (
                f"input signal {instance}.{var} has a slope: FMPy records an output before "
                "it applies the input of that instant, so outputs that depend on it differ"
            )
        if signal.is_jump(scene.start):
            return (
                f"input signal {instance}.{var} jumps at the start: FMPy's simulate_fmu holds "
                "a table's first value over the first step"
            )
    return None


def _simulate_job(scene: Scene, cache_dir: Path | None) -> dict[str, Any]:
    """simulate_fmu's arguments for a scene of one FMU driven by held signals."""
    ((instance, spec),) = scene.fmus.items()
    driven = scene_signals(scene).driven
    names = [var for (_, var) in driven]
    times = sorted({scene.start, scene.stop, *(t for s in driven.values() for t in s.jumps)})
    table = []
    for t in times:
        left = [s.value(t, left=True) for s in driven.values()]
        right = [s.value(t) for s in driven.values()]
        table += [[t, *left], [t, *right]] if left != right else [[t, *right]]
    # Constant Real inputs go in the table too: FMPy warns of an input missing from it.
    constants = {
        k: v
        for k, v in spec.inputs.items()
        if k not in names and spec.model.variables[k].type == "Real"
    }
    names += list(constants)
    table = [row + list(constants.values()) for row in table]
    others = {k: v for k, v in spec.inputs.items() if k not in names}
    return {
        "fmu": str(fmu_files(scene, cache_dir)[instance]),
        "inputs": (names, table),
        "start_values": {**spec.parameters, **others},
    }


def run_tool(
    scene: Scene,
    tool: str,
    steps: int,
    workdir: Path,
    via: str = "ssp",
    cache_dir: Path | None = None,
) -> ToolRun:
    """Export ``scene`` into ``workdir`` and run ``steps`` fixed macro steps of it in ``tool``
    (libcosim from the SSP archive or, with ``via="osp"``, the OSP-IS file)."""
    why = cannot_run(scene, tool, via)
    if why is not None:
        raise ToolCannotRun(why)
    if tool == "fmpy":
        via = "ssp"  # FMPy reads SSP archives, not OSP-IS files
    workdir = Path(workdir)
    record = [list(signal) for signal in scene.record]
    types = {f"{i}.{v}": scene.fmus[i].model.variables[v].type for i, v in scene.record}
    if via == "osp":
        source = export_osp(scene, workdir / "osp", cache_dir)
        what = "OSP-IS file"
    elif tool == "fmpy" and scene_signals(scene):
        source, what = workdir, ""  # simulate_fmu runs the FMU file itself
    else:
        archive = export_ssp(scene, workdir / f"{scene.name}.ssp", cache_dir)
        what = "SSP archive"
        source = archive
        if tool == "libcosim":  # libcosim reads an unpacked archive
            source = workdir / "ssp"
            with zipfile.ZipFile(archive) as z:
                z.extractall(source)
    not_compared: dict[str, str] = {}
    if tool == "libcosim":
        for name, kind in types.items():
            if kind == "Enumeration":
                not_compared[name] = "libcosim ignores FMI 2.0 Enumeration variables"
    child = libcosim_run if tool == "libcosim" else fmpy_run
    if tool == "fmpy" and scene_signals(scene):
        child, what = fmpy_simulate_run, "simulate_fmu with the input signals"
    job = {
        "source": str(source),
        "record": [r for r in record if f"{r[0]}.{r[1]}" not in not_compared],
        "steps": steps,
        "start": scene.start,
        "step": scene.master.step,
        "stop": scene.stop,
        **(_simulate_job(scene, cache_dir) if child is fmpy_simulate_run else {}),
    }
    started = time.perf_counter()
    header, rows = _in_spawned_process(child, job, tool)
    wall = time.perf_counter() - started
    data = np.array(rows, dtype=float).reshape(len(rows), len(header))
    return ToolRun(tool, what, header, data, wall, not_compared)


def _in_spawned_process(child: Any, job: dict[str, Any], tool: str) -> Any:
    """``child(job)`` in a fresh process (the tool's libraries loaded there only); its
    exception raised here; ToolCrashed if that process dies without an answer."""
    context = mp.get_context("spawn")
    mine, theirs = context.Pipe(duplex=False)
    process = context.Process(target=_answer, args=(child, job, theirs), daemon=True)
    process.start()
    theirs.close()
    try:
        while not mine.poll(0.1) and process.is_alive():
            pass
        try:
            ok, value = mine.recv()
        except EOFError:  # it died without an answer
            process.join()
            code = process.exitcode or 0
            cause = (
                f"killed by {signal_name(-code)} (signal {-code})"
                if code < 0
                else f"exit code {code}"
            )
            raise ToolCrashed(f"{tool}'s process ended without an answer: {cause}") from None
    finally:
        mine.close()
        if process.is_alive():
            process.kill()
        process.join()
    if not ok:
        raise value
    return value


def _answer(child: Any, job: dict[str, Any], conn: Any) -> None:
    try:
        conn.send((True, child(job)))
    except Exception as exc:  # noqa: BLE001 - raised again in the parent
        conn.send((False, exc))


class ToolCrashed(RunError):
    """The tool's process died (a crash in an FMU or in the tool) before it answered."""


@dataclass
class _Series:
    """Our run's recorded series (what ``agreement`` reads of it)."""

    header: list[str]
    data: np.ndarray

    def signal(self, name: str) -> np.ndarray:
        return self.data[:, self.header.index(name)]


def _our_series(scene: Scene, out: Path, cache_dir: Path | None) -> _Series:
    ours = run_scene(
        scene, output_dir=out, cache_dir=cache_dir, show_progress=False, compare_reference=False
    )
    if ours.status != "completed":
        raise RunError(f"our Jacobi run did not complete: {ours.message}")
    return _Series(ours.header, ours.data)


def agreement(ours: RunResult | _Series, theirs: ToolRun, scene: Scene) -> Agreement:
    """Compare at the communication points both have (our recorded rows on the grid)."""
    times = ours.signal("time")
    k = np.rint((times - scene.start) / scene.master.step).astype(int)
    on_grid = (k >= 1) & (k <= len(theirs.data))
    on_grid &= np.abs(times - (scene.start + k * scene.master.step)) <= 1e-9 * scene.master.step
    rows = np.flatnonzero(on_grid)
    rows = rows[np.isfinite(theirs.data[k[rows] - 1, 0])]  # NaN time: a row it did not record
    per_signal: dict[str, float] = {}
    for j, name in enumerate(theirs.header[1:], start=1):
        a = ours.data[rows, ours.header.index(name)]
        b = theirs.data[k[rows] - 1, j]
        scale = max(float(np.max(np.abs(a), initial=0.0)), float(np.max(np.abs(b), initial=0.0)))
        diff = float(np.max(np.abs(a - b), initial=0.0))
        if not (math.isfinite(diff) and math.isfinite(scale)):
            per_signal[name] = math.inf
        else:
            per_signal[name] = diff / scale if scale > 0 else 0.0
    return Agreement(per_signal, len(rows))


@dataclass
class Outcome:
    tool: str
    run: ToolRun | None = None
    agreement: Agreement | None = None
    cannot_run: str | None = None  # why the tool cannot run the scene

    @property
    def ok(self) -> bool:
        return self.agreement is not None and self.agreement.worst[1] <= REQUIRED


@dataclass
class Crosscheck:
    scene: Scene  # as run: fixed-step Jacobi, stop on the last whole step compared
    steps: int
    ours_wall_time: float
    outcomes: list[Outcome]

    @property
    def ok(self) -> bool:
        return all(o.ok for o in self.outcomes)


def crosscheck(
    path: Path,
    overrides: dict[str, Any] | None = None,
    stop: str | float | None = None,
    tools: tuple[str, ...] = TOOLS,
    via: str = "ssp",
    cache_dir: Path | None = None,
) -> Crosscheck:
    """Run the scene at ``path`` (an .ssp archive or a TOML scene) under our fixed-step
    Jacobi master and in each of ``tools``, over whole macro steps up to ``stop`` (default:
    the scene's stop, at most DEFAULT_MAX_STEPS steps), and compare."""
    overrides = dict(overrides or {})
    if stop is not None:
        overrides["scene.stop"] = stop
    scene = load_any(path, overrides, cache_dir)
    steps = grid_steps(scene, scene.stop)
    if stop is None:
        steps = min(steps, DEFAULT_MAX_STEPS)
    if steps < 1:
        raise RunError(f"nothing to compare: less than one step of {scene.master.step!r} s")
    overrides |= {
        "master.algorithm": "jacobi",
        "scene.stop": scene.start + steps * scene.master.step,
    }
    scene = load_any(path, overrides, cache_dir)
    steps = grid_steps(scene, scene.stop)
    outcomes = [Outcome(tool, cannot_run=cannot_run(scene, tool, via)) for tool in tools]
    wall = math.nan
    with tempfile.TemporaryDirectory(prefix="mechcosim-crosscheck-") as scratch:
        if any(o.cannot_run is None for o in outcomes):
            started = time.perf_counter()
            out = Path(scratch) / "ours"
            try:  # supervised: an FMU that crashes or hangs ends that run only
                ours = call_supervised(lambda: _our_series(scene, out, cache_dir))
            except RunError as exc:
                raise RunError(f"our Jacobi run did not complete: {exc}") from None
            wall = time.perf_counter() - started
        for o in outcomes:
            if o.cannot_run is None:
                try:
                    o.run = run_tool(scene, o.tool, steps, Path(scratch) / o.tool, via, cache_dir)
                except ToolCrashed as exc:
                    o.cannot_run = str(exc)
                    continue
                o.agreement = agreement(ours, o.run, scene)
    return Crosscheck(scene, steps, wall, outcomes)


def load_any(path: Path, overrides: dict[str, Any], cache_dir: Path | None = None) -> Scene:
    if Path(path).suffix == ".ssp":
        return load_ssp(path, overrides, cache_dir)
    return load_scene(path, overrides, cache_dir)
