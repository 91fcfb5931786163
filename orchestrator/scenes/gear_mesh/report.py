"""Gear-mesh efficiency scenes (Tepper 1981, ARLCD-TR-81020): analysis, plot and
closed-form reference.

A scene holds one ``GearMesh`` FMU: a gear pair driven at a set speed against a load torque.
Its headline quantities are taken over the whole mesh cycles of the run (a cycle is one base
pitch of driver rotation, starting where a new pair enters; clock meshes: one gear pitch,
starting at the handover):

* ``cycle_efficiency``: output work / input work.  At a constant load this is the ratio-weighted
  harmonic mean of the point efficiency, not the report's CYCLEFF (the arithmetic mean of K
  points, which a constant driver torque would give); ``mean_efficiency`` is the driver-angle
  mean of the point efficiency, CYCLEFF for K -> infinity.
* ``min_efficiency`` / ``max_efficiency``: extremes of the recorded point efficiency (the
  regime-aware master records both sides of every contact change, where the extremes are).
* the efficiency on both sides of the contact changes: involute ``efficiency_dual_start``,
  ``efficiency_dual_end``, ``efficiency_single_start``, ``efficiency_single_end``; clock
  ``efficiency_pair_start``, ``efficiency_pair_end``, ``efficiency_ror_end``,
  ``efficiency_rof_start``;
* ``mean_driver_torque`` (input work / driver rotation), ``whole_cycles``, and
  ``energy_residual``: max |input - output - dissipated - stored| / max input work.  The load is
  outside the scene when it is a scene input, so the generic residual (stored + dissipated -
  external) would count the output work as a loss; this one balances it.

The reference computes the same quantities in closed form from components.mesh_efficiency
(involute_cycle_summary; for the clock meshes train_mesh_cycle_summary, adaptive quadrature), the
contact-phase changes as events, and the signals at any time from the prescribed motion.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from components.base import ComponentError
from components.design_rules import Violation
from components.gear_mesh import (
    REGIME_NAMES,
    ClockModel,
    ClockTableModel,
    GearMesh,
    InvoluteModel,
    MeshModel,
    build_mesh,
)
from components.mesh_design import check_mesh_design
from components.mesh_efficiency import (
    CycleSummary,
    clock_table_cycle_summary,
    involute_cycle,
    involute_cycle_summary,
    involute_efficiency_curve,
    involute_linear_terms,
    train_mesh_cycle_summary,
)
from orchestrator.errors import ScenarioError
from orchestrator.plotting import (
    of,
    regime_bands,
    regime_colours,
    regime_names,
    regime_spans,
    run_events,
    save_figure,
)
from orchestrator.scene_model import Scene
from orchestrator.scenes.family import Quantity, Reference, quantity

#: Names of the efficiency on the (left, right) side of each kind of contact change.
_SIDES = {
    "involute": {
        "pair": ("efficiency_single_end", "efficiency_dual_start"),
        "contact": ("efficiency_dual_end", "efficiency_single_start"),
    },
    "clock": {
        "pair": ("efficiency_pair_end", "efficiency_pair_start"),
        "contact": ("efficiency_ror_end", "efficiency_rof_start"),
    },
}


@dataclass(frozen=True)
class MeshScene:
    """The GearMesh instance of a scene, its SI parameters and the built mesh model."""

    instance: str
    params: dict[str, float]
    load: float  # start value of the load torque [N.m]
    load_connected: bool  # the load torque comes from another FMU
    model: MeshModel
    start: float  # s
    theta0: float  # driver angle at the start [rad]

    @property
    def speed(self) -> float:
        return self.params["speed"]

    @property
    def family(self) -> str:
        return "involute" if isinstance(self.model, InvoluteModel) else "clock"

    def angle(self, t: np.ndarray | float) -> np.ndarray | float:
        """Driver angle at scene time t, computed as the component does."""
        return self.theta0 + self.speed * (t - self.start)


def mesh_scene(scene: Scene) -> MeshScene:
    """The one GearMesh of a scene; ScenarioError (file, key, expectation) when it cannot be."""
    names = [n for n, spec in scene.fmus.items() if spec.component == "GearMesh"]
    if len(names) != 1:
        raise ScenarioError(scene.path, "fmus", f"expected exactly one GearMesh, found {names}")
    inst = names[0]
    params = {v.name: float(v.start) for v in GearMesh.variables("parameter")}
    params.update(scene.fmus[inst].parameters)
    try:
        model = build_mesh(
            params["model"], params["mesh"], params["clock_mesh"], params["mu"],
            params["printed_run"], params,
        )  # fmt: skip
    except ComponentError as exc:
        raise ScenarioError(scene.path, f"fmus.{inst}.parameters", str(exc)) from None
    if not params["speed"] > 0.0:
        raise ScenarioError(scene.path, f"fmus.{inst}.parameters.speed", "expected > 0")
    if not 0.0 <= params["phase0"] < 1.0:
        raise ScenarioError(scene.path, f"fmus.{inst}.parameters.phase0", "expected in [0, 1)")
    load = scene.fmus[inst].inputs.get("load_torque", GearMesh.variable("load_torque").start)
    connected = any(c.target == (inst, "load_torque") for c in scene.connections)
    theta0 = model.cycle_start + params["phase0"] * model.cycle
    return MeshScene(inst, params, float(load), connected, model, scene.start, theta0)


def check(scene: Scene) -> list[Violation]:
    """Every broken consistency rule of the user pair the scene's GearMesh selects (empty for
    a stored mesh): components.mesh_design.check_mesh_design on its parameters."""
    names = [n for n, spec in scene.fmus.items() if spec.component == "GearMesh"]
    out: list[Violation] = []
    for name in names:
        params = {v.name: float(v.start) for v in GearMesh.variables("parameter")}
        params.update(scene.fmus[name].parameters)
        out.extend(check_mesh_design(params))
    return out


def _whole_cycles(ms: MeshScene, theta_first: float, theta_last: float) -> tuple[float, int]:
    """(angle where the first whole cycle starts, number of whole cycles up to theta_last)."""
    m = ms.model
    k = math.ceil((theta_first - m.cycle_start) / m.cycle - 1e-9)
    begin = m.cycle_start + k * m.cycle
    return begin, max(0, math.floor((theta_last - begin) / m.cycle + 1e-9))


def _break_kind(m: MeshModel, theta: float) -> str:
    """Kind of the contact change nearest to driver angle theta (cyclically)."""
    local = (theta - m.cycle_start) % m.cycle

    def distance(offset: float) -> float:
        d = abs(local - offset) % m.cycle
        return min(d, m.cycle - d)

    best = min(range(len(m.offsets)), key=lambda i: distance(m.offsets[i]))
    return m.kinds[best]


def _units(name: str) -> str:
    return {"mean_driver_torque": "N.m"}.get(name, "1")


# -- analysis of a run -----------------------------------------------------------------------
def analyse(
    scene: Scene, header: list[str], data: np.ndarray, options: dict[str, Any]
) -> dict[str, Quantity]:
    """Headline quantities of a gear-mesh run over its whole mesh cycles (module doc).

    Needs recorded: driver_angle, efficiency, regime, input_work, output_work, dissipated_work
    of the GearMesh (stored_energy too for the energy residual, if recorded).
    """
    ms = mesh_scene(scene)
    col = {name: data[:, i] for i, name in enumerate(header)}
    p = ms.instance
    theta = col[f"{p}.driver_angle"]
    eff = col[f"{p}.efficiency"]
    w_in, w_out = col[f"{p}.input_work"], col[f"{p}.output_work"]
    out: dict[str, Quantity] = {}
    stored = col.get(f"{p}.stored_energy", np.zeros_like(w_in))
    balance = w_in - w_out - col[f"{p}.dissipated_work"] - stored
    scale = float(np.max(np.abs(w_in)))
    if scale > 0.0:
        out["energy_residual"] = quantity(np.max(np.abs(balance)) / scale, "1")
    begin, n = _whole_cycles(ms, float(theta[0]), float(theta[-1]))
    out["whole_cycles"] = quantity(n, "1")
    if n == 0:
        return out
    end = begin + n * ms.model.cycle
    wi0, wi1 = np.interp([begin, end], theta, w_in)
    wo0, wo1 = np.interp([begin, end], theta, w_out)
    if wi1 > wi0:
        out["cycle_efficiency"] = quantity((wo1 - wo0) / (wi1 - wi0), "1")
    out["mean_driver_torque"] = quantity((wi1 - wi0) / (end - begin), "N.m")
    tol = 1e-9 * ms.model.cycle
    inside = (theta >= begin - tol) & (theta <= end + tol)
    out["min_efficiency"] = quantity(np.min(eff[inside]), "1")
    out["max_efficiency"] = quantity(np.max(eff[inside]), "1")
    # Driver-angle mean: trapezoids between samples (both sides of each jump are recorded).
    x = np.concatenate(([begin], theta[(theta > begin) & (theta < end)], [end]))
    y = np.interp(x, theta, eff)
    out["mean_efficiency"] = quantity(
        np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(x)) / (end - begin), "1"
    )
    regime = col[f"{p}.regime"].astype(int)
    sides: dict[str, list[float]] = {}
    for i in np.nonzero(np.diff(regime))[0]:
        mid = 0.5 * (theta[i] + theta[i + 1])
        if not begin - tol <= mid <= end + tol:
            continue
        kind = _break_kind(ms.model, mid)
        if kind in _SIDES[ms.family]:
            left, right = _SIDES[ms.family][kind]
            sides.setdefault(left, []).append(float(eff[i]))
            sides.setdefault(right, []).append(float(eff[i + 1]))
    for name, values in sides.items():
        out[name] = quantity(np.mean(values), "1")
    return out


# -- closed-form reference -------------------------------------------------------------------
def cycle_summary(ms: MeshScene) -> CycleSummary:
    """CycleSummary of the scene's mesh from components.mesh_efficiency."""
    m = ms.model
    if isinstance(m, InvoluteModel):
        return involute_cycle_summary(m.geometry, m.mu)
    if isinstance(m, ClockTableModel):
        return clock_table_cycle_summary(m.model, m.mu)
    assert isinstance(m, ClockModel)
    return train_mesh_cycle_summary(m.mesh, m.mu, m.rho_gear, m.rho_pinion)


def one_sided_efficiency(m: MeshModel, theta: float, side: int) -> float:
    """Point efficiency just before (side = -1) or after (+1) driver angle theta.

    Involute: exact, from the linear-fractional form of the adjoining phase.  Clock: 1e-9 of a
    cycle away (the efficiency is smooth within a phase; at a sliding reversal the friction
    direction is undefined).
    """
    probe = theta + side * 1e-9 * m.cycle
    if isinstance(m, InvoluteModel):
        if m.ideal:
            return 1.0
        g = m.geometry
        local = g.alpha_in + (probe - g.alpha_in) % g.cycle_angle
        n0, n1, d0, d1 = involute_linear_terms(g, m.mu, local)
        a = local + (theta - probe)  # the break, in the window of the adjoining phase
        return (n0 + n1 * a) / (d0 + d1 * a)
    return m.efficiency(probe)


def reference(scene: Scene) -> Reference:
    """Closed-form values of components.mesh_efficiency for the scene's mesh, mu and load."""
    ms = mesh_scene(scene)
    if ms.load_connected:
        raise ScenarioError(
            scene.path,
            "report.reference",
            "the gear_mesh reference needs the load torque as a scene input, not a connection",
        )
    m = ms.model
    summary = cycle_summary(ms)
    theta_end = float(ms.angle(scene.stop))
    _, n = _whole_cycles(ms, ms.theta0, theta_end)
    headline = {"whole_cycles": float(n)}
    if n > 0:
        headline.update(
            {
                "cycle_efficiency": summary.work_efficiency,
                "mean_efficiency": summary.mean_efficiency,
                "min_efficiency": summary.minimum,
                "max_efficiency": summary.maximum,
                "mean_driver_torque": ms.load * summary.mean_ratio / summary.work_efficiency,
            }
        )
        for b, kind in zip(m.breaks, m.kinds, strict=True):
            if kind in _SIDES[ms.family]:
                left, right = _SIDES[ms.family][kind]
                headline[left] = one_sided_efficiency(m, b, -1)
                headline[right] = one_sided_efficiency(m, b, +1)
    p = ms.instance
    driven0 = m.driven(ms.theta0)

    def signals(times: np.ndarray) -> dict[str, np.ndarray]:
        values = np.array([m.evaluate(float(ms.angle(t))) for t in times]).reshape(-1, 3)
        return {
            f"{p}.driver_angle": ms.angle(times),
            f"{p}.driven_angle": values[:, 0] - driven0,
            f"{p}.speed_ratio": values[:, 1],
            f"{p}.efficiency": values[:, 2],
            f"{p}.driver_torque": ms.load * values[:, 1] / values[:, 2],
        }

    events = []
    theta = m.next_break(ms.theta0)
    while theta <= theta_end:
        before, after = (m.regime(theta + s * 1e-9 * m.cycle) for s in (-1.0, 1.0))
        t = ms.start + (theta - ms.theta0) / ms.speed
        events.append((t, p, REGIME_NAMES[before], REGIME_NAMES[after]))
        theta = m.next_break(theta)
    return Reference(headline=headline, signals=signals, events=events)


# -- plot ------------------------------------------------------------------------------------
def plot(scene: Scene, header: list[str], data: np.ndarray, path: Path) -> None:
    """Point efficiency against driver angle with the closed-form curve, and the driver torque."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ms = mesh_scene(scene)
    m = ms.model
    col = {name: data[:, i] for i, name in enumerate(header)}
    p = ms.instance
    theta = col[f"{p}.driver_angle"]
    deg = np.degrees(theta)
    fig, axes = plt.subplots(2, 1, figsize=(9, 7), sharex=True, height_ratios=(3, 2))
    ax = axes[0]
    # Closed-form curve over the recorded angles, cycle by cycle.
    first = math.floor((theta[0] - m.cycle_start) / m.cycle)
    last = math.floor((theta[-1] - m.cycle_start) / m.cycle)
    label = "closed form"
    for k in range(first, last + 1):
        if isinstance(m, InvoluteModel):
            if m.ideal:
                a = m.cycle_start + m.cycle * np.linspace(0.0, 1.0, 50)
                e = np.ones_like(a)
            else:
                a, e = involute_efficiency_curve(m.geometry, m.mu, n=800)
        else:
            a = m.cycle_start + m.cycle * np.arange(400) / 400
            e = np.array([m.efficiency(float(x)) for x in a])
        a = a + k * m.cycle
        keep = (a >= theta[0]) & (a <= theta[-1])
        ax.plot(np.degrees(a[keep]), e[keep], "-", color="0.6", lw=3, label=label)
        label = None
        for b, kind in zip(m.breaks, m.kinds, strict=True):
            x = b + k * m.cycle
            if theta[0] <= x <= theta[-1]:
                style = {"pair": ":", "contact": "--", "pitch": "-."}[kind]
                ax.axvline(np.degrees(x), color="0.8", ls=style, lw=0.8)
    if isinstance(m, InvoluteModel) and not m.ideal:
        alphas, pts, cyc, mn = involute_cycle(m.geometry, m.mu, m.points)
        ax.plot(
            np.degrees(alphas),
            pts,
            "x",
            color="C3",
            label=f"report K = {m.points} (CYCLEFF {cyc:.4f})",
        )
    ax.plot(deg, col[f"{p}.efficiency"], ".-", color="C0", ms=2, lw=0.8, label="co-simulation")
    ax.set_ylabel("point efficiency")
    phases = "end of dual contact" if ms.family == "involute" else "round-on-round -> on flank"
    ax.set_title(
        f"{scene.name}: {m.name}, mu = {m.mu:g}\n(dotted: new pair, dashed: {phases}, "
        "dash-dot: pitch point)",
        fontsize=9,
    )
    ax.grid(True, alpha=0.3)
    lo, hi = ax.get_ylim()
    ax.set_ylim(lo, hi + 0.18 * (hi - lo))  # room for the legend above the curves
    ax.legend(fontsize=8, loc="upper left", ncol=3)
    ax = axes[1]
    if f"{p}.driver_torque" in col:
        ax.plot(deg, col[f"{p}.driver_torque"], color="C1", lw=0.9)
        ax.set_ylabel("driver torque [N·m]", color="C1")
    if f"{p}.cycle_efficiency" in col:
        twin = ax.twinx()
        twin.plot(deg, col[f"{p}.cycle_efficiency"], color="C2", lw=0.9)
        twin.set_ylabel("output / input work [1]", color="C2")
    ax.set_xlabel("driver angle [deg]" + (" (roll angle)" if ms.family == "involute" else ""))
    ax.grid(True, alpha=0.3)
    # The contact regimes behind the torque, switching at their located times (events.csv)
    # drawn at the driver angle of those times.
    t = col["time"]
    names = regime_names(scene, p)
    spans = regime_spans(t, col[f"{p}.regime"], names, of(run_events(path), p))
    at = [(np.interp(a, t, deg), np.interp(b, t, deg), n) for a, b, n in spans]
    handles = regime_bands(ax, at, regime_colours(names), alpha=0.6)
    ax.legend(
        handles=handles, fontsize=8, loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=3,
        frameon=False, title="contact regimes (bands):", title_fontsize=8, alignment="left",
    )  # fmt: skip
    save_figure(fig, path)
