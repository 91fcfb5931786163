"""The design of an M739-type S&A drawn to scale, as entered, before it runs.

Left: the fuze body seen along the spin axis, with the pivots where B1-B31 put them and
each wheel's pitch, base and outside circles (the escape wheel's tip circle, the pallet's
corner circle).  Right: the escapement at the start (App. C frame: pallet pivot O_p at the
origin, escape-wheel pivot O_s at distance A along x, angles counter-clockwise): the wheel's
N teeth with the tooth at PHID on the entrance face, the pallet's two faces at the verge
angle psi that the contact loop (C17, C18) gives, and the contact point.

``escapement_artists`` draws the escapement at any wheel and verge angle, so a picture of a
run's motion can reuse it.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from components.m739_data import M739Data
from components.sanda2v_deck import _mesh_limits
from components.units import DEG, INCH
from components.verge_geometry import fuze_angles, kinem

#: Drawn lengths are in inches, the unit of the deck.
_IN = 1.0 / INCH


def _circle(ax: Any, centre: tuple[float, float], radius: float, **style: Any) -> Any:
    import matplotlib.patches as patches

    artist = patches.Circle(centre, radius * _IN, fill=False, **style)
    ax.add_patch(artist)
    return artist


def pivots(d: M739Data) -> dict[str, tuple[float, float]]:
    """Pivot positions in the fuze body [in]: spin axis, rotor O1 (on +x), gear 2 O2,
    escape wheel O3 = O_s, pallet O_p (polar angles gamma of B1-B31)."""
    ang = fuze_angles(d)

    def at(r: float, gamma: float) -> tuple[float, float]:
        return (r * math.cos(gamma) * _IN, r * math.sin(gamma) * _IN)

    return {
        "spin axis": (0.0, 0.0),
        "O1 rotor": at(d.r1, 0.0),
        "O2 gear 2": at(d.r2, ang.gamma2),
        "O3 escape wheel": at(d.r3, ang.gamma3),
        "Op pallet": at(d.r4, ang.gamma4),
    }


def contact_ratios(d: M739Data) -> tuple[float, float]:
    """The two meshes' contact ratios (contact range over one base pitch of the driver)."""
    out = []
    for rb_g, rb_p, theta, ro_g, ro_p, ng in (
        (d.rb1_cap, d.rb2, d.theta1, d.ro1_cap, d.ro2, d.ng1),
        (d.rb2_cap, d.rb3, d.theta2, d.ro2_cap, d.ro3, d.ng2),
    ):
        al_in, al_fin = _mesh_limits(rb_g, rb_p, theta, ro_g, ro_p)
        out.append((al_fin - al_in) / (2.0 * math.pi / ng))
    return out[0], out[1]


def draw_body(ax: Any, d: M739Data) -> None:
    """The fuze body: pivots and every wheel's circles, to scale [in]."""
    p = pivots(d)
    wheels = (
        ("O1 rotor", "gear 1", d.rp1_cap, d.rb1_cap, d.ro1_cap, "C0"),
        ("O2 gear 2", "pinion 2", d.rp2, d.rb2, d.ro2, "C1"),
        ("O2 gear 2", "gear 2", d.rp2_cap, d.rb2_cap, d.ro2_cap, "C2"),
        ("O3 escape wheel", "pinion 3", d.rp3, d.rb3, d.ro3, "C3"),
    )
    for pivot, name, rp, rb, ro, colour in wheels:
        c = p[pivot]
        _circle(ax, c, rp, color=colour, lw=1.2, label=f"{name}: pitch / base / outside")
        _circle(ax, c, rb, color=colour, lw=0.8, ls=":")
        _circle(ax, c, ro, color=colour, lw=0.8, ls="--")
    _circle(ax, p["O3 escape wheel"], d.b, color="C4", lw=1.2, label="escape-wheel tips (B)")
    _circle(ax, p["Op pallet"], d.c, color="C5", lw=1.2, label="pallet corners (C)")
    for name, (x, y) in p.items():
        ax.plot([x], [y], "k+", ms=8)
        ax.annotate(name, (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)
    # The centre lines whose lengths the deck fixes: the two meshes and A.
    for a, b in (("O1 rotor", "O2 gear 2"), ("O2 gear 2", "O3 escape wheel")):
        ax.plot(*zip(p[a], p[b], strict=True), color="0.6", lw=0.6)
    ax.plot(*zip(p["O3 escape wheel"], p["Op pallet"], strict=True), color="C5", lw=0.6)
    _circle(ax, (0.0, 0.0), d.r1, color="0.85", lw=0.5)
    ax.set_aspect("equal")
    ax.set_xlabel("x [in]")
    ax.set_ylabel("y [in]")
    ax.legend(loc="lower left", fontsize=6)


def escapement_artists(
    ax: Any, d: M739Data, phi: float, psi: float, face: str = "entrance"
) -> list[Any]:
    """The escape wheel at local angle ``phi`` of the tooth on the active ``face`` and the
    verge at ``psi`` (the active face's frame, App. C), in the C frame [in].  Returns the
    artists (to remove or move them)."""
    import matplotlib.patches as patches

    artists: list[Any] = []
    a, b, c = d.a * _IN, d.b * _IN, d.c * _IN
    delta = 2.0 * math.pi / d.n_teeth
    root = 0.78 * b
    # Teeth: a ratchet tooth per pitch, its tip at the tip radius.
    outline = []
    for k in range(d.n_teeth):
        tip = phi + k * delta
        outline.append((a + root * math.cos(tip - 0.7 * delta), root * math.sin(tip - 0.7 * delta)))
        outline.append((a + b * math.cos(tip), b * math.sin(tip)))
        outline.append(
            (a + root * math.cos(tip + 0.15 * delta), root * math.sin(tip + 0.15 * delta))
        )
    artists.append(ax.add_patch(patches.Polygon(outline, closed=True, fill=False, color="C4")))
    artists += ax.plot([a], [0.0], "k+", ms=8)
    # The pallet: the active face's corner at psi, the other's lambda away.
    if face == "entrance":
        corners = ((psi, d.alpha_en, 1.0, "entrance"), (psi - d.lam, d.alpha_ex, -1.0, "exit"))
    else:
        corners = ((psi + d.lam, d.alpha_en, 1.0, "entrance"), (psi, d.alpha_ex, -1.0, "exit"))
    face_length = 0.35 * c
    for angle, alpha, side, name in corners:
        cx, cy = c * math.cos(angle), c * math.sin(angle)
        tx, ty = math.cos(angle + alpha), math.sin(angle + alpha)
        artists += ax.plot([0.0, cx], [0.0, cy], color="C5", lw=2.0)
        artists += ax.plot(
            [cx, cx + side * face_length * tx],
            [cy, cy + side * face_length * ty],
            color="C3",
            lw=2.5,
            label=f"{name} face",
        )
    artists += ax.plot([0.0], [0.0], "k+", ms=8)
    return artists


def draw_escapement(ax: Any, d: M739Data) -> None:
    """The escapement at the start: the tooth at PHID on the entrance face."""
    psi, g, *_ = kinem(d.phi_start, d.alpha_en, d.a, d.b, d.c)
    escapement_artists(ax, d, d.phi_start, psi)
    # The contact point: the tip of the tooth at PHID.
    tip = ((d.a + d.b * math.cos(d.phi_start)) * _IN, d.b * math.sin(d.phi_start) * _IN)
    ax.plot([tip[0]], [tip[1]], "o", color="k", ms=4, label="contact at the start")
    ax.annotate("O_p", (0, 0), textcoords="offset points", xytext=(-14, -10), fontsize=7)
    ax.annotate("O_s", (d.a * _IN, 0), textcoords="offset points", xytext=(4, -10), fontsize=7)
    ax.set_title(
        f"escapement at the start: PHID {d.phi_start / DEG:.2f} deg, psi {psi / DEG:.2f} deg, "
        f"g {g * _IN:.4f} in",
        fontsize=8,
    )
    ax.set_aspect("equal")
    ax.set_xlabel("x' [in] (O_p to O_s)")
    ax.legend(loc="lower left", fontsize=6)


def draw_design(d: M739Data, path: Path, title: str) -> None:
    """Both views side by side, written as a PNG."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (body, escapement) = plt.subplots(1, 2, figsize=(13, 6.5))
    draw_body(body, d)
    cr1, cr2 = contact_ratios(d)
    body.set_title(
        f"fuze body (configuration {d.config}): meshes {d.ng1}:{d.np2} and {d.ng2}:{d.np3}, "
        f"contact ratios {cr1:.4f} and {cr2:.4f}",
        fontsize=8,
    )
    draw_escapement(escapement, d)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def draw(scene: Any, path: Path) -> None:
    """The scene's design (``mechcosim draw``)."""
    from orchestrator.scenes.m739.design import scene_design

    draw_design(scene_design(scene), Path(path), f"{scene.name}: the design as entered, to scale")
