"""The coupled system: the scene's FMU instances and the value transfers between them.

Value references are resolved once; a transfer is one getReal per source and one setReal
per target.  Masters use only this interface, so they never deal with names.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from orchestrator.errors import RunError
from orchestrator.fmu_instance import FmuInstance
from orchestrator.scenario import Scene


@dataclass
class _Feed:
    """Inputs of one instance: (source instance index, index into its read values, input ref)."""

    sources: list[tuple[int, int]]
    refs: list[int]


class CoupledSystem:
    """FMU instances in master order with their connections and recorded signals."""

    def __init__(self, scene: Scene, fmu_paths: dict[str, Path]) -> None:
        self.scene = scene
        self.names = list(scene.master.order)
        self.index = {n: i for i, n in enumerate(self.names)}
        self.instances: list[FmuInstance] = []
        try:
            for name in self.names:
                self.instances.append(FmuInstance(name, fmu_paths[scene.fmus[name].fmu]))
        except Exception:
            self.close()
            raise
        # Real values read from each instance after every step: connection sources first,
        # then recorded reals; integers (regimes) are read separately for recording only.
        self.read_names: list[list[str]] = [[] for _ in self.names]
        for c in scene.connections:
            self._read_slot(*c.source)
        self.record_slots: list[tuple[int, str, int]] = []  # (instance, kind, slot)
        self.int_names: list[list[str]] = [[] for _ in self.names]
        for inst, var in scene.record:
            i = self.index[inst]
            if self.instances[i].is_integer(var):
                self.int_names[i].append(var)
                self.record_slots.append((i, "int", len(self.int_names[i]) - 1))
            else:
                self.record_slots.append((i, "real", self._read_slot(inst, var)))
        self.read_refs = [
            inst.refs(names) for inst, names in zip(self.instances, self.read_names, strict=True)
        ]
        self.int_refs = [
            inst.refs(names) for inst, names in zip(self.instances, self.int_names, strict=True)
        ]
        self.feeds: list[_Feed] = [_Feed([], []) for _ in self.names]
        for c in scene.connections:
            src, dst = self.index[c.source[0]], self.index[c.target[0]]
            slot = self.read_names[src].index(c.source[1])
            self.feeds[dst].sources.append((src, slot))
            self.feeds[dst].refs.extend(self.instances[dst].refs([c.target[1]]))
        self.values: list[list[float]] = [[] for _ in self.names]
        self.int_values: list[list[int]] = [[] for _ in self.names]
        self.record_header = [f"{inst}.{var}" for inst, var in scene.record]

    def _read_slot(self, instance: str, var: str) -> int:
        names = self.read_names[self.index[instance]]
        if var not in names:
            names.append(var)
        return names.index(var)

    # -- life cycle -------------------------------------------------------------------
    def initialize(self) -> None:
        scene = self.scene
        for inst in self.instances:
            spec = scene.fmus[inst.name]
            inst.initialize(scene.start, scene.stop, {**spec.parameters, **spec.inputs})
        # Outputs with direct feedthrough depend on inputs: settle the initial exchange.
        for _ in range(len(self.instances) + 1):
            self.read_all()
            for i in range(len(self.instances)):
                self.feed(i)
        self.read_all()

    def close(self) -> None:
        for inst in self.instances:
            inst.close()

    # -- transfers (hot path) ---------------------------------------------------------
    def read(self, i: int) -> None:
        inst = self.instances[i]
        self.values[i] = inst.get_real(self.read_refs[i]) if self.read_refs[i] else []

    def read_all(self) -> None:
        for i in range(len(self.instances)):
            self.read(i)

    def feed(self, i: int) -> None:
        """Set instance i's inputs from the latest values read from its sources."""
        feed = self.feeds[i]
        if feed.refs:
            values = self.values
            self.instances[i].set_real(feed.refs, [values[s][k] for s, k in feed.sources])

    def step(self, i: int, t: float, h: float) -> None:
        self.instances[i].do_step(t, h)

    def record_row(self, t: float) -> list[float]:
        for i, inst in enumerate(self.instances):
            if self.int_refs[i]:
                self.int_values[i] = inst.get_integer(self.int_refs[i])
        row = [t]
        for i, kind, slot in self.record_slots:
            row.append(self.values[i][slot] if kind == "real" else self.int_values[i][slot])
        return row

    # -- state ------------------------------------------------------------------------
    def get_state(self) -> list[Any]:
        return [inst.get_state() for inst in self.instances]

    def set_state(self, state: list[Any]) -> None:
        for inst, s in zip(self.instances, state, strict=True):
            inst.set_state(s)
        self.read_all()

    def free_state(self, state: list[Any]) -> None:
        for inst, s in zip(self.instances, state, strict=True):
            inst.free_state(s)

    def instance(self, name: str) -> FmuInstance:
        try:
            return self.instances[self.index[name]]
        except KeyError:
            raise RunError(f"no FMU instance {name!r}") from None
