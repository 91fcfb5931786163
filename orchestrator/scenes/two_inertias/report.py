"""Closed-form reference of the two-inertia scene: two bodies joined by a spring–damper.

The centre of mass moves at constant speed; the twist x = phi_a - phi_b is a damped
oscillator with the reduced inertia J_a J_b / (J_a + J_b).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from components.rotational import damped_oscillator_transition
from orchestrator.plotting import column_unit, pyplot, recorded, save_figure, unit_label
from orchestrator.scene_model import Scene
from orchestrator.scenes.family import Reference
from orchestrator.stop_condition import reference_crossing


def two_inertias_exact(
    t: np.ndarray,
    J_a: float,
    J_b: float,
    k: float,
    d: float,
    phi_a0: float = 0.0,
    w_a0: float = 0.0,
    phi_b0: float = 0.0,
    w_b0: float = 0.0,
) -> dict[str, np.ndarray]:
    """Angles and speeds of both bodies at times t (measured from the start)."""
    t = np.asarray(t, dtype=float)
    total = J_a + J_b
    j_red = J_a * J_b / total
    centre0 = (J_a * phi_a0 + J_b * phi_b0) / total
    centre_w = (J_a * w_a0 + J_b * w_b0) / total
    x0, v0 = phi_a0 - phi_b0, w_a0 - w_b0
    x = np.empty_like(t)
    v = np.empty_like(t)
    for n, tn in enumerate(t):
        m = damped_oscillator_transition(k / j_red, d / j_red, float(tn))
        x[n] = m[0] * x0 + m[1] * v0
        v[n] = m[2] * x0 + m[3] * v0
    centre = centre0 + centre_w * t
    return {
        "phi_a": centre + J_b / total * x,
        "w_a": centre_w + J_b / total * v,
        "phi_b": centre - J_a / total * x,
        "w_b": centre_w - J_a / total * v,
    }


def two_inertias_reference(scene: Scene) -> Reference:
    """The closed form as the scene's Reference (instances named in report.options)."""
    a = scene.report_options.get("body_a", "a")
    b = scene.report_options.get("body_b", "b")
    par_a = {v.name: v.start for v in scene.component_class(a).VARIABLES}
    par_b = {v.name: v.start for v in scene.component_class(b).VARIABLES}
    par_a.update(scene.fmus[a].parameters)
    par_b.update(scene.fmus[b].parameters)

    def signals(times: np.ndarray) -> dict[str, np.ndarray]:
        x = two_inertias_exact(
            np.asarray(times) - scene.start,
            par_a["J"],
            par_b["J"],
            par_b["k"],
            par_b["d"],
            par_a["phi0"],
            par_a["w0"],
            par_b["phi0"],
            par_b["w0"],
        )
        return {
            f"{a}.phi": x["phi_a"],
            f"{a}.w": x["w_a"],
            f"{b}.phi": x["phi_b"],
            f"{b}.w": x["w_b"],
        }

    # A run that stops on scene.stop_when ends where the closed form meets it: the final
    # angle there (the run's own end: its crossing, within its last step).
    end, at_condition = scene.stop, False
    if scene.stop_when is not None:
        crossing = reference_crossing(signals, scene.stop_when, scene.start, scene.stop)
        if crossing is not None:
            end, at_condition = crossing, True
    final = signals(np.array([end]))
    return Reference(
        headline={"final_angle_a": float(final[f"{a}.phi"][0])},
        signals=signals,
        at_stop_when=at_condition,
    )


def plot(scene: Scene, header: list[str], data: np.ndarray, path: Path) -> None:
    """Both bodies' angles and speeds, and the coupling torque, each on its own axis."""
    a = scene.report_options.get("body_a", "a")
    b = scene.report_options.get("body_b", "b")
    col = {name: data[:, i] for i, name in enumerate(header)}
    t = col["time"]
    panels = [("angle", "phi"), ("speed", "w"), ("coupling torque", "tau")]
    panels = [(q, v) for q, v in panels if f"{a}.{v}" in col or f"{b}.{v}" in col]
    fig, axes = pyplot().subplots(len(panels), 1, figsize=(9, 2.6 * len(panels)), sharex=True)
    for ax, (quantity, variable) in zip(np.atleast_1d(axes), panels, strict=True):
        unit = ""
        for k, body in enumerate((a, b)):
            if f"{body}.{variable}" in col:
                recorded(ax, t, col[f"{body}.{variable}"], color=f"C{k}", label=f"{body}")
                unit = column_unit(scene, f"{body}.{variable}")
        unit_label(ax, quantity, unit)
        ax.legend(loc="upper right", fontsize=8)
        ax.grid(True, alpha=0.3)
    np.atleast_1d(axes)[-1].set_xlabel("time [s]")
    save_figure(fig, path, f"{scene.name}: two inertias on a spring-damper")
