"""The M739 S&A scenes: turns to arm, contact-force maxima and impacts, and their yardstick.

Targets of Lowen & Tepper (1982), ARLCD-TR-82013: Output Data (pp. 11-13) and Conclusions.

The scene couples two FMUs at the escape-wheel shaft: ``train`` (GearTrain) and ``verge``
(VergeEscapement), and stops when the cumulative escape-wheel angle reaches the arming
angle (``scene.stop_when``).  Instance names come from ``[report.options]`` (defaults
"train" and "verge").
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from components.gear_train import TRAIN_REGIME_NAMES
from components.m739_data import M739
from components.units import RPM_PER_RAD_S
from components.verge_escapement import FREE, REGIME_NAMES
from orchestrator.plotting import (
    event_lines,
    of,
    pyplot,
    recorded,
    regime_colours,
    regime_names,
    regime_spans,
    regime_strip,
    run_events,
    save_figure,
    unit_label,
    window,
)
from orchestrator.scene_model import Scene
from orchestrator.scenes.family import Outcome, Quantity, Reference, quantity
from orchestrator.scenes.m739.design import instances, parameter, scene_design
from orchestrator.scenes.m739.monolithic import run_m739

#: (gear train, verge) instances of a scene, and a parameter of one of its FMUs as run.
instance_names = instances
_parameter = parameter


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
    result = run_m739(**monolithic_arguments(scene))
    return reference_from(result, train, verge, train_regimes=TRAIN_REGIME_NAMES)


def reference_from(
    result: Any, train: str, verge: str, train_regimes: dict[int, str] | None = None
) -> Reference:
    """A Reference from a monolithic verge-and-train result (``M739Result``); with
    ``train_regimes`` (the train FMU's regime names), the train's reversals are among its
    events too, as that FMU logs them."""
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
    if train_regimes is not None:
        events += [
            (te, train, train_regimes.get(a, str(a)), train_regimes.get(b, str(b)))
            for te, a, b in getattr(result, "train_log", ())
        ]
    events.sort(key=lambda e: e[0])
    # The monolithic model ends at arming, as a scene does on its stop_when.
    return Reference(
        headline=headline, signals=signals, events=events, t_range=t_range, at_stop_when=True
    )


def plot(scene: Scene, header: list[str], data: np.ndarray, path: Path) -> None:
    """The whole run (escape-wheel turns to arming, its speed, impacts per tooth) above the
    first teeth in detail (regimes, angles, speeds, normal force, impacts)."""
    train, _ = instance_names(scene)
    t_arm = arming_time(scene, data[:, 0], data[:, header.index(f"{train}.phi")])
    escapement_plot(scene, header, data, path, f"{scene.name}: M739 S&A, rotor-gear train", t_arm)


#: Teeth of the escape wheel shown in the detail window, from the start of the run.
DETAIL_TEETH = 3


def escapement_plot(
    scene: Scene,
    header: list[str],
    data: np.ndarray,
    path: Path,
    title: str,
    t_arm: float | None,
    extra: Any = None,
) -> None:
    """The plot of a spin-driven train and verge escapement armed at ``t_arm`` (None: not
    armed).  ``extra(axes, ms, col)`` draws on further detail panels (as many as its
    ``panels`` attribute says)."""
    plt = pyplot()

    train, verge = instance_names(scene)
    col = {name: data[:, i] for i, name in enumerate(header)}
    t = col["time"]
    events = run_events(path)
    phi = col[f"{train}.phi"]
    pitch = 2.0 * math.pi / M739.n_teeth
    impacts = _impacts(events, verge, t, col[f"{verge}.impact_count"])
    detail_end = crossing_time(t, phi - phi[0], DETAIL_TEETH * pitch) or float(t[-1])
    panels = getattr(extra, "panels", 0)
    # A fixed layout, in inches from the edges (a layout engine draws the figure several
    # times over to place it: most of the plot's cost): legends stand right of the axes.
    width, height = 11.0, 15.0 + 1.8 * panels
    fig = plt.figure(figsize=(width, height))
    top_height = 6.4  # the whole run, whatever the detail panels below
    top, bottom = fig.subfigures(2, 1, height_ratios=(top_height, height - top_height))
    verge_colours = regime_colours(regime_names(scene, verge))
    overview = _margins(width, top_height, top=1.2, bottom=0.55, hspace=0.12)
    _overview(top, scene, t, phi, col[f"{train}.phi_dot"], pitch, impacts, t_arm, detail_end,
              overview)  # fmt: skip
    _impact_bars(top.axes[2], t, phi, pitch, impacts, verge_colours)
    fig.suptitle(title, y=1.0 - 0.12 / height, va="top")
    top.suptitle("whole run", y=1.0 - 0.42 / top_height, va="top")
    heights = (0.5, 1, 1, 1.2, 1, *(1.1,) * panels)
    axes = bottom.subplots(
        len(heights),
        1,
        sharex=True,
        height_ratios=heights,
        gridspec_kw=_margins(width, height - top_height, top=0.55, bottom=0.55, hspace=0.25),
    )
    sel = window(t, t[0], detail_end)
    ms, cols = 1e3 * t[sel], {name: v[sel] for name, v in col.items()}
    rows = []
    for instance, label, first in ((verge, "verge", 0), (train, "train", 3)):
        names = regime_names(scene, instance)
        spans = regime_spans(ms * 1e-3, cols[f"{instance}.regime"], names, of(events, instance))
        rows.append((label, spans, regime_colours(names, first)))
    regime_strip(axes[0], rows, scale=1e3)
    recorded(axes[1], ms, np.degrees(cols[f"{train}.phi"]), color="C0")
    unit_label(axes[1], "escape wheel φ", "deg")
    recorded(axes[2], ms, np.degrees(cols[f"{verge}.psi"]), color="C1")
    unit_label(axes[2], "verge ψ", "deg")
    recorded(axes[3], ms, cols[f"{train}.phi_dot"], color="C0", label="escape wheel dφ/dt")
    recorded(axes[3], ms, cols[f"{verge}.psi_dot"], color="C1", label="verge dψ/dt")
    unit_label(axes[3], "speed", "rad/s")
    axes[3].legend(loc="upper left", bbox_to_anchor=(1.005, 1.0), fontsize=8, frameon=False)
    recorded(axes[4], ms, cols[f"{verge}.PN"], color="C2")
    unit_label(axes[4], "tooth normal force PN", "N")
    if extra is not None:
        extra(axes[5:], ms, cols)
    hit = [ti for ti, _ in impacts if t[0] <= ti <= detail_end]
    release = [e[0] for e in of(events, verge) if e[3] == REGIME_NAMES[FREE]]
    release = [ti for ti in release if ti <= detail_end]
    event_lines(axes[1:], release, 1e3, colour="0.45", style="--", width=0.7)
    event_lines(axes[1:], hit, 1e3, colour="C3", width=1.0)
    detail_title = 1.0 - 0.15 / (height - top_height)
    bottom.suptitle(f"the first {DETAIL_TEETH} teeth in detail", y=detail_title, va="top")
    axes[1].set_title(
        "recorded values as dots; red lines: impacts, "
        "dashed: the verge leaves the tooth (located times, events.csv)",
        fontsize=9,
        loc="left",
    )
    for ax in axes[1:]:
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel("time [ms]")
    axes[-1].set_xlim(1e3 * t[0], 1e3 * detail_end)
    bottom.align_ylabels(axes)
    save_figure(fig, path, tight=False)  # laid out here


def _margins(
    width: float, height: float, top: float, bottom: float, hspace: float
) -> dict[str, float]:
    """Grid parameters of a panel of ``width`` x ``height`` inches: ``top`` and ``bottom``
    margins in inches, room for the y labels left and the legends right."""
    return {
        "left": 0.95 / width,
        "right": 1.0 - 1.95 / width,
        "top": 1.0 - top / height,
        "bottom": bottom / height,
        "hspace": hspace,
    }


def _impacts(events: list, verge: str, t: np.ndarray, count: np.ndarray) -> list[tuple[float, str]]:
    """(time, pallet) of each impact: the verge's located switches from free motion onto a
    pallet, else the rows whose recorded impact count rose (pallet unknown)."""
    free = REGIME_NAMES[FREE]
    located = [(e[0], e[3]) for e in of(events, verge) if e[2] == free]
    if located:
        return located
    rose = np.nonzero(np.diff(count) > 0)[0] + 1
    return [(float(t[k]), "impact") for k in rose]


def _tooth_passes(t: np.ndarray, phi: np.ndarray, pitch: float) -> np.ndarray:
    """The start time and the times the escape wheel has turned one more tooth pitch."""
    teeth = int((phi[-1] - phi[0]) / pitch)
    passes = [crossing_time(t, phi - phi[0], k * pitch) for k in range(1, teeth + 1)]
    return np.array([t[0], *[x for x in passes if x is not None]])


def _impact_bars(
    ax: Any,
    t: np.ndarray,
    phi: np.ndarray,
    pitch: float,
    impacts: list[tuple[float, str]],
    colours: dict[str, str],
) -> None:
    """Impacts in each tooth's passage, by the pallet struck, stacked over its duration."""
    edges = _tooth_passes(t, phi, pitch)
    if len(edges) < 2:
        return
    tooth = np.searchsorted(edges, [ti for ti, _ in impacts], side="right") - 1
    bottom = np.zeros(len(edges) - 1)
    for kind in dict.fromkeys(kind for _, kind in impacts):
        mine = [k for k, (_, kd) in zip(tooth, impacts, strict=True) if kd == kind]
        n = np.bincount([k for k in mine if 0 <= k < len(bottom)], minlength=len(bottom))
        ax.stairs(
            bottom + n,
            1e3 * edges,
            baseline=bottom.copy(),
            fill=True,
            color=colours.get(kind, "C4"),
            label=f"onto {kind}",
        )
        bottom += n
    ax.legend(loc="upper left", bbox_to_anchor=(1.005, 1.0), fontsize=8, frameon=False)


def _overview(
    fig: Any,
    scene: Scene,
    t: np.ndarray,
    phi: np.ndarray,
    phi_dot: np.ndarray,
    pitch: float,
    impacts: list[tuple[float, str]],
    t_arm: float | None,
    detail_end: float,
    grid: dict[str, float],
) -> None:
    """Escape-wheel turns against time up to arming, its speed (recorded, and the mean over
    each tooth), impacts per tooth by pallet; ``grid``: the panel's margins."""
    axes = fig.subplots(3, 1, sharex=True, height_ratios=(1.4, 1, 0.8), gridspec_kw=grid)
    ms = 1e3 * t
    axes[0].plot(ms, phi / (2.0 * math.pi), color="C0", lw=1.2, label="escape wheel")
    unit_label(axes[0], "escape-wheel angle", "turn")
    level = _arming_angle(scene) / (2.0 * math.pi)
    if scene.stop_when is not None and ".".join(scene.stop_when.signal).endswith(".phi"):
        axes[0].axhline(level, color="C3", ls=":", lw=1, label="arming angle")
    if t_arm is not None:
        for ax in axes:
            ax.axvline(1e3 * t_arm, color="C3", lw=1.2)
        axes[0].annotate(
            f"armed at {1e3 * t_arm:.2f} ms, {turns_to_arm(scene, t_arm):.2f} projectile turns",
            (1e3 * t_arm, 0.5 * float(phi[-1]) / (2.0 * math.pi)),
            xytext=(-8, 0),
            textcoords="offset points",
            ha="right",
            color="C3",
            fontsize=9,
        )
    axes[0].legend(loc="upper left", fontsize=8)
    per_turn = turns_to_arm(scene, 1e-3)  # projectile turns per millisecond
    if per_turn > 0.0:
        sec = axes[0].secondary_xaxis(
            "top", functions=(lambda x: x * per_turn, lambda n: n / per_turn)
        )
        sec.set_xlabel("projectile turns")
    axes[1].plot(ms, phi_dot, ".", ms=1.5, color="0.65", label="recorded")
    edges = _tooth_passes(t, phi, pitch)
    if len(edges) > 1:
        mean = pitch / np.diff(edges)
        axes[1].stairs(
            mean, 1e3 * edges, baseline=None, color="C0", lw=1.5, label="mean over each tooth"
        )
    unit_label(axes[1], "escape-wheel speed", "rad/s")
    axes[1].legend(loc="upper left", fontsize=8)
    axes[2].set_ylabel("impacts per tooth")
    axes[2].set_xlabel("time [ms]")
    for ax in axes:
        ax.axvspan(1e3 * t[0], 1e3 * detail_end, color="0.9", zorder=0)
        ax.grid(True, alpha=0.3)
    axes[0].text(1e3 * detail_end, 0.0, " detail below", fontsize=8, va="bottom", color="0.4")


def monolithic_model(scene: Scene) -> Callable[[float], Outcome]:
    """The monolithic model with the scene's physics (as the reference runs it), as a
    function of its tolerance: its turns to arm (NaN: it did not arm)."""
    return arming_model(run_m739, monolithic_arguments(scene))


def arming_model(model: Callable[..., Any], kwargs: dict[str, Any]) -> Callable[[float], Outcome]:
    """``model(tolerance=..., **kwargs)`` (an S&A's monolithic run) as a function of its
    tolerance: its turns to arm (NaN: it did not arm)."""

    def run(tolerance: float) -> Outcome:
        result = model(tolerance=tolerance, **kwargs)
        return Outcome(result.turns if result.armed else math.nan, result.reason)

    return run
