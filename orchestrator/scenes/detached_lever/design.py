"""The design of a detached-lever scene: Monday's deck each DetachedLever was given, and the
rules of Monday's model it must satisfy before it runs.

Imports only the physics (no scene loader), so the loader can check a design as it reads a
scene.
"""

from __future__ import annotations

from typing import Any

from components.design_rules import Violation
from components.detached_lever_design import LeverDesign, violations

LEVER_FMU = "DetachedLever"


def levers(scene: Any) -> list[str]:
    """The scene's DetachedLever instances, in scene order."""
    return [name for name, spec in scene.fmus.items() if spec.component == LEVER_FMU]


def parameters(scene: Any, instance: str) -> dict[str, float]:
    """Every parameter of a lever: as the scene gives it, else its default."""
    values = {v.name: v.start for v in scene.component_class(instance).variables("parameter")}
    values.update(scene.fmus[instance].parameters)
    return values


def scene_design(scene: Any, instance: str) -> LeverDesign:
    return LeverDesign.of(parameters(scene, instance))


def check(scene: Any) -> list[str]:
    """Every broken rule of every lever's design, each naming its instance."""
    problems = []
    for instance in levers(scene):
        for v in violations(scene_design(scene, instance)):
            problems.append(str(Violation(v.rule, f"fmus.{instance}: {v.detail}")))
    return problems
