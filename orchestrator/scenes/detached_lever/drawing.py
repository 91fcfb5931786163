"""The design of a detached-lever scene drawn as entered, before it runs.

Left: the balance seen along its staff, at its start angle THETO, on a dial of balance angle
(zero the dead point, positive counter-clockwise): the lever's windows as sectors, moving
negative on the outer ring (unlock EPIL to ALPHA, impulse ALPHA to 0 to -BETA), moving positive
on the inner ring (unlock -SIGMA to -GAMA, impulse -GAMA to 0 to AMU), and the start swing.
Right: the right-hand side of each of Monday's ten segments against balance angle, per unit
inertia as his cards have it (Table III): the Coulomb friction R(n) and the lever's forcing
X(n) at the scene's drive torque, moving negative above, moving positive below.  (The
phase-scheduled model opens its windows at the phases pi/2 - EPIL ... of the free swing; they
are drawn with the same numbers as balance angles, as Monday's Fig. 8, p. 38, draws them.)
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from components.detached_lever_design import SEGMENTS, UNLOCK, LeverDesign

_UNLOCK_COLOUR = "C3"
_IMPULSE_COLOUR = "C2"
_FRICTION_COLOUR = "0.55"
_SPAN_NAMES = {
    2: "EPIL to ALPHA",
    3: "ALPHA to 0",
    4: "0 to -BETA",
    7: "-SIGMA to -GAMA",
    8: "-GAMA to 0",
    9: "0 to AMU",
}


def segment_spans(d: LeverDesign, reach: float) -> dict[int, tuple[float, float]]:
    """Balance-angle span (from, to) of each segment in the direction of motion [rad]."""
    return {
        1: (reach, d.epsilon),
        2: (d.epsilon, d.alpha),
        3: (d.alpha, 0.0),
        4: (0.0, -d.beta),
        5: (-d.beta, -reach),
        6: (-reach, -d.sigma),
        7: (-d.sigma, -d.gamma),
        8: (-d.gamma, 0.0),
        9: (0.0, d.mu),
        10: (d.mu, reach),
    }


def draw_dial(ax: Any, d: LeverDesign, x: dict[int, float]) -> None:
    """The balance at THETO and the lever's windows on a polar dial of balance angle."""
    import numpy as np

    spans = segment_spans(d, 0.0)
    lines = []
    for s in SEGMENTS:
        if s.ratio is None:
            continue
        lo, hi = sorted(spans[s.n])
        radius = 1.0 if s.direction < 0 else 0.78
        colour = _UNLOCK_COLOUR if s.kind == UNLOCK else _IMPULSE_COLOUR
        ax.bar(
            0.5 * (lo + hi), 0.16, width=hi - lo, bottom=radius - 0.08, color=colour,
            alpha=0.5, edgecolor="k", lw=0.6,
        )  # fmt: skip
        ax.annotate(f"{s.n}", (0.5 * (lo + hi), radius), ha="center", va="center", fontsize=7)
        kind = "unlock" if s.kind == UNLOCK else "impulse"
        lines.append(f"X({s.n}) = {x[s.n]:9.4g}  {kind}, {_SPAN_NAMES[s.n]}")
    ax.text(
        0.78, -0.1, "lever windows [1/s^2]:\n" + "\n".join(lines), transform=ax.transAxes,
        fontsize=6.5, family="monospace", va="bottom",
    )  # fmt: skip
    # the balance: rim, staff and the mark of its zero, turned to THETO
    rim = np.linspace(0.0, 2.0 * math.pi, 200)
    ax.plot(rim, np.full_like(rim, 0.4), color="C0", lw=1.5)
    th = d.theta_start
    ax.plot([th, th], [0.0, 0.4], color="C0", lw=2.5, label=f"balance at THETO = {th:.4g} rad")
    ax.plot([th + math.pi, th + math.pi], [0.0, 0.4], color="C0", lw=1.0)
    swing = math.hypot(d.theta_start, d.omega_start / d.omega0)
    arc = np.linspace(-min(swing, math.pi), min(swing, math.pi), 200)
    full = " (beyond a full turn)" if swing > math.pi else ""
    ax.plot(arc, np.full_like(arc, 1.3), color="C1", lw=1.0,
            label=f"start swing ±{swing:.4g} rad{full}")  # fmt: skip
    for name, angle, radius in (
        ("EPIL", d.epsilon, 1.0), ("ALPHA", d.alpha, 1.0), ("BETA", -d.beta, 1.0),
        ("SIGMA", -d.sigma, 0.78), ("GAMA", -d.gamma, 0.78), ("AMU", d.mu, 0.78),
    ):  # fmt: skip
        ax.plot([angle, angle], [radius - 0.08, radius + 0.08], color="k", lw=0.8)
        outer = radius > 0.9
        ax.annotate(
            name, (angle, radius + 0.14 if outer else radius - 0.14), ha="center",
            va="center", fontsize=6,
        )  # fmt: skip
    ax.bar(0, 0, color=_UNLOCK_COLOUR, alpha=0.5, label="unlock (resists)")
    ax.bar(0, 0, color=_IMPULSE_COLOUR, alpha=0.5, label="impulse (drives)")
    ax.set_ylim(0.0, 1.45)
    ax.set_yticks([])
    ax.set_theta_zero_location("N")  # the dead point up
    ax.set_xticks([k * math.pi / 4 for k in range(8)])
    ax.set_xticklabels(["0", "π/4", "π/2", "3π/4", "±π", "-3π/4", "-π/2", "-π/4"])
    ax.set_title(
        "balance and lever windows: outer ring moving negative, inner ring moving positive\n"
        "(balance angle, counter-clockwise positive, dead point up; radius has no meaning)",
        fontsize=8,
    )
    ax.legend(loc="lower left", bbox_to_anchor=(-0.15, -0.12), fontsize=6.5)


def draw_forcing(axes: Any, d: LeverDesign, x: dict[int, float]) -> None:
    """R(n) and X(n) of each segment against balance angle, one axis per direction."""
    # the windows, with the free swing either side (it goes on to the extremes)
    reach = 2.0 * max(d.epsilon, d.sigma, d.beta, d.mu)
    spans = segment_spans(d, reach)
    for ax, direction in zip(axes, (-1, 1), strict=True):
        for s in (s for s in SEGMENTS if s.direction == direction):
            a, b = spans[s.n]
            r = d.r(s.n)
            ax.fill_between([a, b], [0.0, 0.0], [r, r], color=_FRICTION_COLOUR, alpha=0.4, lw=0)
            top = r
            if s.n in x:
                colour = _UNLOCK_COLOUR if s.kind == UNLOCK else _IMPULSE_COLOUR
                top = r + x[s.n]
                ax.fill_between([a, b], [r, r], [top, top], color=colour, alpha=0.45, lw=0)
            ax.plot([a, b], [top, top], color="k", lw=1.0)
            label_y = top if abs(top) >= abs(r) else r
            ax.annotate(
                f"{s.n}", (0.5 * (a + b), label_y), textcoords="offset points",
                xytext=(0, 4 if label_y >= 0 else -10), ha="center", fontsize=7,
            )  # fmt: skip
        ax.axhline(0.0, color="k", lw=0.5)
        ax.axvline(0.0, color="k", lw=0.5, ls=":")
        ax.set_xlim(-reach, reach)
        if direction < 0:
            ax.invert_xaxis()  # drawn in the direction of motion
        word = "negative" if direction < 0 else "positive"
        ax.set_title(
            f"moving {word}: segments {'1-5' if direction < 0 else '6-10'} "
            "(grey R(n), colour X(n); line R(n) + X(n))",
            fontsize=8,
        )
        ax.set_ylabel("torque / I [1/s^2]")
    axes[-1].set_xlabel("balance angle [rad], in the direction of motion (1, 5, 6, 10 go on)")


def draw_design(d: LeverDesign, drive_torque: float, path: Path, title: str) -> None:
    """Dial and forcing side by side, written as a PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    x = {n: ratio * drive_torque / d.inertia for n, ratio in d.ratio.items()}
    fig = plt.figure(figsize=(14, 7))
    grid = fig.add_gridspec(2, 2, width_ratios=(1.25, 1.0))
    dial = fig.add_subplot(grid[:, 0], projection="polar")
    draw_dial(dial, d, x)
    forcing = [fig.add_subplot(grid[0, 1]), fig.add_subplot(grid[1, 1])]
    draw_forcing(forcing, d, x)
    mode = "phase-scheduled" if d.switching_mode == 0 else "angle-switched"
    fig.suptitle(
        f"{title}\n{mode}; OMEGO {d.omega0:.5g} rad/s, C {d.viscous / d.inertia:.4g} 1/s, "
        f"drive torque {drive_torque:.4g} N.m",
        fontsize=10,
    )
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def draw(scene: Any, path: Path) -> None:
    """The scene's lever design (``mechcosim draw``)."""
    from orchestrator.scenes.detached_lever.design import scene_design
    from orchestrator.scenes.detached_lever.lever import lever_scene

    lever = lever_scene(scene)
    draw_design(
        scene_design(scene, lever.instance),
        lever.drive_torque,
        Path(path),
        f"{scene.name}: the lever design as entered ({lever.instance})",
    )
