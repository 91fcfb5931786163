"""The design of an M739-type S&A scene: the SANDA2V deck its train and verge were given,
and the rules it must satisfy before it runs.

Imports only the physics (no scene loader), so the loader can check a design as it reads
a scene.
"""

from __future__ import annotations

import math
from typing import Any

from components.m739_data import M739Data
from components.sanda2v_deck import DECK, TRAIN, VERGE, data_from, violations
from components.units import DEG


def instances(scene: Any) -> tuple[str, str]:
    """(gear train, verge) instances, from [report.options]."""
    o = scene.report_options
    return o.get("train", "train"), o.get("verge", "verge")


def parameter(scene: Any, instance: str, name: str) -> float:
    """A parameter of one of the scene's FMUs: as the scene gives it, else its default."""
    spec = scene.fmus[instance]
    if name in spec.parameters:
        return spec.parameters[name]
    return scene.component_class(instance).variable(name).start


def scene_design(scene: Any) -> M739Data:
    """The whole deck of the scene: the train's quantities from the train, the verge's from
    the verge (the quantities both take are one value, stated once for the scene)."""
    train, verge = instances(scene)
    values: dict[str, float] = {}
    for entry in DECK:
        instance = train if TRAIN in entry.users else verge
        if instance in scene.fmus:
            values[entry.name] = parameter(scene, instance, entry.name)
    return data_from(values)


def check(scene: Any) -> list[str]:
    """Every broken rule of the scene's design (none where its FMUs are told not to check:
    ``check_design = 0``), and a stop condition on the wheel angle that is not the design's
    arming angle."""
    train, verge = instances(scene)
    users = frozenset(
        user
        for user, instance in ((TRAIN, train), (VERGE, verge))
        if instance in scene.fmus and parameter(scene, instance, "check_design") != 0
    )
    d = scene_design(scene)
    problems = [str(v) for v in violations(d, users)]
    cond = scene.stop_when
    if cond is not None and cond.signal == (train, "phi") and cond.rising:
        if not math.isclose(cond.threshold, d.phi_cut, rel_tol=1e-9):
            problems.append(
                f"design rule 'arming angle' broken: scene.stop_when stops at train.phi = "
                f"{cond.threshold / DEG:.6g} deg, the design arms at PHICUTD = "
                f"{d.phi_cut / DEG:.6g} deg (arming_angle); expected the same angle"
            )
    return problems
