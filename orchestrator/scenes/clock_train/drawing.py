"""The design of a clock-train S&A drawn to scale, as entered, before it runs.

Left and middle: the two clock meshes in contact at the start (report 003, Task 2: gear tip
rounds rho_G centred a_G from the gear pivot; pinion leaves with the radial flank along
phi_P + alpha_P up to f_P and the leaf round rho_P), each in its own frame, gear pivot at the
origin and pinion pivot at b along beta; the pair in contact and its contact point as the
train's kinematics put them at the scene's start (``mesh_phase``, ``phi_start``).  The source
models the gear tooth by its tip round and the leaf by its working flank and round: what
lies beyond (the gear tooth's body, the back of a leaf) is not drawn, the rest of each leaf
round's circle dotted.
Right: the escapement at the start (``orchestrator.scenes.m739.drawing.draw_escapement``).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from components.clock_gear_train import ClockTrainPhysics
from components.clock_train_design import body_data, clock_train
from components.clock_train_kinematics import ClockMesh
from components.units import DEG, INCH
from orchestrator.scenes.m739.drawing import draw_escapement

_IN = 1.0 / INCH
#: Points per round arc of an outline.
_ARC = 24


def _arc(cx: float, cy: float, r: float, a0: float, a1: float) -> list[tuple[float, float]]:
    return [
        (cx + r * math.cos(a0 + (a1 - a0) * k / _ARC), cy + r * math.sin(a0 + (a1 - a0) * k / _ARC))
        for k in range(_ARC + 1)
    ]


def gear_rounds(m: ClockMesh, v: float) -> list[tuple[float, float]]:
    """Centres of every gear tooth's tip round at gear angle v (mesh-1 convention) [m]."""
    out = []
    for j in range(m.n_gear):
        c = v - j * m.gear_pitch - m.delta_g  # next teeth at -2 pi/N_G (eqs. 41-45)
        out.append((m.a_g * math.cos(c), m.a_g * math.sin(c)))
    return out


def pinion_profiles(
    m: ClockMesh, x: float
) -> list[tuple[list[tuple[float, float]], list[tuple[float, float]]]]:
    """Every pinion leaf at pinion angle x (mesh-1 convention): (working profile, rest of its
    round) [m].  The working profile is the radial flank (direction x + alpha_P) from the root
    circle up to f_P and the leaf round from there over the tip; the back of the leaf is not
    in the source's model (only its round's circle is drawn)."""
    ox, oy = m.b * math.cos(m.beta1), m.b * math.sin(m.beta1)
    root = max(min(m.b - m.a_g - m.rho_g, m.f_p) - 0.5 * m.rho_p, 0.2 * m.f_p)
    out = []
    for j in range(m.n_pinion):
        e = x + j * m.pinion_pitch + m.alpha_p  # next leaves at +2 pi/N_P
        c = e - math.atan2(m.rho_p, m.f_p)  # direction of the round's centre: x - delta_P
        cx, cy = ox + m.a_p * math.cos(c), oy + m.a_p * math.sin(c)
        work = [(ox + root * math.cos(e), oy + root * math.sin(e))]
        work += _arc(cx, cy, m.rho_p, e + 0.5 * math.pi, c - 0.5 * math.pi)
        rest = _arc(cx, cy, m.rho_p, c - 0.5 * math.pi, e + 0.5 * math.pi - 2.0 * math.pi)
        out.append((work, rest))
    return out


def draw_mesh(ax: Any, phys: ClockTrainPhysics, i: int, phi: float) -> None:
    """Mesh i (0, 1) of the train at cumulative escape-wheel angle phi, in its own frame [in]."""
    import matplotlib.patches as patches

    m = phys.meshes[i]
    ev = phys.evaluate(phi)
    k, phase, _ = phys.pieces[i]
    x = ev[6 + i]
    v = m._pair_inverse(x, phase)[0]
    flip = -1.0 if m.mirrored else 1.0  # mesh 2 is the mirror image of the mesh-1 convention

    def to_in(pts: list[tuple[float, float]]) -> list[tuple[float, float]]:
        return [(px * _IN, flip * py * _IN) for px, py in pts]

    for j, (gx, gy) in enumerate(gear_rounds(m, v)):
        ax.add_patch(
            patches.Circle(
                (gx * _IN, flip * gy * _IN), m.rho_g * _IN, fill=False, color="C0", lw=0.8,
                label="gear tip rounds" if j == 0 else None,
            )
        )  # fmt: skip
    for j, (work, rest) in enumerate(pinion_profiles(m, x)):
        wx, wy = zip(*to_in(work), strict=True)
        rx, ry = zip(*to_in(rest), strict=True)
        ax.plot(wx, wy, color="C1", lw=0.9, label="pinion flank and round" if j == 0 else None)
        ax.plot(rx, ry, color="C1", lw=0.5, ls=":")
    cx, cy, _, _ = m.contact(x, v, phase)
    ox, oy = m.b * math.cos(m.beta1), m.b * math.sin(m.beta1)
    ax.plot([0.0, ox * _IN], [0.0, flip * oy * _IN], "k:", lw=0.6)
    ax.plot([0.0, ox * _IN], [0.0, flip * oy * _IN], "k+", ms=8)
    ax.plot([cx * _IN], [flip * cy * _IN], "o", color="k", ms=4, label="contact at the start")
    names = (("gear 1", "pinion 2"), ("gear 2", "pinion 3"))[i]
    ax.annotate(names[0], (0, 0), textcoords="offset points", xytext=(-14, -12), fontsize=7)
    ax.annotate(names[1], (ox * _IN, flip * oy * _IN), textcoords="offset points",
                xytext=(4, -12), fontsize=7)  # fmt: skip
    ax.set_title(
        f"mesh {i + 1}: {m.n_gear}:{m.n_pinion}, b = {m.b * _IN:.4f} in, pair {k} "
        f"{'round on round' if phase == 'ror' else 'round on flank'}",
        fontsize=8,
    )
    # Frame the contact region: the pinion and the gear's rim near it.
    span = 1.3 * (m.a_p + m.rho_p) * _IN
    mx, my = 0.5 * (ox + cx) * _IN, flip * 0.5 * (oy + cy) * _IN
    ax.set_xlim(mx - 1.6 * span, mx + 1.6 * span)
    ax.set_ylim(my - 1.2 * span, my + 1.2 * span)
    ax.set_aspect("equal")
    ax.set_xlabel("[in]")
    ax.legend(loc="lower left", fontsize=6)


def draw_design(
    values: dict[str, float], verge: Any, path: Path, title: str, mesh_phase: float = 0.0,
    phi_start: float = 0.0,
) -> None:  # fmt: skip
    """The two meshes and the escapement side by side, written as a PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    phys = ClockTrainPhysics(clock_train(values), body_data(values), mesh_phase=mesh_phase)
    phys.set_mode(phi_start, 1)
    fig, axes = plt.subplots(1, 3, figsize=(17, 6.0))
    for i in (0, 1):
        draw_mesh(axes[i], phys, i, phi_start)
    draw_escapement(axes[2], verge)
    fig.suptitle(
        f"{title}\ncluster phasing kappa2 = {phys.kappa2 / DEG:.3f} deg, "
        f"mesh phase {mesh_phase / DEG:.3f} deg"
    )
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def draw(scene: Any, path: Path) -> None:
    """The scene's design (``mechcosim draw``)."""
    from orchestrator.scenes.clock_train.design import train_values, verge_data
    from orchestrator.scenes.m739.design import instances, parameter

    train, _ = instances(scene)
    draw_design(
        train_values(scene),
        verge_data(scene),
        Path(path),
        f"{scene.name}: the design as entered, to scale",
        mesh_phase=parameter(scene, train, "mesh_phase"),
        phi_start=parameter(scene, train, "phi_start"),
    )
