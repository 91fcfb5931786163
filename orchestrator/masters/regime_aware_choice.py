"""Which regime-aware algorithm a scene runs: the single-pass master (``master.input_hold =
"extrapolated"``), the midpoint-hold master (``"midpoint"``; ``"start"`` its first-order
form), by default (``"auto"``) the single pass where an FMU reports its own copy of a
partner's state and the midpoint hold elsewhere; or fixed-step Jacobi where an FMU cannot
save and restore its state (no trial could be taken back)."""

from __future__ import annotations

from dataclasses import replace

from orchestrator.masters.fixed_step import fixed_step_master
from orchestrator.masters.macro_step import Master
from orchestrator.masters.regime_aware import RegimeAwareMaster
from orchestrator.masters.single_pass import SinglePassMaster, judged_by_copies
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
    settings = replace(scene.master.settings, input_hold=input_hold(system, scene))
    stats.extra["input_hold"] = settings.input_hold
    algorithm = SinglePassMaster if settings.single_pass else RegimeAwareMaster
    return algorithm(system, settings, stats)


#: The single pass asks its FMUs for this fraction of its own tolerance, at most
#: FMU_TOLERANCE_MAX: their integration error stays below the coupling error it controls
#: (M739 at 1e-2: turns error 1.11e-5 against 1.09e-5 at their own 1e-8, about 10 % less
#: time; the monolithic M739 leaves the escapement's path at 5e-5 and looser).  A tenth,
#: not a thousandth: the verge's and trains' steps at 1e-4 and 1e-5 were integrated a
#: hundred times finer than the coupling needs (M739 at 1e-5: 4365 integrator steps against
#: 5615, 16 % fewer Python calls, turns error 4.6e-7 against 8.1e-7; at 1e-4 3.0e-6 against
#: 2.3e-6; the clock train 6.1e-6 against 6.7e-6 at 1e-5, 1.45e-5 against 1.22e-5 at 1e-4).
FMU_TOLERANCE_FRACTION = 1e-1
FMU_TOLERANCE_MAX = 1e-5


def fmu_tolerance(system: CoupledSystem, scene: Scene) -> float | None:
    """The integration tolerance a scene's master asks of its FMUs (fmi2SetupExperiment):
    the single pass's (with ``input_hold`` "extrapolated", or "auto" where it runs); None,
    the FMUs' own, for every other master (their validated numbers stay as they are)."""
    settings = scene.master.settings
    if scene.master.algorithm != "regime-aware" or settings is None:
        return None
    if input_hold(system, scene) == "extrapolated":
        return min(FMU_TOLERANCE_MAX, FMU_TOLERANCE_FRACTION * settings.tolerance)
    return None


def input_hold(system: CoupledSystem, scene: Scene) -> str:
    """The regime-aware master's ``input_hold`` with "auto" resolved: the single pass
    ("extrapolated") where an FMU's copy of its partner judges the coupling; elsewhere the
    midpoint hold, as the single pass's error test holds steps near the stiffest coupling's
    stability limit (press feed Run 1 at 1e-3: 4.8x its reference, the midpoint hold 2.2x)."""
    hold = scene.master.settings.input_hold
    if hold != "auto":
        return hold
    return "extrapolated" if judged_by_copies(system) else "midpoint"
