"""Every master algorithm, by the name a scene gives its ``master.algorithm``: its typed
settings (orchestrator/master_settings.py) and its factory.

A factory takes the algorithm's settings and the coupled system and returns the master
(orchestrator/masters/macro_step.py, ``Master``); it is named "package.module:function"
and imported only when a run makes its master, so the scene loader reads the settings
from here without importing any master.  Adding a master is its module and one line in
``ALGORITHMS`` (docs/architecture.md, "Adding a master"); everything else the loader and
the studies need is derived from the entries when asked, never copied.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from orchestrator.lazy import resolve
from orchestrator.master_settings import (
    FixedStepSettings,
    RegimeAwareSettings,
    SettingKind,
    Settings,
    kinds_of,
)


@dataclass(frozen=True)
class Algorithm:
    """One master algorithm: its settings class and its factory, (settings, system) ->
    Master, as "package.module:function" or the callable itself.  (Typed loosely: the
    masters and the system import the scene loader, which reads this registry.)"""

    settings: type
    factory: str | Callable[[Any, Any], Any]

    def make(self, settings: Settings, system: Any) -> Any:
        """The master of one run (masters/macro_step.py, ``Master``) on the coupled system."""
        factory = resolve(self.factory) if isinstance(self.factory, str) else self.factory
        return factory(settings, system)


ALGORITHMS: dict[str, Algorithm] = {
    "jacobi": Algorithm(FixedStepSettings, "orchestrator.masters.fixed_step:jacobi"),
    "gauss-seidel": Algorithm(FixedStepSettings, "orchestrator.masters.fixed_step:gauss_seidel"),
    "regime-aware": Algorithm(
        RegimeAwareSettings, "orchestrator.masters.regime_aware_choice:regime_aware"
    ),
}


def algorithm(name: str) -> Algorithm:
    return ALGORITHMS[name]


def step_key(name: str) -> str:
    """The key the master ``name`` reads its step from (its settings' STEP_KEY)."""
    return ALGORITHMS[name].settings.STEP_KEY


def step_keys() -> tuple[str, ...]:
    """The keys the masters read their step from (master_settings.py's module doc)."""
    return tuple(dict.fromkeys(a.settings.STEP_KEY for a in ALGORITHMS.values()))


def setting_kinds() -> dict[str, SettingKind]:
    """Every key a scene's [master] table may hold beyond its algorithm, order and step,
    with its kind."""
    classes = dict.fromkeys(a.settings for a in ALGORITHMS.values())
    return {k: v for cls in classes for k, v in kinds_of(cls).items()}


def tolerance_masters() -> tuple[str, ...]:
    """The masters whose accuracy is set by master.tolerance rather than by their step."""
    return tuple(n for n, a in ALGORITHMS.items() if "tolerance" in kinds_of(a.settings))


def settings_of(
    name: str, step: float, duration: float, options: dict[str, Any], fixed_step: float
) -> Settings:
    """The typed settings of master ``name`` (raises SettingError on a value out of range)."""
    return ALGORITHMS[name].settings.from_options(step, duration, options, fixed_step)
