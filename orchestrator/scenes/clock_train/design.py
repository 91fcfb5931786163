"""The design of a clock-train S&A scene: the clock train and bodies its train was given, the
SANDA2V deck of its verge, and the rules they must satisfy before it runs.

Imports only the physics (no scene loader), so the loader can check a design as it reads
a scene.
"""

from __future__ import annotations

from typing import Any

from components.clock_train_design import DESIGN_NAMES, train_violations
from components.clock_train_design import clock_train as train_of
from components.m739_data import M739Data
from components.sanda2v_deck import DECK, VERGE, data_from, verge_violations
from orchestrator.scenes.m739.design import instances, parameter


def train_values(scene: Any) -> dict[str, float]:
    """The clock train's design parameters as the scene gives them (else their defaults)."""
    train, _ = instances(scene)
    return {name: parameter(scene, train, name) for name in DESIGN_NAMES}


def verge_data(scene: Any) -> M739Data:
    """The verge's deck (cards 1-2, its body and the pivots that place it), as the scene gives
    it; the bodies of the train from the train."""
    train, verge = instances(scene)
    values = {n: v for n, v in train_values(scene).items() if n in {e.name for e in DECK}}
    if verge in scene.fmus:
        values.update({e.name: parameter(scene, verge, e.name) for e in DECK if VERGE in e.users})
    return data_from(values)


def check(scene: Any) -> list[str]:
    """Every broken rule of the scene's clock train and verge (none for an FMU told not to
    check: ``check_design = 0``)."""
    train, verge = instances(scene)
    problems: list[str] = []
    if train in scene.fmus and parameter(scene, train, "check_design") != 0:
        problems += [str(v) for v in train_violations(train_of(train_values(scene)))]
    if verge in scene.fmus and parameter(scene, verge, "check_design") != 0:
        problems += [str(v) for v in verge_violations(verge_data(scene))]
    return problems
