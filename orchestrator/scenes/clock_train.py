"""The clock-train S&A scenes: the M739 verge escapement behind a two-pass clock gear train.

Two FMUs meet at the escape-wheel shaft: ``train`` (ClockGearTrain: the M739 spin-driven rotor
and the clock train of ``components.clock_train``) and ``verge`` (VergeEscapement, with its
escapement centre distance as a parameter).  Arming is the rotor's: the run stops when the rotor
has turned as far as the M739's does to arm (``scene.stop_when`` on ``train.rotor_angle``;
1485 deg of escape wheel over 32 on the M739).  The clock ratio ripples, so the escape-wheel
angle at arming differs a little from 1485 deg; it is reported.

``reference`` is the monolithic model of the same physics: the verge regime machine with the
live clock-train physics (``ClockTrainPhysics``) in place of the held affine response, one ODE
with every event located (the structure of ``orchestrator.references.m739``), and the tooth
handover impact there including the verge inertia exactly when the verge is coupled.
Instance names come from ``[report.options]`` (defaults "train" and "verge").
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from components.clock_gear_train import LOSS_POINT, ClockTrainPhysics
from components.clock_train import M739_TRAIN
from components.m739_data import M739, rpm_to_rad_s
from components.verge_escapement import (
    FREE,
    IND_MESH_HI,
    IND_MESH_LO,
    VergeConstants,
    escapement_data,
)
from components.verge_geometry import kinem
from orchestrator.references import Reference
from orchestrator.references.m739 import REFERENCE_TOLERANCE, M739Result, _Monolithic, simulate
from orchestrator.scenario import Scene
from orchestrator.scenes.m739 import (
    _names,
    _parameter,
    _q,
    _why_not_armed,
    escapement_figure,
    reference_from,
    save_figure,
)

RPM_PER_RAD_S = 60.0 / (2.0 * math.pi)
#: Rotor angle at arming: the M739's rotor travel, PHICUTD of escape wheel times N31 (= 1/32).
ARMING_ROTOR_ANGLE = M739.phi1c + M739.n31 * M739.phi_cut


def _arming(scene: Scene, train: str) -> tuple[str, float, bool]:
    """(signal column, threshold, rising) of the arming condition."""
    cond = scene.stop_when
    if cond is not None:
        return ".".join(cond.signal), cond.threshold, cond.rising
    return f"{train}.rotor_angle", ARMING_ROTOR_ANGLE, True


def _crossing(t: np.ndarray, x: np.ndarray, level: float, rising: bool) -> float | None:
    """First time x reaches level (linear within the step a fixed-step master overshoots)."""
    hit = np.nonzero(x >= level if rising else x <= level)[0]
    if not len(hit):
        return None
    k = int(hit[0])
    if k == 0 or x[k] == level:
        return float(t[k])
    return float(t[k - 1] + (t[k] - t[k - 1]) * (level - x[k - 1]) / (x[k] - x[k - 1]))


def analyse(
    scene: Scene, header: list[str], data: np.ndarray, options: dict[str, Any]
) -> dict[str, Any]:
    """Turns to arm (or why not), escape-wheel angle at arming, force maxima, impacts,
    tooth handovers."""
    train, verge = _names(scene)
    col = {name: data[:, i] for i, name in enumerate(header)}
    t = col["time"]
    spin = _parameter(scene, train, "spin")
    signal, level, rising = _arming(scene, train)
    out: dict[str, Any] = {}
    t_arm = _crossing(t, col[signal], level, rising) if signal in col else None
    if t_arm is not None:
        out["armed"] = _q(1.0, "1")
        out["arming_time"] = _q(t_arm, "s")
        out["turns_to_arm"] = _q(t_arm * abs(spin) / (2.0 * math.pi), "1")
        out["phi_at_arming"] = _q(float(np.interp(t_arm, t, col[f"{train}.phi"])), "rad")
    else:
        out["armed"] = _q(0.0, "1")
        out["not_armed_reason"] = {"value": _why_not_armed(scene, col, train), "unit": ""}
    coupled = col[f"{verge}.regime"] != FREE
    for name, mask in (("F23", coupled), ("F12", coupled), ("FF23", ~coupled), ("FF12", ~coupled)):
        source = col[f"{train}.{name}"]  # F*: coupled motion, FF*: free motion (as the M739's)
        out[f"{name}_max"] = _q(float(np.max(source[mask])) if mask.any() else 0.0, "N")
    out["PN_max"] = _q(float(np.max(col[f"{verge}.PN"])), "N")
    out["impacts"] = _q(float(col[f"{verge}.impact_count"][-1]), "1")
    if f"{train}.handovers" in col:
        out["handovers"] = _q(float(col[f"{train}.handovers"][-1]), "1")
    return out


# ------------------------------------------------------------------------------------------
# Monolithic reference
# ------------------------------------------------------------------------------------------
class _ClockMonolithic(_Monolithic):
    """The M739 monolithic verge with the live clock-train physics.

    A tooth handover of the train is an inelastic impact of the new pair: its speed map takes
    the verge inertia along while the verge rides on the wheel (I_p U^2), exactly.
    """

    def event(self, y: list[float], index: int, t: float) -> list[float]:
        tr = self.train
        tr.locate(y[0])  # reflected inertia at this point, for an impact of the verge
        if index not in (IND_MESH_HI, IND_MESH_LO):
            return super().event(y, index, t)
        j_load = 0.0
        if self.coupled:
            k = self.k
            u = kinem(y[0] + self.phi_off, self.alpha, k.a, k.b, k.c)[2]
            j_load = k.ip * u * u
        w, _ = tr.cross(y[0], y[1], j_load)
        y = [y[0], w, y[2], y[3], y[4]]
        if self.coupled:
            y = self._sync_kinematics(y)
        self.record(y)
        return y


def arming_phi(phys: ClockTrainPhysics, rotor_angle: float = ARMING_ROTOR_ANGLE) -> float:
    """Cumulative escape-wheel angle at which the rotor reaches rotor_angle (forward kinematics
    of the train, note §4-5)."""
    theta1 = phys.theta1_0 + (rotor_angle - phys.phi1c)
    return M739_TRAIN.escape_angle(theta1) - phys.psi0


def run_clock_train(
    mu: float = M739.mu,
    mu1: float = M739.mu1,
    rpm: float = M739.rpm,
    e_rest: float = M739.e_rest,
    t_stop: float = 0.2,
    loss_model: int = LOSS_POINT,
    pivot_loads: bool = True,
    mesh_phase: float = 0.0,
    center_distance: float = M739.a,
    pallet_inertia: float = M739.ip,
    rotor_arming_angle: float = ARMING_ROTOR_ANGLE,
    tolerance: float = REFERENCE_TOLERANCE,
    sample_dt: float = 1.0e-5,
) -> M739Result:
    """Simulate the clock-train S&A from rest on the entrance face until arming or t_stop.

    Same outcome record as ``run_m739`` (turns, force maxima with F12/F23 the mesh normal
    forces, impacts, regime log, series); it never raises.
    """
    omega = rpm_to_rad_s(rpm)
    data = escapement_data(center_distance, pallet_inertia=pallet_inertia)
    events: list[tuple[float, int, int, str]] = []

    def log(t: float, old: int, new: int, why: str) -> None:
        events.append((t, old, new, why))

    train = ClockTrainPhysics(
        M739_TRAIN,
        M739,
        mu=mu,
        omega=omega,
        loss_model=loss_model,
        pivot_loads=pivot_loads,
        mesh_phase=mesh_phase,
    )
    phi_stop = arming_phi(train, rotor_arming_angle)
    k = VergeConstants(data, mu1, mu, omega, e_rest)
    core = _ClockMonolithic(k, train, data.phi_start, phi_stop=phi_stop, log=log)
    result = simulate(core, data, events, t_stop, tolerance, sample_dt)
    result.handovers = train.handovers  # type: ignore[attr-defined]
    return result


def reference(scene: Scene) -> Reference:
    """The monolithic clock-train S&A with the scene's physics, as the yardstick."""
    train, verge = _names(scene)
    spin = _parameter(scene, train, "spin")
    signal, level, _ = _arming(scene, train)
    if signal != f"{train}.rotor_angle":
        raise ValueError(
            f"clock_train reference: arming must be scene.stop_when on {train}.rotor_angle"
        )
    result = run_clock_train(
        mu=_parameter(scene, train, "mu"),
        mu1=_parameter(scene, verge, "mu1"),
        rpm=spin * RPM_PER_RAD_S,
        e_rest=_parameter(scene, verge, "e_rest"),
        t_stop=scene.stop,
        loss_model=int(_parameter(scene, train, "loss_model")),
        pivot_loads=_parameter(scene, train, "pivot_loads") == 1.0,
        mesh_phase=_parameter(scene, train, "mesh_phase"),
        center_distance=_parameter(scene, verge, "center_distance"),
        pallet_inertia=_parameter(scene, verge, "pallet_inertia"),
        rotor_arming_angle=level,
    )
    ref = reference_from(result, train, verge)
    if result.armed:
        ref.headline["phi_at_arming"] = result.phi_end
    return ref


def plot(scene: Scene, header: list[str], data: np.ndarray, path: Path) -> None:
    """Verge and escape-wheel motion over the first cycles, with the train's speed ratio and
    mesh efficiencies."""
    train, _ = _names(scene)
    fig, axes, (ms, col) = escapement_figure(scene, header, data, extra_panels=1)
    if f"{train}.speed_ratio" in col:
        axes[3].plot(ms, col[f"{train}.speed_ratio"], label="speed ratio (wheel/rotor)")
        axes[3].set_ylabel("speed ratio [1]")
        if f"{train}.efficiency1" in col:
            ax3 = axes[3].twinx()
            for i, c in ((1, "C2"), (2, "C3")):
                ax3.plot(ms, col[f"{train}.efficiency{i}"], color=c, label=f"mesh {i} efficiency")
            ax3.set_ylabel("point efficiency [1]")
            ax3.legend(loc="lower right")
        axes[3].legend(loc="upper right")
    title = f"{scene.name}: verge, escape wheel and clock train, first cycles"
    save_figure(fig, title, path)
