"""Scene families: one package per family of scenes (M739, clock train, press feed, ...).

Each package ``orchestrator/scenes/<family>/`` declares ``FAMILY`` (a ``SceneFamily``) in its
``__init__``: what its analysis and reference read from a scene, and where they live. Its
``report`` module holds the analysis, plot and reference adapter; ``monolithic`` (where there
is one) the whole mechanism as one ODE with exact events. A family is registered by being a
package here: the registries below are derived from the packages.
"""

from __future__ import annotations

import pkgutil
from functools import cache
from importlib import import_module
from pathlib import Path

from orchestrator.lazy import LazyRegistry
from orchestrator.scenes.family import SceneFamily, SharedParameter

#: Family names, as ``[report] family`` / ``reference`` name them.
FAMILY_NAMES: tuple[str, ...] = tuple(
    sorted(m.name for m in pkgutil.iter_modules([str(Path(__file__).parent)]) if m.ispkg)
)


@cache
def family(name: str) -> SceneFamily:
    """The declaration of family ``name`` (imports only its package's ``__init__``)."""
    return import_module(f"{__name__}.{name}").FAMILY


@cache
def shared_parameters(names: tuple[str, ...]) -> dict[str, SharedParameter]:
    """The shared parameters of families ``names`` (a scene's [report] family and
    reference), by name, the FMUs that take one joined: a family's shared parameters hold
    in its own scenes only."""
    found: dict[str, SharedParameter] = {}
    for name in names:
        for p in family(name).shared:
            known = found.get(p.name)
            components = p.components | (known.components if known else frozenset())
            found[p.name] = SharedParameter(
                p.name, components, known.meaning if known else p.meaning
            )
    return found


def _registry(role: str) -> LazyRegistry:
    """Name -> callable for every family that has ``role`` (analysis, plot, reference)."""
    return LazyRegistry(
        {n: getattr(family(n), role) for n in FAMILY_NAMES if getattr(family(n), role)}
    )


#: (scene, header, data, options) -> {name: {"value", "unit"}}
ANALYSES = _registry("analysis")
#: (scene, header, data, path) -> None, a PNG after a completed run
PLOTS = _registry("plot")
#: (scene) -> Reference
REFERENCES = _registry("reference")
#: (scene, path) -> None, a PNG of the design to scale
DRAWINGS = _registry("drawing")
