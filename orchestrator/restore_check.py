"""Checking a foreign FMU's state restores as a run goes (issue: a restore that does not
reproduce the state it saved makes every rollback change the answer).

The start check (``CoupledSystem.restore_faults``) takes one step on a twin; a fault that
acts only later (after a set-point jump, say) passes it.  So every restore of a watched
FMU is checked where it happens: the outputs read just after ``fmi2SetFMUstate`` must be,
bit for bit, those read just after the ``fmi2GetFMUstate`` that saved it (one getReal and
one getInteger more per save and per restore).  A fault in a hidden state that no output
shows at once is not seen here.
"""

from __future__ import annotations

import struct
from typing import Any


class RestoreCheck:
    """The outputs of one FMU instance at each state saved, compared at each restore."""

    def __init__(self, inst: Any) -> None:
        outputs = [v for v in inst.model_description.modelVariables if v.causality == "output"]
        self.real_names = [v.name for v in outputs if v.type == "Real"]
        self.int_names = [v.name for v in outputs if v.type in ("Integer", "Enumeration")]
        reals, ints = self.real_names, self.int_names
        self._reals = inst.getter(inst.refs(reals)) if reals else None
        self._ints = inst.getter(inst.refs(ints), integer=True) if ints else None
        self.at_save: dict[int, tuple[list[float], list[int]]] = {}
        self.failure: str | None = None  # what differed at the first restore that failed

    def _outputs(self) -> tuple[list[float], list[int]]:
        reals = self._reals() if self._reals is not None else []
        ints = self._ints() if self._ints is not None else []
        return list(reals), list(ints)

    def saved(self, state: Any) -> None:
        self.at_save[state.value] = self._outputs()

    def restored(self, state: Any) -> None:
        saved = self.at_save.get(state.value)
        if saved is None or self.failure is not None:
            return
        now = self._outputs()
        for name, a, b in zip(self.real_names, saved[0], now[0], strict=True):
            if struct.pack("<d", a) != struct.pack("<d", b):
                self.failure = f"output {name} differs by {b - a:.3g} ({a!r} then {b!r})"
                return
        for name, a, b in zip(self.int_names, saved[1], now[1], strict=True):
            if a != b:
                self.failure = f"output {name} differs ({a} then {b})"
                return

    def freed(self, state: Any) -> None:
        self.at_save.pop(state.value, None)
