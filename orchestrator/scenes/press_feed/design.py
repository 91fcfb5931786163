"""The design of a press-feed scene (Xu 1993, Table 1 and Table 4): the linkage, coupler,
clutch and load its three FMUs were given, and the rules it must satisfy before it runs.

Imports only the physics (no scene loader), so the loader can check a design as it reads
a scene.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

from components.press_feed_data import BentCoupler, RSSRLinkage, SpragGeometry
from components.press_feed_rules import brake_note, drive_violations, sprag_violations
from components.sprag_clutch import MODEL_HERTZ
from components.units import RPM

_ROLES = ("CrankCouplerDrive", "SpragClutch", "BrakeLoad")


class DesignNote(UserWarning):
    """A design that runs but that the source warns against (e.g. a brake below the
    engagement minimum)."""


@dataclass(frozen=True)
class FeedDesign:
    """The quantities of a press-feed scene's design, SI (None: the scene lacks that FMU)."""

    linkage: RSSRLinkage | None
    coupler: BentCoupler | None
    elastic: bool
    omega: float
    sprag: SpragGeometry | None  # only for the two-point Hertz clutch
    j5: float | None
    brake_torque: float | None


def _parameters(scene: Any, component: str) -> dict[str, float] | None:
    """The SI parameters (given, else default) of the scene's one FMU of a component."""
    names = [n for n, spec in scene.fmus.items() if spec.component == component]
    if len(names) != 1:
        return None
    values = {v.name: float(v.start) for v in scene.component_class(names[0]).VARIABLES}
    values.update(scene.fmus[names[0]].parameters)
    return values


def scene_design(scene: Any) -> FeedDesign:
    """The design the scene's drive, clutch and load were given."""
    d, c, b = (_parameters(scene, role) for role in _ROLES)
    linkage = coupler = sprag = None
    elastic, omega = False, 0.0
    if d is not None:
        linkage = RSSRLinkage(d["a1"], d["a3"], d["a4"], d["s1"], d["s2"], d["s3"])
        coupler = BentCoupler(
            length=d["L"],
            alpha=d["alpha"],
            d_outer=d["d_outer"],
            d_inner=d["d_inner"],
            youngs=d["youngs"],
            density=d["density"],
            c_co=d["c_co"],
            p1=d["p1"],
            gauge_x1=d["gauge_x1"],
            lumped_mass=d["lumped_mass"],
        )
        elastic = d["rigid"] <= 0.5
        omega = d["crank_speed"] if d["crank_speed"] > 0.0 else d["rpm"] * RPM
    if c is not None and round(c["model"]) == MODEL_HERTZ:
        sprag = SpragGeometry(
            c["r_outer"],
            c["r_inner"],
            c["r_sprag"],
            c["sprag_offset"],
            int(c["n_sprags"]),
            c["strut_inner"],
            c["strut_outer"],
            c["youngs"],
            c["poisson"],
            0.0,
            0.0,
            0.0,
        )
    return FeedDesign(
        linkage,
        coupler,
        elastic,
        omega,
        sprag,
        None if b is None else b["j"],
        None if b is None else b["brake_torque"],
    )


def violations(design: FeedDesign) -> list[str]:
    """Every broken rule of a design, one line each."""
    out = []
    if design.linkage is not None and design.coupler is not None:
        out += drive_violations(design.linkage, design.coupler, design.elastic)
    if design.sprag is not None:
        out += sprag_violations(design.sprag)
    return [str(v) for v in out]


def notes(design: FeedDesign) -> list[str]:
    """What the design runs with but the source warns against (the brake below the
    engagement minimum); only of a design without broken rules."""
    if (
        design.linkage is None
        or design.coupler is None
        or design.j5 is None
        or design.brake_torque is None
        or design.omega <= 0.0
        or violations(design)
    ):
        return []
    note = brake_note(
        design.linkage, design.coupler.alpha, design.omega, design.j5, design.brake_torque
    )
    return [] if note is None else [note]


def check(scene: Any) -> list[str]:
    """Every broken rule of the scene's design; its notes are given as DesignNote warnings."""
    design = scene_design(scene)
    for note in notes(design):
        warnings.warn(note, DesignNote, stacklevel=2)
    return violations(design)
