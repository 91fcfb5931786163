"""The execution loop every master shares: the fixed-step masters record exactly what a
hand-written Jacobi / Gauss–Seidel loop records, and ``output.every`` thins the record of
every master without changing what it computes."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from orchestrator.lazy import resolve
from orchestrator.master_settings import FixedStepSettings
from orchestrator.masters.macro_step import MacroStep
from orchestrator.masters.registry import ALGORITHMS, Algorithm, tolerance_masters
from orchestrator.recorder import StepStats
from orchestrator.run import fmu_files, run_scene
from orchestrator.scenario import load_scene
from orchestrator.system import CoupledSystem

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
STOP_AT_ONE_RADIAN = {"signal": "a.phi", "above": "1 rad"}


def _run(tmp_path, fmu_cache, scene, name):
    return run_scene(
        scene,
        output_dir=tmp_path / name,
        cache_dir=fmu_cache,
        show_progress=False,
        plots=False,
        compare_reference=False,
    )


def _by_hand(scene, fmu_cache, sequential: bool):
    """The record of a fixed-step run written out as one loop (as each master ran its own
    before the loop was shared): rows every ``output.every`` steps, the regime changes
    logged at the step end, the step that meets ``stop_when`` the last."""
    system = CoupledSystem(scene, fmu_files(scene, fmu_cache))
    try:
        system.initialize()
        h, start, stop = scene.master.step, scene.start, scene.stop
        n = math.ceil((stop - start) / h - 1e-9)
        m = len(system.instances)
        rows, events = [system.record_row(start)], []
        names = [model.regime_names for model in system.models]
        last = system.regimes()
        t = start
        for k in range(n):
            hk = h if k < n - 1 else stop - t
            for i in range(m):
                system.feed(i)
                system.step(i, t, hk)
                if sequential:
                    system.read(i)
            if not sequential:
                system.read_all()
            t = start + (k + 1) * h if k < n - 1 else stop
            now = system.regimes()
            for i, (a, b) in enumerate(zip(last, now, strict=True)):
                if a != b:
                    events.append(
                        (t, system.names[i], names[i].get(a, str(a)), names[i].get(b, str(b)))
                    )
            last = now
            g = system.stop_indicator()
            done = g is not None and g <= 0.0
            if (k + 1) % scene.record_every == 0 or k == n - 1 or done:
                rows.append(system.record_row(t))
            if done:
                break
        return rows, events, k + 1
    finally:
        system.close()


@pytest.mark.parametrize(
    ("algorithm", "file", "overrides"),
    [
        ("jacobi", "two_inertias.toml", {}),
        ("gauss-seidel", "two_inertias.toml", {}),
        ("jacobi", "two_inertias.toml", {"output.every": 7, "scene.stop_when": STOP_AT_ONE_RADIAN}),
        ("gauss-seidel", "press_feed_run1.toml", {"scene.stop": "0.3 s", "output.every": 3}),
        ("jacobi", "press_feed_run1.toml", {"scene.stop": "0.3 s"}),
    ],
)
def test_fixed_step_masters_record_what_one_hand_written_loop_records(
    tmp_path, fmu_cache, algorithm, file, overrides
) -> None:
    scene = load_scene(SCENARIOS / file, {"master.algorithm": algorithm, **overrides})
    rows, events, steps = _by_hand(scene, fmu_cache, sequential=algorithm == "gauss-seidel")
    result = _run(tmp_path, fmu_cache, scene, "run")
    assert result.status == "completed"
    assert result.stats.steps == steps and result.stats.do_steps == steps * len(scene.fmus)
    assert result.data.tolist() == rows  # bit for bit
    assert [(t, s, a, b) for t, s, a, b in result.events] == events
    if "scene.stop_when" in overrides:
        assert result.stats.stopped_by_condition


class _Spy:
    """Wraps a master factory: keeps every MacroStep the masters of a run return."""

    def __init__(self, factory) -> None:
        self.factory, self.steps = factory, []

    def __call__(self, settings, system):
        master = self.factory(settings, system)
        step = master.step

        def spied(t, stop):
            taken = step(t, stop)
            self.steps.append(taken)
            return taken

        master.step = spied
        return master


def _scene_for(algorithm: str, every: int, hold: str | None = None):
    overrides = {"master.algorithm": algorithm, "output.every": every}
    if hold is not None:
        overrides["master.input_hold"] = hold
    if algorithm not in tolerance_masters():
        return load_scene(SCENARIOS / "two_inertias.toml", overrides | {"scene.stop": "0.1 s"})
    # The M739's first 4 ms: a dozen escapement switches, each recorded on both sides.
    overrides |= {"scene.stop": "4 ms", "master.tolerance": 1e-2}
    return load_scene(SCENARIOS / "m739.toml", overrides)


#: Every master, the regime-aware one with each of its schemes.
MASTERS_AND_SCHEMES = [
    *((a, None) for a in ALGORITHMS if a not in tolerance_masters()),
    *((a, hold) for a in tolerance_masters() for hold in ("midpoint", "extrapolated")),
]


@pytest.mark.parametrize(("algorithm", "hold"), MASTERS_AND_SCHEMES)
def test_output_every_thins_the_record_of_every_master(
    tmp_path, fmu_cache, monkeypatch, algorithm, hold
) -> None:
    """Every 7th macro step and the last are recorded (a step onto a switch with its values
    just before it, where the master has them); the run itself, its statistics, its events
    and its energy residual are those of the full record, and each recorded row is the full
    record's row, bit for bit."""
    entry = ALGORITHMS[algorithm]
    spy = _Spy(resolve(entry.factory))
    monkeypatch.setitem(ALGORITHMS, algorithm, Algorithm(entry.settings, spy))
    full = _run(tmp_path, fmu_cache, _scene_for(algorithm, 1, hold), "full")
    steps, spy.steps = spy.steps, []
    thinned = _run(tmp_path, fmu_cache, _scene_for(algorithm, 7, hold), "thinned")
    assert full.status == thinned.status == "completed"
    assert [(s.end, s.h) for s in spy.steps] == [(s.end, s.h) for s in steps]
    assert len(steps) == full.stats.steps > 20
    if algorithm in tolerance_masters():
        assert sum(s.switched for s in steps) >= 10
    if hold == "midpoint":  # the single pass lands past the switch: no row before it
        assert any(s.left_row is not None for s in steps[6::7])  # a switch among those kept
    for key in ("steps", "do_steps", "rejections", "rollbacks", "iterations", "events"):
        assert getattr(thinned.stats, key) == getattr(full.stats, key), key
    assert thinned.events == full.events
    # The energy balance is kept over every step, not over the recorded ones.
    assert thinned.headline["energy_residual"] == full.headline["energy_residual"]
    expected = [thinned.scene.start]
    for k, s in enumerate(steps, start=1):
        if k % 7 == 0 or k == len(steps):
            expected += ([s.left_row[0]] if s.left_row is not None else []) + [s.end]
    assert thinned.signal("time").tolist() == expected
    rows = {tuple(row) for row in full.data.tolist()}
    assert all(tuple(row) in rows for row in thinned.data.tolist())
    assert thinned.data[-1].tolist() == full.data[-1].tolist()
    assert len(full.data) == 1 + len(steps) + sum(s.left_row is not None for s in steps)


class _HalfStepJacobi:
    """A master as docs/architecture.md's "Adding a master" describes one: Jacobi steps of half
    ``master.step``, with nothing but the stepping."""

    name = "half-jacobi"

    def __init__(self, settings: FixedStepSettings, system) -> None:
        self.settings, self.system, self.stats = settings, system, StepStats()
        self.h = 0.5 * settings.step

    def setup(self) -> None:
        pass

    def start(self, t: float, stop: float) -> None:
        pass

    def step(self, t: float, stop: float) -> MacroStep:
        h = stop - t if stop - t < 1.5 * self.h else self.h  # no sliver of a last step
        for i in range(len(self.system.instances)):
            self.system.feed(i)
            self.system.step(i, t, h)
        self.system.read_all()
        self.stats.do_steps += len(self.system.instances)
        return MacroStep(t + h, h)


def test_a_new_master_is_its_stepping_and_its_settings(tmp_path, fmu_cache, monkeypatch) -> None:
    """Registered with its settings, a master that only steps gets the rest from the loop:
    the stop time, the stop condition, the thinned record, the regime log and the counts."""
    # One registry line (in orchestrator/masters/registry.py, a "module:function" factory).
    monkeypatch.setitem(ALGORITHMS, "half-jacobi", Algorithm(FixedStepSettings, _HalfStepJacobi))
    overrides = {"scene.stop": "0.1 s", "output.every": 4}
    half = _run(
        tmp_path,
        fmu_cache,
        load_scene(
            SCENARIOS / "two_inertias.toml", overrides | {"master.algorithm": "half-jacobi"}
        ),
        "half",
    )
    jacobi = _run(
        tmp_path,
        fmu_cache,
        load_scene(
            SCENARIOS / "two_inertias.toml",
            overrides | {"master.algorithm": "jacobi", "master.step": "0.05 ms", "output.every": 2},
        ),
        "jacobi",
    )
    assert half.status == "completed" and half.stats.steps == 2000
    # The summary records the settings that ran.
    assert half.metadata["master_ran"] == {
        "algorithm": "half-jacobi",
        "step": 1e-4,
        "call_timeout": 60.0,
    }
    assert half.stats.do_steps == 2 * half.stats.steps
    assert len(half.data) == 1 + 2000 // 4 and half.signal("time")[-1] == pytest.approx(0.1)
    # Every 4th half step is every 2nd step of 0.05 ms: the same motion, but for rounding
    # (the grid there, the sum of the steps here).
    assert half.data[::2] == pytest.approx(jacobi.data[::4], rel=1e-9, abs=1e-12)
    stopped = _run(
        tmp_path,
        fmu_cache,
        load_scene(
            SCENARIOS / "two_inertias.toml",
            {"master.algorithm": "half-jacobi", "scene.stop_when": STOP_AT_ONE_RADIAN},
        ),
        "stopped",
    )
    assert stopped.stats.stopped_by_condition
    assert 1.0 < stopped.signal("a.phi")[-1] < 1.0 + 10.0 * 0.5e-4
