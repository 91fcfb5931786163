"""The clock-train S&A scenes: the M739 verge escapement behind a two-pass clock gear train.

Sources: the M739 rotor, verge and data of Lowen & Tepper (1982), ARLCD-TR-82013; the clock
train kinematics of the US Army fuze report of about 1980 (Task 2, eqs. 1-126).

Two FMUs meet at the escape-wheel shaft: ``train`` (ClockGearTrain: the M739 spin-driven rotor
and the clock train of ``components.clock_train_kinematics``) and ``verge`` (VergeEscapement,
with its
escapement centre distance as a parameter).  Arming is the rotor's: the run stops when the rotor
has turned as far as the M739's does to arm (``scene.stop_when`` on ``train.rotor_angle``;
1485 deg of escape wheel over 32 on the M739).  The clock ratio ripples, so the escape-wheel
angle at arming differs a little from 1485 deg; it is reported.

``reference`` is the monolithic model of the same physics: the verge regime machine with the
live clock-train physics (``ClockTrainPhysics``) in place of the held affine response, one ODE
with every event located (the structure of ``orchestrator.scenes.m739.monolithic``), and the tooth
handover impact there including the verge inertia exactly when the verge is coupled.
Instance names come from ``[report.options]`` (defaults "train" and "verge").
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from components.verge_escapement import (
    FREE,
)
from orchestrator.plotting import recorded
from orchestrator.scene_model import Scene
from orchestrator.scenes.clock_train.design import train_values, verge_data
from orchestrator.scenes.clock_train.monolithic import ARMING_ROTOR_ANGLE, run_clock_train
from orchestrator.scenes.family import Outcome, Quantity, Reference, quantity
from orchestrator.scenes.m739.report import (
    _parameter,
    _why_not_armed,
    arming_model,
    crossing_time,
    escapement_arguments,
    escapement_plot,
    force_max,
    instance_names,
    pn_max,
    reference_from,
    turns_to_arm,
)


def _arming(scene: Scene, train: str) -> tuple[str, float, bool]:
    """(signal column, threshold, rising) of the arming condition."""
    cond = scene.stop_when
    if cond is not None:
        return ".".join(cond.signal), cond.threshold, cond.rising
    return f"{train}.rotor_angle", ARMING_ROTOR_ANGLE, True


def analyse(
    scene: Scene, header: list[str], data: np.ndarray, options: dict[str, Any]
) -> dict[str, Quantity]:
    """Turns to arm (or why not), escape-wheel angle at arming, force maxima, impacts,
    tooth handovers."""
    train, verge = instance_names(scene)
    col = {name: data[:, i] for i, name in enumerate(header)}
    t = col["time"]
    signal, level, rising = _arming(scene, train)
    out: dict[str, Any] = {}
    t_arm = crossing_time(t, col[signal], level, rising) if signal in col else None
    if t_arm is not None:
        out["armed"] = quantity(1.0, "1")
        out["arming_time"] = quantity(t_arm, "s")
        out["turns_to_arm"] = quantity(turns_to_arm(scene, t_arm), "1")
        out["phi_at_arming"] = quantity(float(np.interp(t_arm, t, col[f"{train}.phi"])), "rad")
    else:
        out["armed"] = quantity(0.0, "1")
        out["not_armed_reason"] = {"value": _why_not_armed(scene, col, train), "unit": ""}
    coupled = col[f"{verge}.regime"] != FREE
    for name, mask in (("F23", coupled), ("F12", coupled), ("FF23", ~coupled), ("FF12", ~coupled)):
        out[f"{name}_max"] = quantity(force_max(col, train, name, mask), "N")
    out["PN_max"] = quantity(pn_max(col, verge), "N")
    out["impacts"] = quantity(float(col[f"{verge}.impact_count"][-1]), "1")
    if f"{train}.handovers" in col:
        out["handovers"] = quantity(float(col[f"{train}.handovers"][-1]), "1")
    return out


def monolithic_arguments(scene: Scene) -> dict[str, Any]:
    """What ``run_clock_train`` takes for the scene: its operating point, its design and
    its arming angle (the reference and the work-precision curve both run it so)."""
    train, verge = instance_names(scene)
    signal, level, _ = _arming(scene, train)
    if signal != f"{train}.rotor_angle":
        raise ValueError(
            f"clock_train reference: arming must be scene.stop_when on {train}.rotor_angle"
        )
    return {
        **escapement_arguments(scene, train, verge),
        "loss_model": int(_parameter(scene, train, "loss_model")),
        "pivot_loads": _parameter(scene, train, "pivot_loads") == 1.0,
        "mesh_phase": _parameter(scene, train, "mesh_phase"),
        "center_distance": _parameter(scene, verge, "center_distance"),
        "pallet_inertia": _parameter(scene, verge, "pallet_inertia"),
        "rotor_arming_angle": level,
        "design": train_values(scene),
        "verge_data": verge_data(scene),
    }


def reference(scene: Scene) -> Reference:
    """The monolithic clock-train S&A with the scene's physics, as the yardstick."""
    train, verge = instance_names(scene)
    result = run_clock_train(**monolithic_arguments(scene))
    ref = reference_from(result, train, verge)
    if result.armed:
        ref.headline["phi_at_arming"] = result.phi_end
    return ref


def plot(scene: Scene, header: list[str], data: np.ndarray, path: Path) -> None:
    """The whole run to arming above the first teeth in detail, the clock train's speed ratio
    and mesh efficiencies among them."""
    train, _ = instance_names(scene)

    def clock_panels(axes: list, ms: np.ndarray, col: dict[str, np.ndarray]) -> None:
        if f"{train}.speed_ratio" in col:
            recorded(axes[0], ms, col[f"{train}.speed_ratio"], color="C4")
        axes[0].set_ylabel("speed ratio\nwheel/rotor [1]")
        for i, c in ((1, "C5"), (2, "C6")):
            if f"{train}.efficiency{i}" in col:
                recorded(axes[1], ms, col[f"{train}.efficiency{i}"], color=c, label=f"mesh {i}")
        axes[1].set_ylabel("point efficiency [1]")
        if axes[1].get_lines():
            axes[1].legend(loc="upper left", bbox_to_anchor=(1.005, 1.0), fontsize=8, frameon=False)

    clock_panels.panels = 2  # type: ignore[attr-defined]
    title = f"{scene.name}: M739 verge behind a clock gear train"
    signal, level, rising = _arming(scene, train)
    t = data[:, 0]
    t_arm = (
        crossing_time(t, data[:, header.index(signal)], level, rising) if signal in header else None
    )
    escapement_plot(scene, header, data, path, title, t_arm, extra=clock_panels)


def monolithic_model(scene: Scene) -> Callable[[float], Outcome]:
    """The monolithic model with the scene's physics (as the reference runs it), as a
    function of its tolerance: its turns to arm (NaN: it did not arm)."""
    return arming_model(run_clock_train, monolithic_arguments(scene))
