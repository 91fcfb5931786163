"""Schematic stages: the detached lever, the press feed and a gear mesh, each moving with its
run's recorded angles.  Not to scale (their designs have no drawing to reuse here): each
wheel is a circle with tooth marks and a spoke, turned by its recorded angle, and each FMU's
regime is named as its events switch it.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from orchestrator.animate.record import RunRecord, Track

TWO_PI = 2.0 * math.pi


def wheel_marks(teeth: int, r_in: float, r_out: float, spokes: int = 1) -> np.ndarray:
    """A wheel at angle 0 as one polyline with breaks: a mark per tooth, ``spokes`` spokes."""
    pts: list[tuple[float, float]] = []
    for ang in np.arange(teeth) * TWO_PI / teeth:
        c, s = math.cos(ang), math.sin(ang)
        pts += [(r_in * c, r_in * s), (r_out * c, r_out * s), (np.nan, np.nan)]
    for ang in np.arange(spokes) * TWO_PI / spokes:
        pts += [(0.0, 0.0), (r_in * math.cos(ang), r_in * math.sin(ang)), (np.nan, np.nan)]
    return np.array(pts)


class _Wheels:
    """Wheels on one axes, each turned about its centre by an angle given per frame."""

    def __init__(self, ax: Any) -> None:
        self.ax = ax
        self.turns: list[tuple[Any, Any]] = []

    def add(self, centre: tuple[float, float], pts: np.ndarray, angle: Any, **style: Any) -> Any:
        from matplotlib.patches import Circle
        from matplotlib.transforms import Affine2D

        radius = float(np.nanmax(np.hypot(pts[:, 0], pts[:, 1])))
        self.ax.add_patch(Circle(centre, radius, fill=False, color="0.7", lw=0.6))
        self.ax.plot([centre[0]], [centre[1]], "k+", ms=6)
        (line,) = self.ax.plot(pts[:, 0], pts[:, 1], **style)
        turn = Affine2D()
        line.set_transform(turn + Affine2D().translate(*centre) + self.ax.transData)
        self.turns.append((turn, angle))
        return line

    def update(self, t: float) -> None:
        for turn, angle in self.turns:
            turn.clear().rotate(float(angle(t)))


class _RegimeText:
    """Each named FMU's regime at the frame's time, in the corner of an axes."""

    def __init__(self, run: RunRecord, ax: Any, instances: list[str]) -> None:
        self.timelines = [(i, run.regime_at(i)) for i in instances if run.has(f"{i}.regime")]
        self.text = ax.text(0.02, 0.97, "", transform=ax.transAxes, fontsize=8, va="top")

    def update(self, t: float) -> None:
        self.text.set_text("\n".join(f"{i}: {tl.at(t)}" for i, tl in self.timelines))


def _axes(fig: Any, title: str, lim: tuple[float, float, float, float]) -> Any:
    ax = fig.add_axes((0.04, 0.04, 0.92, 0.8))
    ax.set_xlim(lim[0], lim[1])
    ax.set_ylim(lim[2], lim[3])
    ax.set_aspect("equal", adjustable="box")
    ax.set_axis_off()
    ax.set_title(title, fontsize=8)
    return ax


class LeverStage:
    """Detached lever: the balance turning at ``theta``; the lever schematic (it follows
    the balance's roller near the centre and rests on a banking outside it)."""

    default_slowdown = 2.0

    def __init__(self, run: RunRecord) -> None:
        self.run = run
        (self.lever,) = [i for i in run.scene.fmus if run.has(f"{i}.theta")] or ["lever"]
        self.theta = Track(run.time, run.column(f"{self.lever}.theta"))

    def build(self, fig: Any, frame_step: float) -> list[Any]:
        ax = _axes(fig, "detached lever (schematic): balance and lever", (-2.6, 2.6, -1.3, 1.3))
        self.wheels = _Wheels(ax)
        balance = self.wheels.add((-1.0, 0.0), wheel_marks(24, 1.0, 1.08, 4), self.theta,
                                  color="C0", lw=1.2)  # fmt: skip
        (self.arm,) = ax.plot([], [], color="C3", lw=2.5)
        ax.plot([1.4], [0.0], "k+", ms=8)
        ax.plot([1.4 + 0.6 * math.cos(a) for a in (2.8, 3.48)], [0.6 * math.sin(a) for a in
                (2.8, 3.48)], "s", color="0.5", ms=5)  # fmt: skip  # the bankings
        self.regimes = _RegimeText(self.run, ax, [self.lever])
        self.angle = ax.text(0.98, 0.03, "", transform=ax.transAxes, ha="right", fontsize=8)
        return [balance, self.arm, self.regimes.text, self.angle]

    def update(self, t: float) -> None:
        self.wheels.update(t)
        theta = float(self.theta(t))
        swing = 0.34 * math.tanh(theta / 0.3)  # schematic: between the bankings
        a = math.pi + swing
        self.arm.set_data([1.4, 1.4 + 1.4 * math.cos(a)], [0.0, 1.4 * math.sin(a)])
        self.regimes.update(t)
        self.angle.set_text(f"balance angle {theta:+.3f} rad")


class PressFeedStage:
    """Press feed: crank (``drive.phi1``), coupler to the rocker (``drive.angle``), the
    sprag clutch's outer race on the rocker and inner race on the feed roll
    (``load.angle``)."""

    default_slowdown = 5.0

    def __init__(self, run: RunRecord) -> None:
        self.run = run
        t = run.time
        self.crank = Track(t, run.column("drive.phi1"))
        self.rocker = Track(t, run.column("drive.angle"))
        self.roll = Track(t, run.column("load.angle"))
        self.windup = Track(t, run.column("clutch.windup")) if run.has("clutch.windup") else None

    def build(self, fig: Any, frame_step: float) -> list[Any]:
        ax = _axes(fig, "press feed (schematic): crank, coupler, rocker, sprag clutch, feed roll",
                   (-3.2, 3.2, -1.6, 1.6))  # fmt: skip
        self.wheels = _Wheels(ax)
        self.o1, self.o2 = (-2.0, 0.0), (1.0, 0.0)
        rocker0 = float(self.rocker(self.run.time[0]))
        crank = self.wheels.add(self.o1, wheel_marks(1, 0.5, 0.5, 1), self.crank, color="C0",
                                lw=2.0)  # fmt: skip
        swing = Track(self.run.time, self.run.column("drive.angle") - rocker0)
        outer = self.wheels.add(self.o2, wheel_marks(18, 0.8, 0.9, 0), swing, color="C1", lw=1.0)
        inner = self.wheels.add(self.o2, wheel_marks(12, 0.55, 0.65, 3), self.roll, color="C2",
                                lw=1.2)  # fmt: skip
        (self.rocker_arm,) = ax.plot([], [], color="C1", lw=2.5)
        (self.coupler,) = ax.plot([], [], color="C3", lw=2.0)
        self.regimes = _RegimeText(self.run, ax, ["drive", "clutch", "load"])
        self.values = ax.text(0.98, 0.03, "", transform=ax.transAxes, ha="right", fontsize=8)
        self._rocker0 = rocker0
        return [crank, outer, inner, self.rocker_arm, self.coupler, self.regimes.text,
                self.values]  # fmt: skip

    def update(self, t: float) -> None:
        self.wheels.update(t)
        phi1, rocker = float(self.crank(t)), float(self.rocker(t))
        pin = (self.o1[0] + 0.5 * math.cos(phi1), self.o1[1] + 0.5 * math.sin(phi1))
        a = math.pi / 2 + 4.0 * (rocker - self._rocker0)  # the rocker's swing, magnified 4x
        tip = (self.o2[0] + 1.2 * math.cos(a), self.o2[1] + 1.2 * math.sin(a))
        self.rocker_arm.set_data([self.o2[0], tip[0]], [self.o2[1], tip[1]])
        self.coupler.set_data([pin[0], tip[0]], [pin[1], tip[1]])
        self.regimes.update(t)
        text = (
            f"crank {math.degrees(phi1) % 360:5.1f} deg, feed roll {float(self.roll(t)):+.4f} rad"
        )
        if self.windup is not None:
            text += f", clutch windup {float(self.windup(t)) * 1e3:+.3f} mrad"
        self.values.set_text(text + " (rocker swing drawn 4x)")


class GearMeshStage:
    """A gear mesh: driver and driven wheels turning at their recorded angles, their radii
    in the ratio of the run's mean speeds."""

    default_slowdown = 20.0

    def __init__(self, run: RunRecord) -> None:
        self.run = run
        (self.mesh,) = [i for i in run.scene.fmus if run.has(f"{i}.driver_angle")] or ["mesh"]
        t = run.time
        driver = run.column(f"{self.mesh}.driver_angle")
        driven = run.column(f"{self.mesh}.driven_angle")
        # Drawn side by side, the driven wheel turns against the driver (an external mesh).
        self.driver, self.driven = Track(t, driver), Track(t, -driven)
        turned = abs(driver[-1] - driver[0])
        self.ratio = abs(driven[-1] - driven[0]) / turned if turned > 0.0 else 1.0
        self.ratio = min(max(self.ratio, 0.1), 10.0)  # a drawable pair

    def build(self, fig: Any, frame_step: float) -> list[Any]:
        r1 = 1.0
        r2 = r1 / self.ratio
        span = r1 + r2
        big = 1.3 * max(r1, r2)
        lim = (-1.3 * r1, span + 1.3 * r2, -big, big)
        ax = _axes(fig, "gear mesh (schematic): driver and driven wheels", lim)
        self.wheels = _Wheels(ax)
        n1 = 24
        n2 = max(int(round(n1 / self.ratio)), 6)
        a = self.wheels.add((0.0, 0.0), wheel_marks(n1, r1 * 0.9, r1, 1), self.driver,
                            color="C0", lw=1.2)  # fmt: skip
        b = self.wheels.add((span, 0.0), wheel_marks(n2, r2 * 0.9 if r2 > 0.2 else r2 - 0.1 * r1,
                            r2, 1), self.driven, color="C3", lw=1.2)  # fmt: skip
        self.regimes = _RegimeText(self.run, ax, [self.mesh])
        return [a, b, self.regimes.text]

    def update(self, t: float) -> None:
        self.wheels.update(t)
        self.regimes.update(t)
