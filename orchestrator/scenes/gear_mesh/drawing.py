"""A gear-mesh scene's pair drawn in mesh, to scale (millimetres), at the scene's start angle.

Involute pair (Tepper 1981, Figs. 7-8): the operating pitch, base and outside circles of both
members at their centres, the involute flanks of a few teeth on each side of the contact (each
tooth the standard thickness pi / (2 Pd) at the standard pitch circle, from the base circle to
the tip), the line of action between the base-tangent points T' and T, the path of contact and
the contact points of the pairs in contact.  Clock mesh: the pitch circles (for the M739-like
train meshes, the centre distance split in the tooth ratio), the tooth and leaf rounds of a few
teeth on each side of the contact, the pinion flanks, and the contact point with its normal.
Left: the whole pair; right: the contact region enlarged.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from components.gear_mesh import ClockModel, ClockTableModel, InvoluteModel, MeshModel
from components.mesh_efficiency import train_mesh_contact
from orchestrator.scene_model import Scene
from orchestrator.scenes.gear_mesh.report import mesh_scene

MM = 1e3  # drawing units per metre
GEAR, PINION, ACTION = "C0", "C3", "C2"


def _inv(x: float) -> float:
    return math.tan(x) - x


def _involute_tooth(
    centre: np.ndarray, rb: float, r_out: float, r_in: float, beta0: float, half_base: float
) -> np.ndarray:
    """Outline of one involute tooth (mm): the flank that leaves the base circle at angle
    beta0 (the point of a string unwound counter-clockwise: tangent point at beta0 + t, point
    at polar angle beta0 + t - atan t), the tip arc, and the mirrored flank; half_base: the
    tooth's half angle at the base circle (the tooth lies counter-clockwise of this flank)."""
    t_lo = math.sqrt(max(r_in * r_in / (rb * rb) - 1.0, 0.0))
    t_hi = math.sqrt(r_out * r_out / (rb * rb) - 1.0)
    t = np.linspace(t_lo, t_hi, 40)
    radius = rb * np.sqrt(1.0 + t * t)
    polar = beta0 + t - np.arctan(t)  # polar angle of the flank point
    mid = beta0 + half_base  # tooth centreline
    mirror = 2.0 * mid - polar
    tip = np.linspace(polar[-1], mirror[-1], 12)
    angles = np.concatenate([polar, tip, mirror[::-1]])
    radii = np.concatenate([radius, np.full(12, r_out), radius[::-1]])
    return MM * (centre[:, None] + radii * np.array([np.cos(angles), np.sin(angles)])).T


def _circle(ax, centre, radius: float, color: str, style: str, label: str | None = None):
    from matplotlib.patches import Circle

    c = Circle(tuple(MM * np.asarray(centre)), MM * radius, fill=False, ec=color, ls=style,
               lw=0.8, label=label)  # fmt: skip
    ax.add_patch(c)
    return c


def _draw_involute(axes, m: InvoluteModel, theta: float) -> str:
    g, pair = m.geometry, m.pair
    op, rb, big_rb = g.op_pressure_angle, g.pinion_base_radius, g.gear_base_radius
    cd = pair.center_distance
    o_p, o_g = np.zeros(2), np.array([cd, 0.0])
    u = np.array([math.sin(op), -math.cos(op)])  # line of action, T' -> T
    t_pin = rb * np.array([math.cos(op), math.sin(op)])
    d = g.d
    s_gear = math.sqrt(pair.gear_outside_radius**2 - big_rb**2)
    s_pin = math.sqrt(pair.pinion_outside_radius**2 - rb**2)
    s_form = math.sqrt(max(g.form_radius**2 - rb**2, 0.0))
    s_lo, s_hi = max(d - s_gear, s_form), min(s_pin, d)  # path of contact, from T'
    alpha = g.alpha_in + (theta - g.alpha_in) % g.cycle_angle
    pb = g.base_pitch
    if g.pinion_drives:
        s1, lead = rb * alpha, pb
    else:
        s1, lead = d - big_rb * alpha, -pb
    pd = pair.diametral_pitch / 0.0254  # 1/m
    thickness = math.pi / (2.0 * pd)  # standard tooth thickness at the standard pitch circle
    phi = pair.pressure_angle
    n_gear = round(2.0 * pd * pair.gear_pitch_radius)
    members = (
        (o_p, rb, pair.pinion_outside_radius, pair.pinion_pitch_radius, g.pinion_op_pitch_radius,
         pair.n_pinion, PINION, "pinion", op - s1 / rb),
        (o_g, big_rb, pair.gear_outside_radius, pair.gear_pitch_radius, g.gear_op_pitch_radius,
         n_gear, GEAR, "gear", math.pi + op - (d - s1) / big_rb),
    )  # fmt: skip
    for ax in axes:
        for centre, r_b, r_o, r_std, r_op, n, color, who, beta0 in members:
            _circle(ax, centre, r_op, color, "--", f"{who} operating pitch circle")
            _circle(ax, centre, r_b, color, ":", f"{who} base circle")
            _circle(ax, centre, r_o, color, "-", f"{who} outside circle")
            half = thickness / (2.0 * r_std) + _inv(phi)
            r_root = max(r_std - 1.25 / pd, 0.2 * r_b)
            for j in range(-3, 4):
                xy = _involute_tooth(centre, r_b, r_o, max(r_b, r_root),
                                     beta0 + j * 2.0 * math.pi / n, half)  # fmt: skip
                ax.fill(xy[:, 0], xy[:, 1], color=color, alpha=0.15, lw=0)
                ax.plot(xy[:, 0], xy[:, 1], color=color, lw=1.0)
            _circle(ax, centre, max(r_b, r_root), color, "-", None).set_lw(0.4)
            ax.plot(*(MM * centre), "+", color=color, ms=8)
        ends = np.array([t_pin, t_pin + d * u]) * MM
        ax.plot(ends[:, 0], ends[:, 1], color=ACTION, lw=0.8, label="line of action T'T")
        path = np.array([t_pin + s_lo * u, t_pin + s_hi * u]) * MM
        ax.plot(path[:, 0], path[:, 1], color=ACTION, lw=3, alpha=0.5, label="path of contact")
        for s in (s1 - lead, s1, s1 + lead):
            if s_lo - 1e-12 <= s <= s_hi + 1e-12:
                c = (t_pin + s * u) * MM
                ax.plot(c[0], c[1], "o", color="k", ms=4)
        p = np.array([g.pinion_op_pitch_radius * MM, 0.0])
        ax.plot(p[0], p[1], "x", color="k", ms=6)
    zoom = 1.6 * max(pair.pinion_outside_radius - rb, pair.gear_outside_radius - big_rb, pb)
    axes[1].set_xlim(MM * (g.pinion_op_pitch_radius - zoom), MM * (g.pinion_op_pitch_radius + zoom))
    axes[1].set_ylim(-MM * zoom, MM * zoom)
    axes[0].set_xlim(
        -MM * 1.1 * pair.pinion_outside_radius, MM * (cd + 1.1 * pair.gear_outside_radius)
    )
    r = MM * 1.1 * max(pair.gear_outside_radius, pair.pinion_outside_radius)
    axes[0].set_ylim(-r, r)
    driver = "pinion" if g.pinion_drives else "gear"
    return (
        f"contact ratio {g.contact_ratio:.3f}, operating pressure angle "
        f"{math.degrees(op):.2f} deg, {driver} drives; dots: contact points, x: pitch point"
    )


def _clock_pieces(m: MeshModel, theta: float):
    """(gear pivot, pinion pivot, R_G, R_P, gear rounds, pinion rounds, flanks, contact, normal)
    in metres: rounds as (centre, radius, axis) of a few teeth each side of the contact."""
    if isinstance(m, ClockTableModel):
        model, mesh = m.model, m.model.mesh
        c = model.contact(theta)
        o_p = model.o_p
        gear, pinion, flanks = [], [], []
        leaf = c.pinion_angle - c.pair * model.pitch_p
        for j in range(-3, 4):
            tooth = theta + (c.pair + j) * model.pitch_g
            for side in (-1.0, 1.0):
                centre = mesh.gear_center_distance * _unit(tooth + side * model.delta_g)
                gear.append((centre, mesh.gear_arc_radius, _unit(tooth), -side))
                edge = centre - side * mesh.gear_arc_radius * _perp(_unit(tooth))
                flanks.append((edge - mesh.gear_arc_radius * _unit(tooth), edge, GEAR))
            ang = leaf + j * model.pitch_p
            for side in (-1.0, 1.0):
                centre = o_p + mesh.pinion_center_distance * _unit(ang + side * model.delta_p)
                pinion.append((centre, mesh.pinion_arc_radius, _unit(ang), -side))
                # straight flank below the arc centre, at t/2 from the centreline
                edge = centre - side * mesh.pinion_arc_radius * _perp(_unit(ang))
                flanks.append((edge - 0.4 * mesh.pinion_pitch_radius * _unit(ang), edge, PINION))
        return (np.zeros(2), o_p, mesh.gear_pitch_radius, mesh.pinion_pitch_radius, gear, pinion,
                flanks, c.contact, c.normal)  # fmt: skip
    assert isinstance(m, ClockModel)
    mesh = m.mesh
    c = train_mesh_contact(mesh, theta)
    o_p = c.pinion_pivot
    lead_g, lead_p = 2.0 * math.pi / mesh.n_gear, 2.0 * math.pi / mesh.n_pinion
    x = c.pinion_angle
    gear, pinion, flanks = [], [], []
    for j in range(-3, 4):
        tooth = c.local_angle + j * lead_g
        gear.append((mesh.a_g * _unit(tooth - mesh.delta_g), mesh.rho_g, None, 0.0))
        ang = x + j * lead_p
        pinion.append((o_p + mesh.a_p * _unit(ang - mesh.delta_p), mesh.rho_p, None, 0.0))
        e = _unit(ang + mesh.alpha_p)
        flanks.append((o_p + 0.3 * mesh.f_p * e, o_p + mesh.f_p * e, PINION))
    r_g = mesh.b * mesh.n_gear / (mesh.n_gear + mesh.n_pinion)
    return np.zeros(2), o_p, r_g, mesh.b - r_g, gear, pinion, flanks, c.contact, c.normal


def _unit(a: float) -> np.ndarray:
    return np.array([math.cos(a), math.sin(a)])


def _perp(e: np.ndarray) -> np.ndarray:
    return np.array([-e[1], e[0]])


def _round_arc(centre: np.ndarray, radius: float, axis, side: float, pivot: np.ndarray):
    """The part of a tooth round that is profile: outside its centre along the tooth axis and,
    for a two-flank tooth, on the far side of the centreline (side); mm."""
    a = np.linspace(0.0, 2.0 * math.pi, 181)
    pts = centre[:, None] + radius * np.array([np.cos(a), np.sin(a)])
    if axis is None:
        return MM * pts.T
    rel = pts - centre[:, None]
    keep = axis @ rel >= 0.0
    keep &= side * (axis[0] * (pts[1] - pivot[1]) - axis[1] * (pts[0] - pivot[0])) >= 0.0
    out = MM * pts[:, keep].T
    if len(out) > 1:  # start the arc at a gap so the line does not wrap round
        gaps = np.nonzero(~keep)[0]
        if len(gaps):
            order = np.argsort((np.nonzero(keep)[0] - gaps[0]) % len(a))
            out = out[order]
    return out


def _draw_clock(axes, m: MeshModel, theta: float) -> str:
    o_g, o_p, r_g, r_p, gear, pinion, flanks, contact, normal = _clock_pieces(m, theta)
    for ax in axes:
        _circle(ax, o_g, r_g, GEAR, "--", "gear pitch circle")
        _circle(ax, o_p, r_p, PINION, "--", "pinion pitch circle")
        for rounds, color, pivot in ((gear, GEAR, o_g), (pinion, PINION, o_p)):
            for centre, radius, axis, side in rounds:
                xy = _round_arc(centre, radius, axis, side, pivot)
                ax.plot(xy[:, 0], xy[:, 1], color=color, lw=1.0)
            ax.plot(*(MM * pivot), "+", color=color, ms=8)
        for a, b, color in flanks:
            ax.plot([MM * a[0], MM * b[0]], [MM * a[1], MM * b[1]], color=color, lw=1.0)
        span = 0.3 * r_p
        ends = MM * np.array([contact - span * normal, contact + span * normal])
        ax.plot(ends[:, 0], ends[:, 1], color=ACTION, lw=0.8, label="contact normal")
        ax.plot(*(MM * contact), "o", color="k", ms=4)
    zoom = 0.9 * r_p
    axes[1].set_xlim(MM * (contact[0] - zoom), MM * (contact[0] + zoom))
    axes[1].set_ylim(MM * (contact[1] - zoom), MM * (contact[1] + zoom))
    lo = np.minimum(o_g - r_g, o_p - r_p) * 1.1
    hi = np.maximum(o_g + r_g, o_p + r_p) * 1.1
    axes[0].set_xlim(MM * lo[0], MM * hi[0])
    axes[0].set_ylim(MM * lo[1], MM * hi[1])
    rounds = "arcs" if isinstance(m, ClockTableModel) else "rounds (circles)"
    return f"gear drives; tooth and leaf {rounds} and straight flanks, dot: contact"


def figure(scene: Scene):  # noqa: ANN201 - a matplotlib Figure (imported when drawing)
    """The drawing of the scene's pair, as a matplotlib Figure (Agg) in millimetres."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ms = mesh_scene(scene)
    m = ms.model
    fig, axes = plt.subplots(1, 2, figsize=(13, 6.5), width_ratios=(1.1, 1))
    if isinstance(m, InvoluteModel):
        what = _draw_involute(axes, m, ms.theta0)
    else:
        what = _draw_clock(axes, m, ms.theta0)
    for ax, title in zip(axes, ("the pair", "contact region"), strict=True):
        ax.set_aspect("equal", adjustable="box")
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]")
        ax.set_title(title, fontsize=9)
        ax.grid(True, alpha=0.25)
    handles, labels = axes[1].get_legend_handles_labels()
    seen = dict(zip(labels, handles, strict=True))
    axes[1].legend(seen.values(), seen.keys(), fontsize=7, loc="upper right", framealpha=0.9)
    fig.suptitle(f"{scene.name}: {m.name}\n{what}", fontsize=10)
    fig.tight_layout()
    return fig


def draw(scene: Scene, path: Path) -> None:
    """PNG of the scene's gear pair in mesh at its start angle, to scale."""
    import matplotlib.pyplot as plt

    fig = figure(scene)
    fig.savefig(path, dpi=110)
    plt.close(fig)
