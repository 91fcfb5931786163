"""The FMI 2.0 capabilities a master relies on, checked here and nowhere else.

Each FMU's model description says what it can do (``ModelInfo``); a master asks this module
before it relies on a capability: ``lacking`` lists the FMUs of a system without it, and
``require`` refuses a master that cannot do without it, in one line naming the FMU and the
capability.  The regime-aware master rejects and retakes steps (``canGetAndSetFMUstate``)
of varying size (``canHandleVariableCommunicationStepSize``); a fixed-step master varies
its step only where its last one is shortened to land on the stop time or where it lands
on an input signal's breakpoint.  A master that ramps a held input through a step passes
its slope by FMI 2.0's standard call (``canInterpolateInputs``,
fmi2SetRealInputDerivatives) where the FMU declares it and has no input with the role
rate_of that input (``takes_input_derivative``); our own FMUs keep their rate_of input,
whose arithmetic the example runs were validated with.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from orchestrator.errors import RunError

VARIABLE_STEP = "canHandleVariableCommunicationStepSize"
SAVE_STATE = "canGetAndSetFMUstate"
INTERPOLATE_INPUTS = "canInterpolateInputs"

#: What each capability lets a master do, as a message says it an FMU cannot.
_CANNOT = {
    VARIABLE_STEP: "cannot take communication steps of varying size",
    SAVE_STATE: "cannot save and restore its state",
    INTERPOLATE_INPUTS: "cannot interpolate its inputs over a step",
}


def has(model: Any, capability: str) -> bool:
    """Whether an FMU's model description (``ModelInfo``) declares ``capability``."""
    if capability == VARIABLE_STEP:
        return model.can_handle_variable_step
    if capability == SAVE_STATE:
        return model.can_get_set_state
    if capability == INTERPOLATE_INPUTS:
        return model.can_interpolate_inputs
    raise KeyError(f"unknown capability {capability!r}; expected one of {sorted(_CANNOT)}")


@dataclass(frozen=True)
class Shortfall:
    """An FMU of a system that lacks a capability a master needs."""

    fmu: str  # its instance name
    capability: str  # the FMI 2.0 attribute, e.g. "canGetAndSetFMUstate"

    def __str__(self) -> str:
        return f"FMU {self.fmu!r} {_CANNOT[self.capability]} ({self.capability} is false)"


def lacking(system: Any, capabilities: Iterable[str]) -> list[Shortfall]:
    """Every (FMU, capability) of ``capabilities`` that an FMU of ``system`` lacks, in the
    order of the FMUs, then of the capabilities."""
    wanted = tuple(capabilities)
    return [
        Shortfall(name, c)
        for name, model in zip(system.names, system.models, strict=True)
        for c in wanted
        if not has(model, c)
    ]


def takes_input_derivative(model: Any, name: str) -> bool:
    """Whether a master passes the slope of FMU input ``name`` (a continuous Real input
    it does not sample) through fmi2SetRealInputDerivatives: the FMU declares
    canInterpolateInputs and takes no rate of the input through an input with the role
    rate_of it."""
    var = model.variables.get(name)
    return (
        has(model, INTERPOLATE_INPUTS)
        and var is not None
        and var.causality == "input"
        and (var.type, var.variability) == ("Real", "continuous")
        and name not in model.sampled
        and model.with_role("rate_of", name) is None
    )


def require(system: Any, capabilities: Iterable[str], why: str) -> None:
    """Refuse (RunError) where an FMU lacks one of ``capabilities``; ``why`` says what the
    master needs it for, e.g. "which the fixed-step master needs to shorten its last step"."""
    missing = lacking(system, capabilities)
    if missing:
        first = missing[0]
        raise RunError(
            f"{_CANNOT[first.capability]} ({first.capability} is false), {why}", fmu=first.fmu
        )


def regime_aware_shortfalls(system: Any) -> list[Shortfall]:
    """What keeps the regime-aware master from running on ``system``: it takes back
    rejected trials (state) and sizes every step to the error and the switches."""
    return lacking(system, (SAVE_STATE, VARIABLE_STEP))


def regime_aware_fallback(shortfalls: list[Shortfall], fixed: str) -> str:
    """The one-line warning of a regime-aware master that gives up for ``fixed``."""
    return (
        f"{'; '.join(map(str, shortfalls))}, which the regime-aware master needs to reject "
        f"steps and to land on switches: it gives both up and runs {fixed}"
    )


def check_fixed_step(system: Any, start: float, stop: float, h: float) -> None:
    """Refuse a fixed-step master whose step varies on a system with an FMU that cannot
    take steps of varying size: where the step does not divide the span (the last step is
    shortened to land on stop) or where input signals are landed on."""
    n = round((stop - start) / h)
    if abs(n * h - (stop - start)) > 1e-9 * h:
        why = f"a step of {h:g} s that does not divide the span {stop - start:g} s"
    elif system.signals:
        why = "the scene's input signals, whose breakpoints the steps land on"
    else:
        return
    require(system, (VARIABLE_STEP,), f"which the fixed-step master needs with {why}")
