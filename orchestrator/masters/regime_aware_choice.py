"""Which regime-aware algorithm a scene runs: the midpoint-hold master (the default), the
single-pass master (``master.input_hold = "extrapolated"``), or fixed-step Jacobi where an
FMU cannot save and restore its state (no trial could be taken back)."""

from __future__ import annotations

from orchestrator.masters.fixed_step import fixed_step_master
from orchestrator.masters.macro_step import Master
from orchestrator.masters.regime_aware import RegimeAwareMaster
from orchestrator.masters.single_pass import SinglePassMaster
from orchestrator.recorder import StepStats
from orchestrator.scenario import Scene
from orchestrator.system import CoupledSystem


def regime_aware(system: CoupledSystem, scene: Scene, stats: StepStats) -> Master:
    """The regime-aware master of ``scene``; fixed-step Jacobi where an FMU cannot save and
    restore its state."""
    cannot_save = [
        n for n, m in zip(system.names, system.models, strict=True) if not m.can_get_set_state
    ]
    if cannot_save:
        # Without rollback no trial can be taken back: say what is given up, and couple
        # the way every tool can.
        stats.extra.setdefault("warnings", []).append(
            f"FMU {', '.join(map(repr, cannot_save))} cannot save and restore its state "
            "(canGetAndSetFMUstate is false), which the regime-aware master needs to reject "
            "steps and to land on switches: it gives both up and runs fixed-step Jacobi in "
            f"steps of {scene.master.step:g} s (no error control, switches seen only "
            "at communication points)"
        )
        return fixed_step_master(system, scene, stats, scene.master.step, sequential=False)
    settings = scene.master.settings
    algorithm = SinglePassMaster if settings.single_pass else RegimeAwareMaster
    return algorithm(system, settings, stats)
