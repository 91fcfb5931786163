"""The design of a press feed drawn to scale, as entered, at the start position.

The RSSR linkage (Xu 1993, App. A frame: crank axis X0 through O1, rocker axis parallel
to Y0 through O2 = (-s1, -s2, -s3)) at the crank angle where the rocker is at its extreme
(the scenes start there), in two orthographic views: along the crank axis (Y0-Z0 plane) and
along the rocker axis (X0-Z0 plane); the bent coupler A-B-C with its bend B.  Right: the
sprag clutch (Table 4): inner and outer race contact circles and one sprag, its two
contact profiles (radius R_s, curvature centres a apart) touching both races.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from components.coupler_inertia import coupler_frame
from components.press_feed_data import TABLE4, BentCoupler, RSSRLinkage, SpragGeometry
from components.rssr_kinematics import ExactRSSR, rocker_extremes
from components.units import INCH

_IN = 1.0 / INCH  # drawn lengths are in inches, the unit of Table 1


def linkage_points(lk: RSSRLinkage, c: BentCoupler, phi1: float) -> dict[str, np.ndarray]:
    """O1, A, B, C, O2 in the frame O1 X0 Y0 Z0 [m] at a crank angle (rigid coupler)."""
    r_a, i1, j1 = coupler_frame(lk, c.alpha, np.array([phi1]), 0.0)
    a, e1, f1 = r_a[:, 0], i1[:, 0], j1[:, 0]
    chord = (
        c.length * (1.0 + math.cos(2.0 * c.alpha)) * e1 + c.length * math.sin(2.0 * c.alpha) * f1
    )
    return {
        "O1": np.zeros(3),
        "A": a,
        "B": a + c.length * e1,
        "C": a + chord * lk.a3 / np.linalg.norm(chord),
        "O2": np.array([-lk.s1, -lk.s2, -lk.s3]),
    }


def draw_view(ax: Any, pts: dict[str, np.ndarray], lk: RSSRLinkage, axes: tuple[int, int]) -> None:
    """One orthographic view of the linkage: the crank, coupler and rocker [in]."""
    names = "XYZ"
    h, v = axes

    def xy(p: np.ndarray) -> tuple[float, float]:
        return p[h] * _IN, p[v] * _IN

    def line(p: str, q: str, **style: Any) -> None:
        (x0, y0), (x1, y1) = xy(pts[p]), xy(pts[q])
        ax.plot([x0, x1], [y0, y1], **style)

    line("O1", "A", color="C0", lw=3, label=f"crank a1 = {lk.a1 * _IN:.3f} in")
    line("A", "B", color="C1", lw=2, label="coupler A-B-C (bend B)")
    line("B", "C", color="C1", lw=2)
    line("A", "C", color="C1", lw=0.6, ls=":", label=f"chord a3 = {lk.a3 * _IN:.3f} in")
    line("O2", "C", color="C2", lw=3, label=f"rocker a4 = {lk.a4 * _IN:.3f} in")
    for name, p in pts.items():
        x, y = xy(p)
        ax.plot(x, y, "ko", ms=3)
        ax.annotate(name, (x, y), textcoords="offset points", xytext=(4, 4), fontsize=8)
    if axes == (1, 2):  # along the crank axis: the crank circle
        t = np.linspace(0.0, 2.0 * math.pi, 181)
        ax.plot(lk.a1 * _IN * np.cos(t), lk.a1 * _IN * np.sin(t), color="C0", lw=0.6, ls="--")
    if axes == (0, 2):  # along the rocker axis: the rocker circle
        t = np.linspace(0.0, 2.0 * math.pi, 181)
        cx, cy = xy(pts["O2"])
        ax.plot(cx + lk.a4 * _IN * np.sin(t), cy + lk.a4 * _IN * np.cos(t), color="C2", lw=0.6,
                ls="--")  # fmt: skip
    ax.set_xlabel(f"{names[h]}0 [in]")
    ax.set_ylabel(f"{names[v]}0 [in]")
    ax.set_aspect("equal")
    ax.grid(True, lw=0.3)


def sprag_centres(s: SpragGeometry) -> tuple[np.ndarray, np.ndarray]:
    """Curvature centres of the sprag's inner and outer contact profiles [m]: at R_i + R_s
    and R_o - R_s from the race centre, a apart (L.18-L.19)."""
    r_in, r_out = s.r_inner + s.r_sprag, s.r_outer - s.r_sprag
    cos_t = (r_in**2 + r_out**2 - s.offset**2) / (2.0 * r_in * r_out)
    theta = math.acos(max(-1.0, min(1.0, cos_t)))
    return np.array([0.0, r_in]), r_out * np.array([math.sin(theta), math.cos(theta)])


def draw_clutch(ax: Any, s: SpragGeometry) -> None:
    """Race contact circles and one sprag with its two contact profiles [in]."""
    t = np.linspace(0.0, 2.0 * math.pi, 361)
    for r, name, colour in (
        (s.r_inner, "inner race R_i", "C0"),
        (s.r_outer, "outer race R_o", "C2"),
    ):
        ax.plot(r * _IN * np.cos(t), r * _IN * np.sin(t), color=colour,
                label=f"{name} = {r * _IN:.4f} in")  # fmt: skip
    c_in, c_out = sprag_centres(s)
    arc = np.linspace(-0.5, 0.5, 61)
    # Inner profile: around the direction from its centre towards the race centre.
    d_in = math.atan2(-c_in[1], -c_in[0])
    p_in = c_in[:, None] + s.r_sprag * np.stack([np.cos(d_in + arc), np.sin(d_in + arc)])
    d_out = math.atan2(c_out[1], c_out[0])
    p_out = c_out[:, None] + s.r_sprag * np.stack([np.cos(d_out + arc), np.sin(d_out + arc)])
    outline = np.concatenate([p_in, p_out, p_in[:, :1]], axis=1) * _IN
    label = f"sprag: R_s = {s.r_sprag * _IN:.4f} in, a = {s.offset * _IN:.4f} in"
    ax.fill(outline[0], outline[1], color="C1", alpha=0.5, label=label)
    for c in (c_in, c_out):
        ax.plot(c[0] * _IN, c[1] * _IN, "k+", ms=6)
    ax.plot(0.0, 0.0, "k+", ms=8)
    ax.set_aspect("equal")
    ax.set_xlabel("[in]")
    ax.grid(True, lw=0.3)


def draw_design(lk: RSSRLinkage, c: BentCoupler, s: SpragGeometry, path: Path, title: str) -> None:
    """Both linkage views and the clutch, written as a PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    phi1 = rocker_extremes(ExactRSSR(lk, c.alpha))[1]
    pts = linkage_points(lk, c, phi1)
    fig = plt.figure(figsize=(14, 7.5))
    grid = fig.add_gridspec(1, 3, width_ratios=(1.0, 1.0, 0.9))
    front, side, clutch = (fig.add_subplot(grid[0, k]) for k in range(3))
    draw_view(front, pts, lk, (1, 2))
    front.set_title("along the crank axis X0", fontsize=9)
    draw_view(side, pts, lk, (0, 2))
    side.set_title("along the rocker axis Y0", fontsize=9)
    side.legend(fontsize=7, loc="lower right")
    draw_clutch(clutch, s)
    clutch.set_title(f"sprag clutch, Z = {s.n_sprags} sprags (one drawn)", fontsize=9)
    clutch.legend(fontsize=7, loc="lower center")
    fig.suptitle(
        f"{title}\nstart: crank phi1 = {math.degrees(phi1):.2f} deg (rocker extreme); "
        f"coupler L = {c.length * _IN:.3f} in, alpha = {math.degrees(c.alpha):.2f} deg, "
        f"D_o / D_i = {c.d_outer * _IN:.3f} / {c.d_inner * _IN:.3f} in",
        fontsize=10,
    )
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def draw(scene: Any, path: Path) -> None:
    """The scene's design (``mechcosim draw``)."""
    from orchestrator.scenes.press_feed.design import scene_design

    d = scene_design(scene)
    if d.linkage is None or d.coupler is None:
        raise ValueError(f"press feed scene {scene.name}: no CrankCouplerDrive to draw")
    sprag = d.sprag or _clutch_geometry(scene)
    draw_design(d.linkage, d.coupler, sprag, Path(path), f"{scene.name}: the design, to scale")


def _clutch_geometry(scene: Any) -> SpragGeometry:
    """The clutch's Table 4 geometry as the scene gives it (also for the lumped model)."""
    from dataclasses import replace

    for spec in scene.fmus.values():
        if spec.component == "SpragClutch":
            p = spec.parameters
            return replace(
                TABLE4,
                r_outer=p.get("r_outer", TABLE4.r_outer),
                r_inner=p.get("r_inner", TABLE4.r_inner),
                r_sprag=p.get("r_sprag", TABLE4.r_sprag),
                offset=p.get("sprag_offset", TABLE4.offset),
                n_sprags=int(p.get("n_sprags", TABLE4.n_sprags)),
            )
    return TABLE4
