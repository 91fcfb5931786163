"""Detached lever escapement scenes (Monday 1965): amplitude decay, steady amplitude and rate.

A scene holds one ``DetachedLever`` FMU (instance name from ``[report.options] lever``, else the
only DetachedLever of the scene).  Its drive torque is the input's start value, held for the
whole run: the train is not a separate body in this model (Monday 1965, Ch. III, pp. 8-11).

Per-cycle amplitudes are read from the recorded outputs, so any macro step well below half a
balance period works (every switch is located exactly inside the FMU's step):

* phase-scheduled mode (0, the thesis model): ``cycle_end_angle`` at each increment of
  ``cycle_count``, i.e. theta at psi = 2 pi of each cycle, the thesis's "amplitude";
* angle-switched mode (1, the physical model): ``amplitude`` at each positive extreme
  (an increment of ``beat_count`` with theta > 0).

The reference is the same physics from the component module's pure functions: the affine
cycle map derived from Monday's Table III program (mode 0), or the closed-form segments run
extreme to extreme without macro steps, with the steady amplitude and period from the fixed point
of the cycle map
(``steady_state``, mode 1).

Rate is in seconds per day, positive when the balance runs fast: 86400 (T_nominal / T - 1),
against ``[report.options] nominal_period`` (a quantity such as "0.4 s") when given, else
against the damped free period 2 pi / omega1 of the balance and hairspring alone.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from components.detached_lever import (
    ANGLE_SWITCHED,
    PHASE_SCHEDULED,
    STOPPED,
    deck_amplitudes,
    deck_cycle_map,
    steady_state,
    unit_curve,
    unit_curve_steady,
)
from components.detached_lever_data import TABLE_I
from orchestrator.errors import ScenarioError
from orchestrator.plotting import (
    event_lines,
    of,
    recorded,
    regime_bands,
    regime_colours,
    regime_names,
    regime_spans,
    run_events,
    save_figure,
    unit_label,
    window,
)
from orchestrator.scene_model import Scene
from orchestrator.scenes.detached_lever.lever import LeverScene, lever_scene
from orchestrator.scenes.detached_lever.monolithic import beat_run
from orchestrator.scenes.family import Quantity, Reference, quantity

SECONDS_PER_DAY = 86400.0
#: Cycles whose amplitude is reported by name (the worked-example deck, Monday 1965, pp. 39-45,
#: run through the Table III algorithm: cycles 1-10, 20 and 41 are checked in the tests).
NAMED_CYCLES = (1, 2, 3, 10, 20, 41)


# -- reductions of a recorded run -------------------------------------------------------------
def _columns(header: list[str], data: np.ndarray, instance: str) -> dict[str, np.ndarray]:
    prefix = f"{instance}."
    col = {"time": data[:, 0]}
    for k, name in enumerate(header):
        if name.startswith(prefix):
            col[name[len(prefix) :]] = data[:, k]
    return col


def cycle_amplitudes(
    lever: LeverScene, col: dict[str, np.ndarray]
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(cycle numbers, times [s], amplitudes [rad]) of the completed cycles, cycle 0 the start.

    Mode 0: theta at each phase-cycle end (times exact, n 2 pi / omega1 after the start).
    Mode 1: each positive extreme (times are those of the sample that first shows it).
    """
    t = col["time"]
    if lever.mode == PHASE_SCHEDULED:
        count = col["cycle_count"].astype(int)
        rows = np.nonzero(np.diff(count) > 0)[0] + 1
        n = np.concatenate(([0], count[rows]))
        amps = np.concatenate(([col["cycle_end_angle"][0]], col["cycle_end_angle"][rows]))
        return n, lever.start + n * lever.free_period, amps
    beats = col["beat_count"].astype(int)
    rows = np.nonzero(np.diff(beats) > 0)[0] + 1
    rows = rows[col["theta"][rows] > 0.0]
    n = np.arange(len(rows) + 1)
    times = np.concatenate(([t[0]], t[rows]))
    amps = np.concatenate(([abs(col["theta"][0])], col["amplitude"][rows]))
    return n, times, amps


def aitken(values: np.ndarray) -> float:
    """Limit of a sequence from its last three terms (exact for an affine map)."""
    if len(values) < 3:
        return float(values[-1])
    a, b, c = (float(v) for v in values[-3:])
    denom = (c - b) - (b - a)
    if denom == 0.0:
        return c
    return c - (c - b) ** 2 / denom


def lever_energy_residual(col: dict[str, np.ndarray]) -> float | None:
    """Largest drift of stored + dissipated - drive work, relative to the largest stored energy."""
    try:
        total = col["stored_energy"] + col["dissipated_work"] - col["drive_work"]
    except KeyError:
        return None
    scale = float(np.max(np.abs(col["stored_energy"])))
    return float(np.max(np.abs(total - total[0]))) / scale if scale > 0.0 else None


def rate(lever: LeverScene, period: float) -> float:
    """Rate [s/day], positive when the balance runs fast against the nominal period."""
    return SECONDS_PER_DAY * (lever.nominal_period / period - 1.0)


def analyse(
    scene: Scene, header: list[str], data: np.ndarray, options: dict[str, Any]
) -> dict[str, Quantity]:
    """Per-cycle and steady amplitude, period and rate, beats, overbank, energy balance."""
    lever = lever_scene(scene)
    col = _columns(header, data, lever.instance)
    needed = {"theta", "amplitude", "beat_count", "period", "regime"}
    needed |= {"cycle_count", "cycle_end_angle"} if lever.mode == PHASE_SCHEDULED else set()
    missing = sorted(needed - set(col))
    if missing:
        raise ScenarioError(
            scene.path, "output.record", f"the lever analysis needs {lever.instance}.{missing[0]}"
        )
    out: dict[str, Any] = {
        "switching_mode": quantity(lever.mode, "1"),
        "drive_torque": quantity(lever.drive_torque, "N.m"),
        "free_period": quantity(lever.free_period, "s"),
        "nominal_period": quantity(lever.nominal_period, "s"),
    }
    unit, k_cuc = lever.table_i_unit(), lever.table_i_k()
    if unit is not None:
        out["table_i_unit"] = quantity(unit, "1")
    if lever.load_step is not None:
        out["load_multiple"] = quantity(lever.load_multiple(), "1")
    if k_cuc is not None:
        # the thesis's computed unit curve at this unit and load (Table I, p. 56): what the
        # angle-switched model's friction and drive were refitted to
        out["cuc_steady_amplitude"] = quantity(
            unit_curve_steady(TABLE_I[unit].c_over_omega0, k_cuc), "rad"
        )
    n, _, amps = cycle_amplitudes(lever, col)
    out["cycles"] = quantity(n[-1], "1")
    for k in NAMED_CYCLES:
        at = np.nonzero(n == k)[0]  # absent if a macro step spanned a whole cycle
        if len(at):
            out[f"amplitude_cycle_{k}"] = quantity(amps[at[0]], "rad")
    stopped = int(col["regime"][-1]) == STOPPED
    out["stopped"] = quantity(1.0 if stopped else 0.0, "1")
    if stopped:
        moving = np.nonzero(col["regime"] != STOPPED)[0]
        out["stop_time"] = quantity(
            col["time"][moving[-1] + 1] if len(moving) else col["time"][0], "s"
        )
        out["steady_amplitude"] = quantity(0.0, "rad")  # the balance rests
    elif n[-1] >= 1:
        out["final_amplitude"] = quantity(amps[-1], "rad")
        steady = aitken(amps)
        out["steady_amplitude"] = quantity(steady, "rad")
        out["amplitude_settling"] = quantity(abs(amps[-1] - steady), "rad")
        # Mode 0 schedules its windows on the phase: the cycle lasts 2 pi / omega1 by
        # construction (Monday 1965, Fig. 2, p. 11), and the speed may reverse inside a cycle
        # (the draw can stop the balance before the impulse restarts it), so extremes do not
        # measure it.
        period = lever.free_period if lever.mode == PHASE_SCHEDULED else float(col["period"][-1])
        if period > 0.0:
            out["period"] = quantity(period, "s")
            out["rate"] = quantity(rate(lever, period), "s/day")
    out["beats"] = quantity(col["beat_count"][-1], "1")
    if lever.mode == PHASE_SCHEDULED and n[-1] >= 2:
        # speed reversals in the last complete cycle (2 for a plain oscillation)
        count = col["cycle_count"].astype(int)
        ends = np.nonzero(np.diff(count) > 0)[0] + 1
        beats = col["beat_count"]
        out["beats_last_cycle"] = quantity(beats[ends[-1]] - beats[ends[-2]], "1")
    if "overbanked" in col:
        out["overbanked"] = quantity(col["overbanked"][-1], "1")
    if "drive_work" in col:
        out["drive_work"] = quantity(col["drive_work"][-1], "J")
    if "dissipated_work" in col:
        out["dissipated_work"] = quantity(col["dissipated_work"][-1], "J")
    residual = lever_energy_residual(col)
    if residual is not None and not lever.driven_from_scene:
        # The drive torque comes from outside the scene here: its work enters the balance.
        out["energy_residual"] = quantity(residual, "1")
    return out


# -- reference --------------------------------------------------------------------------------
def _step_signal(times: np.ndarray, values: np.ndarray):
    """Piecewise-constant signal: the value of the last event at or before each time."""

    def at(query: np.ndarray) -> np.ndarray:
        k = np.searchsorted(times, query, side="right") - 1
        return values[np.clip(k, 0, len(values) - 1)]

    return at


def reference(scene: Scene) -> Reference:
    """Mode 0: the thesis's affine cycle map; mode 1: extreme-to-extreme closed-form run and
    the fixed point of the cycle map.  The drive torque must be the held input."""
    lever = lever_scene(scene)
    if lever.driven_from_scene:
        raise ScenarioError(
            scene.path,
            "report.reference",
            f"the detached_lever reference needs {lever.instance}.drive_torque held at its "
            "start value, not connected",
        )
    headline: dict[str, float] = {}
    if lever.mode == PHASE_SCHEDULED:
        w1 = lever.omega1
        n_cycles = int(math.floor((lever.stop - lever.start) * w1 / (2.0 * math.pi)))
        args = lever.map_args()
        amps = deck_amplitudes(lever.params["theta_start"], n_cycles, **args)
        ratio, offset = deck_cycle_map(**args)
        for k in NAMED_CYCLES:
            if k <= n_cycles:
                headline[f"amplitude_cycle_{k}"] = float(amps[k])
        headline["cycles"] = float(n_cycles)
        headline["steady_amplitude"] = offset / (1.0 - ratio)
        if n_cycles >= 1:
            headline["final_amplitude"] = float(amps[-1])
        ends = lever.start + np.arange(n_cycles + 1) * lever.free_period
        cycle_end = _step_signal(ends, amps)

        def signals(times: np.ndarray) -> dict[str, np.ndarray]:
            return {f"{lever.instance}.cycle_end_angle": cycle_end(np.asarray(times))}

        return Reference(headline=headline, signals=signals)
    beats = beat_run(lever)
    positive = beats.angles[1:] > 0.0
    amps = np.concatenate(([abs(beats.angles[0])], beats.angles[1:][positive]))
    for k in NAMED_CYCLES:
        if k < len(amps):
            headline[f"amplitude_cycle_{k}"] = float(amps[k])
    headline["cycles"] = float(len(amps) - 1)
    headline["beats"] = float(len(beats.times) - 1)
    if beats.stopped:
        headline["steady_amplitude"] = 0.0
    else:
        if len(amps) > 1:
            headline["final_amplitude"] = float(amps[-1])
        amp, period = steady_state(lever.component_params(), lever.drive_torque)
        if amp == amp:  # a sustained steady state below overbank exists
            headline["steady_amplitude"] = amp
            headline["period"] = period
            if rate(lever, period) != 0.0:  # a relative error needs a nonzero reference
                headline["rate"] = rate(lever, period)
    amplitude = _step_signal(beats.times, beats.amplitudes)

    def signals(times: np.ndarray) -> dict[str, np.ndarray]:
        return {f"{lever.instance}.amplitude": amplitude(np.asarray(times))}

    return Reference(headline=headline, signals=signals)


# -- plot -------------------------------------------------------------------------------------
def plot(scene: Scene, header: list[str], data: np.ndarray, path: Path) -> None:
    """theta(t) with its amplitude envelope; per-cycle amplitudes against the thesis map."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    lever = lever_scene(scene)
    col = _columns(header, data, lever.instance)
    t = col["time"]
    n, times, amps = cycle_amplitudes(lever, col)
    fig, axes = plt.subplots(3, 1, figsize=(10, 11), height_ratios=(1, 1, 0.9))
    ax = axes[0]
    ax.plot(t, col["theta"], lw=0.6, color="C0", label="balance angle")
    envelope = col["amplitude"]
    ax.step(t, envelope, where="post", color="C1", lw=1.0, label="amplitude (last extreme)")
    ax.step(t, -envelope, where="post", color="C1", lw=1.0)
    ax.plot(times, amps, "o", ms=3, color="C3", label="per-cycle amplitude")
    p = lever.params
    for sign in (1.0, -1.0):
        ax.axhline(sign * p["epsilon"], color="grey", lw=0.5, ls=":")
        ax.axhline(sign * p["alpha"], color="grey", lw=0.5, ls="--")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("theta [rad]")
    mode = "phase-scheduled (thesis)" if lever.mode == PHASE_SCHEDULED else "angle-switched"
    ax.set_title(
        f"{scene.name}: {mode}, drive {lever.drive_torque:.4g} N·m "
        f"(dotted: unlock start ±ε, dashed: lift ±α)"
    )
    ax.legend(loc="upper right", fontsize=8)
    ax = axes[1]
    ax.plot(n, amps, "o", ms=4, label="co-simulation (FMU)")
    n_map = max(int(n[-1]), int((t[-1] - t[0]) / lever.free_period), 1)
    unit, k_cuc = lever.table_i_unit(), lever.table_i_k()
    if lever.mode == ANGLE_SWITCHED and k_cuc is not None:
        # refitted Table I unit: its thesis curve is the computed unit curve at this load
        cw = TABLE_I[unit].c_over_omega0
        # the computed unit curves all use the lift 0.2786896 rad (Monday 1965, p. 37)
        thesis = unit_curve(cw, k_cuc, n_map, theta0=p["theta_start"])
        steady = unit_curve_steady(cw, k_cuc)
        label = f"thesis computed unit curve, unit {unit}, K = {k_cuc:.3f}"
    else:
        thesis = deck_amplitudes(p["theta_start"], n_map, **lever.map_args())
        ratio, offset = deck_cycle_map(**lever.map_args())
        steady = offset / (1.0 - ratio) if ratio < 1.0 else math.nan  # undamped: no limit
        label = "thesis cycle map (Table III), same deck"
    ax.plot(np.arange(n_map + 1), thesis, "-", color="C2", lw=1.0, label=label)
    if steady == steady:
        ax.axhline(steady, color="C2", ls=":", lw=0.8, label="thesis steady amplitude")
    if lever.mode == ANGLE_SWITCHED and col["regime"][-1] != STOPPED:
        steady, _ = steady_state(lever.component_params(), lever.drive_torque)
        if steady == steady:
            ax.axhline(steady, color="C0", ls="--", lw=0.8, label="steady state (angle-switched)")
    ax.set_xlabel("cycle")
    ax.set_ylabel("amplitude [rad]")
    ax.legend(loc="upper right", fontsize=8)
    _detail(axes[2], scene, lever, col, path)
    save_figure(fig, path)


def _detail(ax: Any, scene: Scene, lever: LeverScene, col: dict[str, np.ndarray], path: Path):
    """The first two free periods: the balance angle where it was recorded, over its regimes
    as named bands, the switches at their located times."""
    t = col["time"]
    end = min(float(t[-1]), float(t[0]) + 2.0 * lever.free_period)
    sel = window(t, float(t[0]), end)
    names = regime_names(scene, lever.instance)
    events = of(run_events(path), lever.instance)
    spans = regime_spans(t[sel], col["regime"][sel], names, events)
    handles = regime_bands(ax, spans, regime_colours(names), alpha=0.8)
    recorded(ax, t[sel], col["theta"][sel], color="C0")
    event_lines([ax], [e[0] for e in events if e[0] <= end], colour="0.4", style=":", width=0.7)
    ax.set_xlim(float(t[0]), end)
    ax.set_xlabel("time [s]")
    unit_label(ax, "balance angle θ", "rad")
    ax.set_title(
        "first two free periods: recorded values as dots, switches dotted (events.csv)",
        fontsize=9,
        loc="left",
    )
    ax.legend(handles=handles, title="regime", loc="upper right", fontsize=8, title_fontsize=8)
