"""The regime-aware master's factory: which algorithm a scene runs.

The single-pass trials (``master.input_hold = "extrapolated"``), the midpoint hold
(``"midpoint"``; ``"start"`` its first-order form), by default (``"auto"``, resolved here
once) the single pass where an FMU reports its own copy of a partner's state and the
midpoint hold elsewhere; or fixed-step Jacobi where an FMU cannot save and restore its
state (no trial could be taken back)."""

from __future__ import annotations

from dataclasses import replace

from orchestrator import capabilities
from orchestrator.master_settings import RegimeAwareSettings
from orchestrator.masters.copies import judged_by_copies
from orchestrator.masters.fixed_step import FixedStepMaster
from orchestrator.masters.macro_step import Master
from orchestrator.masters.midpoint_trial import MidpointTrials
from orchestrator.masters.regime_aware import RegimeAwareMaster
from orchestrator.masters.single_pass import SinglePassTrials
from orchestrator.recorder import StepStats
from orchestrator.system import CoupledSystem


def regime_aware(settings: RegimeAwareSettings, system: CoupledSystem) -> Master:
    """The regime-aware master with ``input_hold`` resolved; fixed-step Jacobi where an FMU
    cannot save and restore its state or take steps of varying size
    (orchestrator/capabilities.py)."""
    shortfalls = capabilities.regime_aware_shortfalls(system)
    if shortfalls:
        # Without rollback and varying steps no trial can be taken back: say what is given
        # up, and couple the way every tool can.
        stats = StepStats()
        stats.warnings.append(
            capabilities.regime_aware_fallback(shortfalls, settings.jacobi_words())
        )
        return FixedStepMaster(settings.jacobi(), system, sequential=False, stats=stats)
    resolved = replace(settings, input_hold=input_hold(settings, system))
    trials = SinglePassTrials if resolved.single_pass else MidpointTrials
    return RegimeAwareMaster(resolved, system, trials)


def input_hold(settings: RegimeAwareSettings, system: CoupledSystem) -> str:
    """``input_hold`` with "auto" resolved: the single pass ("extrapolated") where an FMU's
    copy of its partner judges the coupling; elsewhere the midpoint hold, as the single
    pass's error test holds steps near the stiffest coupling's stability limit
    (docs/measurements.md: the press feed)."""
    if settings.input_hold != "auto":
        return settings.input_hold
    return "extrapolated" if judged_by_copies(system) else "midpoint"
