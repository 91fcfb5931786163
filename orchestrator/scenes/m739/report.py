"""The M739 S&A scenes: turns to arm, contact-force maxima and impacts, and their yardstick.

Targets of Lowen & Tepper (1982), ARLCD-TR-82013: Output Data (pp. 11-13) and Conclusions.

The scene couples two FMUs at the escape-wheel shaft: ``train`` (GearTrain) and ``verge``
(VergeEscapement), and stops when the cumulative escape-wheel angle reaches the arming
angle (``scene.stop_when``).  Instance names come from ``[report.options]`` (defaults
"train" and "verge").
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from components.gear_train import TRAIN_REGIME_NAMES
from components.m739_data import LBF, M739
from components.units import RPM_PER_RAD_S
from components.verge_escapement import FREE, REGIME_NAMES
from orchestrator.scenario import Scene
from orchestrator.scenes.family import Quantity, Reference, quantity
from orchestrator.scenes.m739.design import scene_design
from orchestrator.scenes.m739.monolithic import run_m739


def instance_names(scene: Scene) -> tuple[str, str]:
    """(gear train, verge) instances, from [report.options]."""
    o = scene.report_options
    return o.get("train", "train"), o.get("verge", "verge")


def _parameter(scene: Scene, instance: str, name: str) -> float:
    spec = scene.fmus[instance]
    if name in spec.parameters:
        return spec.parameters[name]
    return scene.component_class(instance).variable(name).start


def escapement_arguments(scene: Scene, train: str, verge: str) -> dict[str, float]:
    """The arguments every verge-train monolithic model takes, from the scene's FMUs."""
    return {
        "mu": _parameter(scene, train, "mu"),
        "mu1": _parameter(scene, verge, "mu1"),
        "rpm": _parameter(scene, train, "spin") * RPM_PER_RAD_S,
        "e_rest": _parameter(scene, verge, "e_rest"),
        "t_stop": scene.stop,
    }


def _arming_angle(scene: Scene) -> float:
    """The scene's stop condition (the design's arming angle, which the loader checked it
    against), else the design's arming angle."""
    cond = scene.stop_when
    if cond is not None:
        return cond.threshold
    train, _ = instance_names(scene)
    if "arming_angle" in {v.name for v in scene.component_class(train).VARIABLES}:
        return _parameter(scene, train, "arming_angle")
    return M739.phi_cut


def crossing_time(t: np.ndarray, x: np.ndarray, level: float, rising: bool = True) -> float | None:
    """First time x reaches level (linear within the step a fixed-step master overshoots);
    None: never."""
    hit = np.nonzero(x >= level if rising else x <= level)[0]
    if not len(hit):
        return None
    k = int(hit[0])
    if k == 0 or x[k] == level:
        return float(t[k])
    return float(t[k - 1] + (t[k] - t[k - 1]) * (level - x[k - 1]) / (x[k] - x[k - 1]))


def arming_time(scene: Scene, t: np.ndarray, phi: np.ndarray) -> float | None:
    """When the escape-wheel angle ``phi`` first reaches the arming angle; None: never."""
    return crossing_time(t, phi, _arming_angle(scene))


def turns_to_arm(scene: Scene, t_arm: float) -> float:
    """Turns of the projectile (at the train's spin) in ``t_arm`` seconds."""
    train, _ = instance_names(scene)
    return t_arm * abs(_parameter(scene, train, "spin")) / (2.0 * math.pi)


def analyse(
    scene: Scene, header: list[str], data: np.ndarray, options: dict[str, Any]
) -> dict[str, Quantity]:
    """Turns to arm (or why not), arming time, force maxima by regime, impacts."""
    train, verge = instance_names(scene)
    col = {name: data[:, i] for i, name in enumerate(header)}
    out: dict[str, Any] = {}
    t_arm = arming_time(scene, col["time"], col[f"{train}.phi"])
    if t_arm is not None:
        out["armed"] = quantity(1.0, "1")
        out["arming_time"] = quantity(t_arm, "s")
        out["turns_to_arm"] = quantity(turns_to_arm(scene, t_arm), "1")
    else:
        out["armed"] = quantity(0.0, "1")
        out["not_armed_reason"] = {"value": _why_not_armed(scene, col, train), "unit": ""}
    regime = col[f"{verge}.regime"]
    coupled = regime != FREE
    for name, mask in (("F23", coupled), ("F12", coupled), ("FF23", ~coupled), ("FF12", ~coupled)):
        out[f"{name}_max"] = quantity(force_max(col, train, name, mask), "N")
    out["PN_max"] = quantity(pn_max(col, verge), "N")
    out["impacts"] = quantity(float(col[f"{verge}.impact_count"][-1]), "1")
    return out


def force_max(col: dict[str, np.ndarray], train: str, name: str, mask: np.ndarray) -> float:
    """The largest mesh force ``name`` (F*: coupled motion, FF*: free motion, as the
    report's) over the recorded rows of ``mask``, or the train's own peak over its internal
    steps (``<name>_peak``) where recorded and larger."""
    source = col[f"{train}.{name}"]
    recorded = float(np.max(source[mask])) if mask.any() else 0.0
    peak = col.get(f"{train}.{name}_peak")
    return recorded if peak is None else max(recorded, float(peak[-1]))


def pn_max(col: dict[str, np.ndarray], verge: str) -> float:
    """The largest tooth-face normal force: the verge's own peak over its internal steps
    where recorded (``PN_peak``), else the largest recorded value."""
    recorded = float(np.max(col[f"{verge}.PN"]))
    peak = col.get(f"{verge}.PN_peak")
    return recorded if peak is None else max(recorded, float(peak[-1]))


def _why_not_armed(scene: Scene, col: dict[str, np.ndarray], train: str) -> str:
    speed = col[f"{train}.phi_dot"]
    if len(speed) > 1 and abs(speed[-1]) < 1e-9 and col[f"{train}.regime"][-1] == 0:
        moving = np.nonzero(np.abs(speed) >= 1e-9)[0]
        t_stop = col["time"][moving[-1] + 1] if len(moving) else col["time"][0]
        return f"stalled: the train is held by friction from t = {t_stop:.6g} s on"
    return f"stop time {scene.stop:.6g} s reached before the arming angle"


def monolithic_arguments(scene: Scene) -> dict[str, Any]:
    """What ``run_m739`` takes for the scene: its operating point and its whole design."""
    train, verge = instance_names(scene)
    return {
        **escapement_arguments(scene, train, verge),
        "indexing": int(_parameter(scene, train, "indexing")),
        "data": scene_design(scene),
    }


def reference(scene: Scene) -> Reference:
    """The monolithic M739 model with the scene's physics and design, as the yardstick."""
    train, verge = instance_names(scene)
    return reference_from(run_m739(**monolithic_arguments(scene)), train, verge)


def reference_from(result: Any, train: str, verge: str) -> Reference:
    """A Reference from a monolithic verge-and-train result (``M739Result``)."""
    s = result.series
    headline = {
        "F23_max": result.f23_max,
        "F12_max": result.f12_max,
        "FF23_max": result.ff23_max,
        "FF12_max": result.ff12_max,
        "PN_max": result.pn_max,
        "impacts": float(result.impacts),
    }
    if result.armed:
        headline["turns_to_arm"] = result.turns
        headline["arming_time"] = result.t_arm

    def signals(times: np.ndarray) -> dict[str, np.ndarray]:
        # The escape-wheel angle is continuous (speeds jump at impacts): it is the trajectory
        # compared, within the reference's time range (t_range).
        if "t" not in s or len(s["t"]) == 0:
            return {}  # the reference has no time series (e.g. no spin: it never moved)
        return {f"{train}.phi": np.interp(times, s["t"], s["phi"])}

    t_range = (float(s["t"][0]), float(s["t"][-1])) if len(s.get("t", ())) else None

    events = [
        (te, verge, REGIME_NAMES.get(a, str(a)), REGIME_NAMES.get(b, str(b)))
        for te, a, b in result.regime_log
    ]
    # The train's reversals and sticks, as the train FMU logs them (an impact with rebound
    # throws the wheel back).
    events += [
        (te, train, TRAIN_REGIME_NAMES.get(a, str(a)), TRAIN_REGIME_NAMES.get(b, str(b)))
        for te, a, b in getattr(result, "train_log", ())
    ]
    events.sort(key=lambda e: e[0])
    return Reference(headline=headline, signals=signals, events=events, t_range=t_range)


def plot(scene: Scene, header: list[str], data: np.ndarray, path: Path) -> None:
    """Verge and escape-wheel motion over the first cycles (about 3 teeth)."""
    fig, _, _ = escapement_figure(scene, header, data, extra_panels=0)
    save_figure(fig, f"{scene.name}: verge and escape-wheel motion, first cycles", path)


def escapement_figure(scene: Scene, header: list[str], data: np.ndarray, extra_panels: int):
    """The first 2.2 ms: angles, speeds, and PN with the verge regime, above ``extra_panels``
    empty panels.  Returns (figure, axes, (ms, columns restricted to the window))."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    train, verge = instance_names(scene)
    col = {name: data[:, i] for i, name in enumerate(header)}
    t = col["time"]
    window = t <= min(t[-1], 2.2e-3)
    col = {name: values[window] for name, values in col.items()}
    rows = 3 + extra_panels
    fig, axes = plt.subplots(rows, 1, figsize=(9, 8 + 2 * extra_panels), sharex=True)
    ms = col["time"] * 1e3
    axes[0].plot(ms, np.degrees(col[f"{train}.phi"]), label="escape wheel (cumulative)")
    axes[0].set_ylabel("angle [deg]")
    ax2 = axes[0].twinx()
    ax2.plot(ms, np.degrees(col[f"{verge}.psi"]), color="C1", label="verge")
    ax2.set_ylabel("verge angle [deg]", color="C1")
    axes[1].plot(ms, col[f"{train}.phi_dot"], label="escape wheel")
    axes[1].plot(ms, col[f"{verge}.psi_dot"], label="verge")
    axes[1].set_ylabel("speed [rad/s]")
    axes[1].legend(loc="upper right")
    axes[2].plot(ms, col[f"{verge}.PN"] / LBF, label="PN")
    axes[2].step(ms, col[f"{verge}.regime"], where="post", color="grey", label="regime")
    axes[2].set_ylabel("PN [lb] / regime")
    axes[2].legend(loc="upper right")
    axes[-1].set_xlabel("time [ms]")
    return fig, axes, (ms, col)


def save_figure(fig: Any, title: str, path: Path) -> None:
    import matplotlib.pyplot as plt

    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
