"""The exchanged signals a regime-aware master holds over a step, and how it measures them.

A Real input is held over a macro step.  One an FMU samples as a state at the step start
(``sampled``) carries no hold error of its own and is never averaged; the others are held
at a value standing for the step (their step mean).  An FMU that does not say which of its
inputs are sampled (one from another tool) is a black box: averaging a sampled input would
be wrong at first order, unseen by the error test, so its inputs stay at their step-start
values and their change over the step is the error (first order).  Where such an FMU
declares that it interpolates its inputs (FMI 2.0 ``canInterpolateInputs``), a master that
ramps them passes their slope from the step start by fmi2SetRealInputDerivatives
(``interpolated``; orchestrator/capabilities.py says which inputs).

The error measures are relative to each signal's running scale: its largest magnitude so
far, from its declared FMI ``nominal`` (a speed starting from rest is not held to its first
millionths).
"""

from __future__ import annotations

from typing import Any, NamedTuple

from orchestrator import capabilities
from orchestrator.masters.switches import Readings
from orchestrator.system import CoupledSystem

Slot = tuple[int, int]  # (instance, index of a Real output)


class HeldInput(NamedTuple):
    """One Real input of an FMU, in feed order."""

    source: Slot  # the output that drives it
    averaged: bool  # held at its step mean (else at its step-start value)
    name: str  # the input's name in its FMU
    #: its FMU ramps it from its step-start value by the slope fmi2SetRealInputDerivatives
    #: gives (an FMU's own rate_of input is preferred where it has one)
    interpolated: bool = False


class Slopes(NamedTuple):
    """The inputs of one FMU it ramps by the slopes fmi2SetRealInputDerivatives gives."""

    instance: int
    indices: list[int]  # of the inputs in its instance's feed order
    setter: Any  # sets their first derivatives


class HeldInputs:
    """The held inputs of every FMU, the signals each error measure reads and their running
    scales."""

    def __init__(self, system: CoupledSystem) -> None:
        self.system = system
        held, unannotated, unsloped = set(), set(), set()
        #: per instance, its Real inputs in feed order
        self.inputs: list[list[HeldInput]] = [[] for _ in system.names]
        for c, src in zip(system.connections, system.connection_sources, strict=True):
            if src is None:
                continue
            j = system.index[c.target[0]]
            model = system.models[j]
            sampled = c.target[1] in model.sampled
            if not model.annotated:
                unannotated.add(src)
            elif not sampled:
                held.add(src)
            averaged = model.annotated and not sampled
            interpolated = capabilities.takes_input_derivative(model, c.target[1])
            if not model.annotated and not interpolated:
                unsloped.add(src)
            self.inputs[j].append(HeldInput(src, averaged, c.target[1], interpolated))
        #: every held signal (inputs held at the step start: the error is their change)
        self.signals: list[Slot] = sorted(held | unannotated)
        #: the signals into black boxes (held at the step start whatever the scheme)
        self.unannotated: list[Slot] = sorted(unannotated)
        #: of those, the ones some black box takes with no slope: held through the step even
        #: by a master that passes slopes
        self.unsloped: list[Slot] = sorted(unsloped)
        self.scale = {s: system.nominal(*s) for s in self.signals}
        #: every Real connection source (the midpoint hold's corrector compares them)
        self.outputs: list[Slot] = sorted({s for s in system.connection_sources if s is not None})
        self.out_scale = {s: system.nominal(*s) for s in self.outputs}
        #: the black boxes that receive a connection
        self.black_boxes = sorted(
            {c.target[0] for c in system.connections}
            & {n for n, m in zip(system.names, system.models, strict=True) if not m.annotated}
        )

    def averaged_sources(self, skip: set[int] = frozenset()) -> list[Slot]:
        """The sources of the averaged inputs (of the FMUs not in ``skip``), sorted."""
        return sorted(
            {
                held.source
                for i, inputs in enumerate(self.inputs)
                if i not in skip
                for held in inputs
                if held.averaged
            }
        )

    def interpolated_sources(self) -> list[Slot]:
        """The sources of the inputs FMUs ramp by input derivatives, sorted."""
        return sorted({h.source for inputs in self.inputs for h in inputs if h.interpolated})

    def slopes(self) -> list[Slopes]:
        """Per FMU that takes input derivatives, the inputs it ramps by them."""
        found = []
        for j, inputs in enumerate(self.inputs):
            indices = [k for k, held in enumerate(inputs) if held.interpolated]
            if indices:
                inst = self.system.instances[j]
                refs = inst.refs([inputs[k].name for k in indices])
                found.append(Slopes(j, indices, inst.derivative_setter(refs)))
        return found

    def change_ratio(self, before: Readings, signals: list[Slot], tolerance: float) -> float:
        """Held-input error relative to ``tolerance``: the largest change of the signals
        since ``before`` relative to their scales (first order in the step)."""
        values = self.system.values
        worst = 0.0
        for i, k in signals:
            a, b = before.values[i][k], values[i][k]
            scale = self.scale[(i, k)] = max(self.scale[(i, k)], abs(a), abs(b))
            if scale > 0.0:
                worst = max(worst, abs(b - a) / (tolerance * scale))
        return worst
