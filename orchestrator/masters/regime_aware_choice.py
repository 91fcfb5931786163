"""Which regime-aware algorithm a scene runs: the single-pass master (``master.input_hold =
"extrapolated"``), the midpoint-hold master (``"midpoint"``; ``"start"`` its first-order
form), by default (``"auto"``) the single pass where an FMU reports its own copy of a
partner's state and the midpoint hold elsewhere; or fixed-step Jacobi where an FMU cannot
save and restore its state, or whose restore does not reproduce a step (no trial could be
taken back)."""

from __future__ import annotations

from dataclasses import replace

from orchestrator.masters.copies import judged_by_copies
from orchestrator.masters.fixed_step import fixed_step_master
from orchestrator.masters.macro_step import Master
from orchestrator.masters.midpoint_trial import MidpointTrials
from orchestrator.masters.regime_aware import RegimeAwareMaster
from orchestrator.masters.single_pass import SinglePassTrials
from orchestrator.masters.switches import Landing
from orchestrator.recorder import StepStats
from orchestrator.scene_model import Scene
from orchestrator.system import CoupledSystem


def regime_aware(system: CoupledSystem, scene: Scene, stats: StepStats) -> Master:
    """The regime-aware master of ``scene``; fixed-step Jacobi where an FMU cannot save and
    restore its state."""
    cannot_save = [
        n for n, m in zip(system.names, system.models, strict=True) if not m.can_get_set_state
    ]
    fixed = (
        f"fixed-step Jacobi in steps of {scene.master.step:g} s (no error control, switches "
        "seen only at communication points)"
    )
    if cannot_save:
        # Without rollback no trial can be taken back: say what is given up, and couple
        # the way every tool can.
        stats.extra.setdefault("warnings", []).append(
            f"FMU {', '.join(map(repr, cannot_save))} cannot save and restore its state "
            "(canGetAndSetFMUstate is false), which the regime-aware master needs to reject "
            f"steps and to land on switches: it gives both up and runs {fixed}"
        )
        return fixed_step_master(system, scene, stats, scene.master.step, sequential=False)
    # A restore that does not reproduce a step would make every rollback change the
    # answer: such an FMU is not rolled back, and no FMU is, as no trial could be retaken.
    faults = system.restore_faults(scene.start, scene.master.settings.first_step)
    if faults:
        for name, fault in faults.items():
            stats.extra.setdefault("warnings", []).append(
                f"FMU {name!r}: restoring its state does not reproduce its step ({fault}): "
                f"it is not rolled back; the regime-aware master runs {fixed}"
            )
        return fixed_step_master(system, scene, stats, scene.master.step, sequential=False)
    settings = replace(scene.master.settings, input_hold=input_hold(system, scene))
    stats.extra["input_hold"] = settings.input_hold
    landing = Landing.of(settings)
    trials = SinglePassTrials if settings.single_pass else MidpointTrials
    scheme = trials(system, settings, stats, landing)
    return RegimeAwareMaster(system, settings, stats, scheme, landing)


def fmu_tolerance(system: CoupledSystem, scene: Scene) -> float | None:
    """The integration tolerance a scene's master asks of its FMUs (fmi2SetupExperiment):
    the single pass's (with ``input_hold`` "extrapolated", or "auto" where it runs); None,
    the FMUs' own, for every other master (their validated numbers stay as they are)."""
    settings = scene.master.settings
    if scene.master.algorithm != "regime-aware" or settings is None:
        return None
    if input_hold(system, scene) == "extrapolated":
        return settings.single_pass_control.fmu_tolerance(settings.tolerance)
    return None


def input_hold(system: CoupledSystem, scene: Scene) -> str:
    """The regime-aware master's ``input_hold`` with "auto" resolved: the single pass
    ("extrapolated") where an FMU's copy of its partner judges the coupling; elsewhere the
    midpoint hold, as the single pass's error test holds steps near the stiffest coupling's
    stability limit (docs/measurements.md: the press feed)."""
    hold = scene.master.settings.input_hold
    if hold != "auto":
        return hold
    return "extrapolated" if judged_by_copies(system) else "midpoint"
