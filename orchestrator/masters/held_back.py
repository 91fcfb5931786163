"""FMUs the regime-aware master does not roll back: foreign FMUs whose state restore does
not reproduce their state.

Each foreign FMU that declares canGetAndSetFMUstate is checked on a twin before the first
step (``CoupledSystem.restore_faults``) and at every restore after it (the outputs read
just after a restore against those read when the state was saved: restore_check.py).  An
FMU found faulty is held back, from the start or from the macro step after the rollback
that found it: the trials neither step, read, feed nor restore it, and once a trial is
accepted it is stepped once over that step with the inputs read at the step start, as
Jacobi steps it.  The other FMUs keep the error control: the change of their outputs into
the held-back FMU is judged as any input held at the step start, and the change of its
outputs over its step bounds the next step (first order: it cannot be retaken).
"""

from __future__ import annotations

import math

from orchestrator.master_settings import RegimeAwareSettings
from orchestrator.masters.switches import Readings
from orchestrator.recorder import StepStats
from orchestrator.system import CoupledSystem


class HeldBack:
    """Finds the FMUs not to roll back, steps them and bounds the next step by them."""

    def __init__(
        self, system: CoupledSystem, settings: RegimeAwareSettings, stats: StepStats
    ) -> None:
        self.system, self.settings, self.stats = system, settings, stats
        self.names: list[str] = []  # held back, in the order found
        self.scale: dict[tuple[int, int], float] = {}  # running scale of their outputs

    def start(self, t: float) -> None:
        """Check each foreign FMU's restore on a twin; hold back those that fail, watch
        every restore of the others."""
        system = self.system
        for name, fault in system.restore_faults(t, self.settings.first_step).items():
            self._hold(system.index[name], fault, "at the start")
        watched = [
            i
            for i, model in enumerate(system.models)
            if not model.annotated and model.can_get_set_state and i not in system.held_back
        ]
        system.watch_restores(watched)

    def check(self, t: float) -> None:
        """Hold back, from this macro step on, each FMU whose restore failed so far."""
        for i, fault in self.system.restore_failures().items():
            self._hold(i, fault, f"at a rollback to t = {t:.9g} s")

    def _hold(self, i: int, fault: str, when: str) -> None:
        name = self.system.names[i]
        self.system.hold_back(i)
        self.names.append(name)
        self.stats.warnings.append(
            f"FMU {name!r}: restoring its state does not reproduce it ({fault}, found {when}): "
            "it is no longer rolled back; it is stepped once per macro step with the inputs "
            "at the step start, as Jacobi steps it, and the other FMUs keep the error control"
        )

    def step(self, t: float, h: float, before: Readings) -> float:
        """Step the held-back FMUs over the accepted step [t, t+h] and exchange; the longest
        next step their outputs' change allows (inf: none held back)."""
        system = self.system
        if not system.held_back:
            return math.inf
        skipped, system.skipped_steps = system.skipped_steps, 0
        held = system.step_held_back(t, h, before.values, before.ints)
        self.stats.do_steps += len(held) - skipped
        system.exchange()
        worst, tol = 0.0, self.settings.tolerance
        for i in held:
            for k, (a, b) in enumerate(zip(before.values[i], system.values[i], strict=True)):
                key = (i, k)
                scale = max(self.scale.get(key, system.nominal(i, k)), abs(a), abs(b))
                self.scale[key] = scale
                if scale > 0.0:
                    worst = max(worst, abs(b - a) / (tol * scale))
        control = self.settings.control
        return h * control.grow(worst, first_order=True)
