"""The M739-type S&A (and the clock-train S&A, which has its verge) in motion.

Left: the fuze body to scale (``draw_body``), each wheel's tooth marks and a spoke turning at
its angle: the rotor at phi1c + n31 phi (or the recorded ``train.rotor_angle``), gear 2 and
its pinion at n32 phi, the escape wheel and its pinion at phi.  Right: the escapement
(``escapement_artists``, App. C frame) with the escape wheel at its recorded angle and the
verge at its recorded angle ``verge.psi`` (entrance-face coordinates), the contact point and
the verge's regime, and each impact drawn where and when the run located it.

Between records the wheel angle is interpolated linearly; while a tooth slides on a face the
verge angle is the one the contact kinematics gives for that wheel angle (C18, ``kinem``), so
the tooth stays on the face; in free flight it is interpolated linearly too.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from components.m739_data import M739Data
from components.sanda2v_deck import DECK, TRAIN, data_from
from components.units import INCH
from components.verge_geometry import kinem
from orchestrator.animate.record import RunRecord, Track
from orchestrator.scenes.m739.design import instances, parameter, scene_design
from orchestrator.scenes.m739.drawing import draw_body, escapement_artists, pivots

_IN = 1.0 / INCH
#: Within this of the recorded verge angle a tooth is the one in contact [rad].
_CONTACT_MATCH = 0.05
TWO_PI = 2.0 * math.pi


def design(scene: Any) -> M739Data:
    """The scene's design: the M739 family's own; for a train without the deck's train
    quantities (the clock train) those of the verge, the rest the M739's."""
    try:
        return scene_design(scene)
    except (KeyError, AttributeError):
        pass
    train, verge = instances(scene)
    values: dict[str, float] = {}
    for entry in DECK:
        order = (train, verge) if TRAIN in entry.users else (verge, train)
        for instance in order:
            if instance in scene.fmus:
                try:
                    values[entry.name] = parameter(scene, instance, entry.name)
                    break
                except KeyError:
                    continue
    return data_from(values)


def _verge_start(scene: Any, verge: str, d: M739Data) -> float:
    try:
        return float(parameter(scene, verge, "phi_local_start"))
    except KeyError:
        return d.phi_start


class EscapementMotion:
    """Wheel and verge angles at any time of the run, the tooth in contact included."""

    def __init__(self, run: RunRecord) -> None:
        scene = run.scene
        self.train, self.verge = instances(scene)
        self.d = d = design(scene)
        t = run.time
        phi = run.column(f"{self.train}.phi")
        self.phi = Track(t, phi)
        self.psi = Track(t, run.column(f"{self.verge}.psi"), wrapped=True)
        # phi_local = phi + phi_off with phi_off fixed by the first record (re-indexing
        # shifts it by whole pitches, which draw the same wheel).
        self.phi_offset = _verge_start(scene, self.verge, d) - phi[0]
        self.rotor = (
            Track(t, run.column(f"{self.train}.rotor_angle"))
            if run.has(f"{self.train}.rotor_angle")
            else None
        )
        self.regimes = run.regime_at(self.verge)
        self.train_regimes = run.regime_at(self.train) if run.has(f"{self.train}.regime") else None
        self.delta = TWO_PI / d.n_teeth
        self.impacts = self._impacts(run)

    def wheel(self, t: float) -> float:
        """The escape wheel's local angle (App. C) [rad]."""
        return float(self.phi(t)) + self.phi_offset

    def rotor_angle(self, t: float) -> float:
        if self.rotor is not None:
            return float(self.rotor(t))
        return self.d.phi1c + self.d.n31 * float(self.phi(t))

    def verge_at(self, t: float) -> tuple[float, tuple[float, float] | None, str]:
        """(verge angle in entrance-face coordinates, contact point [in] or None, regime)."""
        regime = self.regimes.at(t)
        psi = float(self.psi(t))
        if not regime.startswith("coupled"):
            return psi, None, regime
        d = self.d
        exit_face = regime.endswith("exit")
        alpha = d.alpha_ex if exit_face else d.alpha_en
        phi0 = self.wheel(t)
        best: tuple[float, float, float] | None = None
        for k in range(d.n_teeth):
            tip = phi0 + k * self.delta
            psi_face = kinem(tip, alpha, d.a, d.b, d.c)[0]
            psi_entrance = psi_face + (d.lam if exit_face else 0.0)
            miss = abs(math.remainder(psi_entrance - psi, TWO_PI))
            if best is None or miss < best[0]:
                best = (miss, psi_entrance, tip)
        assert best is not None
        miss, psi_exact, tip = best
        if miss > _CONTACT_MATCH:
            return psi, None, regime
        contact = ((d.a + d.b * math.cos(tip)) * _IN, d.b * math.sin(tip) * _IN)
        return psi + math.remainder(psi_exact - psi, TWO_PI), contact, regime

    def _impacts(self, run: RunRecord) -> list[tuple[float, tuple[float, float] | None]]:
        """Every contact that was an impact (the impact count rose there; every contact when
        the count is not recorded), with where it struck."""
        count_name = f"{self.verge}.impact_count"
        counts = run.column(count_name) if run.has(count_name) else None
        out = []
        for tc in self.regimes.entered("coupled"):
            if counts is not None:
                before = counts[max(int(np.searchsorted(run.time, tc, side="left")) - 1, 0)]
                after = counts[max(int(np.searchsorted(run.time, tc, side="right")) - 1, 0)]
                if after <= before:
                    continue
            out.append((tc, self.verge_at(tc)[1]))
        return out


def _marks(rings: tuple[tuple[int, float, float], ...]) -> np.ndarray:
    """Radial tooth marks, ``teeth`` of them from radius r_in to r_out [m] per ring, and a
    spoke to the outermost ring, at angle 0, as one polyline with breaks [in]."""
    pts: list[tuple[float, float]] = []
    for teeth, r_in, r_out in rings:
        for ang in np.arange(teeth) * TWO_PI / teeth:
            c, s = math.cos(ang), math.sin(ang)
            pts += [(r_in * _IN * c, r_in * _IN * s), (r_out * _IN * c, r_out * _IN * s)]
            pts.append((np.nan, np.nan))
    pts += [(0.0, 0.0), (max(r for _, _, r in rings) * _IN, 0.0)]
    return np.array(pts)


class EscapementStage:
    """The figure: fuze body (left), escapement (right)."""

    default_slowdown = 1000.0

    def __init__(self, run: RunRecord) -> None:
        self.run = run
        self.motion = EscapementMotion(run)
        self.hold = 0.0  # how long an impact stays marked [s], set by the clock

    def build(self, fig: Any, frame_step: float) -> list[Any]:
        from matplotlib.transforms import Affine2D

        m, d = self.motion, self.motion.d
        self.hold = 3.0 * frame_step
        body = fig.add_axes((0.05, 0.08, 0.42, 0.8))
        esc = fig.add_axes((0.53, 0.08, 0.44, 0.8))
        self._axes = esc
        draw_body(body, d)
        body.get_legend().remove()  # the pivots are named; the legend would hide wheels
        body.set_title("fuze body: wheels at their ratios", fontsize=8)
        p = pivots(d)
        wheels = (
            ("O1 rotor", ((d.ng1, 2 * d.rp1_cap - d.ro1_cap, d.ro1_cap),), "C0", m.rotor_angle),
            ("O2 gear 2", ((d.ng2, 2 * d.rp2_cap - d.ro2_cap, d.ro2_cap),
                           (d.np2, 2 * d.rp2 - d.ro2, d.ro2)), "C2",
             lambda t: d.n32 * float(m.phi(t))),
            ("O3 escape wheel", ((d.n_teeth, 0.85 * d.b, d.b), (d.np3, 2 * d.rp3 - d.ro3, d.ro3)),
             "C4", lambda t: float(m.phi(t))),
        )  # fmt: skip
        self._wheels = []
        animated: list[Any] = []
        for pivot, rings, colour, angle in wheels:
            pts = _marks(rings)
            (line,) = body.plot(pts[:, 0], pts[:, 1], color=colour, lw=1.0)
            rotation = Affine2D()
            line.set_transform(rotation + Affine2D().translate(*p[pivot]) + body.transData)
            self._wheels.append((rotation, angle))
            animated.append(line)
        # The escapement: the design's artists at zero angles, turned rigidly each frame.
        self._wheel_turn, self._verge_turn = Affine2D(), Affine2D()
        for artist in escapement_artists(esc, d, 0.0, 0.0, "entrance"):
            if artist.__class__.__name__ == "Polygon":
                centre = Affine2D().translate(-d.a * _IN, 0.0)
                turn = centre + self._wheel_turn + Affine2D().translate(d.a * _IN, 0.0)
            elif getattr(artist, "get_marker", lambda: "")() == "+":
                continue  # the pivots stand still
            else:
                turn = self._verge_turn
            artist.set_transform(turn + esc.transData)
            animated.append(artist)
        esc.annotate("O_p", (0, 0), textcoords="offset points", xytext=(-14, -10), fontsize=7)
        esc.annotate("O_s", (d.a * _IN, 0), textcoords="offset points", xytext=(4, -10),
                     fontsize=7)  # fmt: skip
        reach = 1.15 * d.b * _IN
        esc.set_xlim(-0.2 * d.c * _IN - 0.05 * reach, d.a * _IN + reach)
        esc.set_ylim(-reach, reach)
        esc.set_aspect("equal", adjustable="box")
        esc.set_xlabel("x' [in] (O_p to O_s)", fontsize=7)
        esc.tick_params(labelsize=6)
        body.tick_params(labelsize=6)
        body.xaxis.label.set_size(7)
        body.yaxis.label.set_size(7)
        (self._contact,) = esc.plot([], [], "o", color="k", ms=4)
        # The impact star in gold, a colour no part of the mechanism is drawn in.
        (self._impact,) = esc.plot([], [], "*", color="gold", ms=16, mec="k", mew=0.6)
        self._regime = esc.text(0.02, 0.97, "", transform=esc.transAxes, fontsize=8, va="top")
        self._impact_text = esc.text(
            0.02, 0.03, "", transform=esc.transAxes, fontsize=8, color="darkred"
        )
        esc.set_title("escapement (App. C frame): wheel, verge, contact point", fontsize=8)
        animated += [self._contact, self._impact, self._regime, self._impact_text]
        self._impact_times = np.array([t for t, _ in m.impacts])
        return animated

    def update(self, t: float) -> None:
        m = self.motion
        for rotation, angle in self._wheels:
            rotation.clear().rotate(angle(t))
        self._wheel_turn.clear().rotate(m.wheel(t))
        psi, contact, regime = m.verge_at(t)
        self._verge_turn.clear().rotate(psi)
        self._contact.set_data(*(([contact[0]], [contact[1]]) if contact else ([], [])))
        lines = [f"verge: {regime}"]
        if m.train_regimes is not None:
            lines.append(f"train: {m.train_regimes.at(t)}")
        self._regime.set_text("\n".join(lines))
        # An impact is marked from its located instant on, for a few frames.
        i = int(np.searchsorted(self._impact_times, t, side="right")) - 1
        if i >= 0 and t - self._impact_times[i] < self.hold and m.impacts[i][1] is not None:
            where = m.impacts[i][1]
            self._impact.set_data([where[0]], [where[1]])
            self._impact_text.set_text(
                f"impact {i + 1} at t = {self._impact_times[i] * 1e3:.6f} ms"
            )
        else:
            self._impact.set_data([], [])
            self._impact_text.set_text("")

    def layout(self) -> dict[str, Any]:
        """Where the escapement was drawn: its axes' box in image pixels (left, top, right,
        bottom; rows counted from the top) and its data limits [in]."""
        return _axes_layout("escapement", self._axes)


def _axes_layout(name: str, ax: Any) -> dict[str, Any]:
    height = ax.figure.bbox.height
    box = ax.bbox
    return {
        name: {
            "pixels": (box.x0, height - box.y1, box.x1, height - box.y0),
            "xlim": tuple(ax.get_xlim()),
            "ylim": tuple(ax.get_ylim()),
        }
    }
