"""The coupled system: the scene's FMU instances and the value transfers between them.

Value references are resolved once; a transfer is one getReal per source and one setReal
per target.  Masters use only this interface, so they never deal with names.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from orchestrator.errors import RunError
from orchestrator.fmu_instance import FmuInstance
from orchestrator.restore_check import RestoreCheck
from orchestrator.scene_model import Scene
from orchestrator.signals import scene_signals

#: which of values, ints, bools a value of a kind is read into (``record_row``)
_KIND_LISTS = {"real": 0, "int": 1, "bool": 2}


@dataclass
class _Feed:
    """Inputs of one instance: (source instance, slot in its read values) and input refs."""

    real_sources: list[tuple[int, int]]
    real_refs: list[int]
    int_sources: list[tuple[int, int]]
    int_refs: list[int]


@dataclass
class Watch:
    """What a master watches on one instance: regime, event indicators, last event time."""

    regime: int | None  # slot in the instance's integer values
    indicators: list[int]  # slots in its real values (outputs named ind_*)
    indicator_names: list[str]
    t_event: int | None  # slot in its real values


class CoupledSystem:
    """FMU instances in master order with their connections and recorded signals."""

    _dependent: list[int] | None = None  # see input_dependent
    _dependent_kinds: list[tuple[bool, ...]] = []  # per instance: Reals, Integers, Booleans

    def __init__(self, scene: Scene, fmu_paths: dict[str, Path] | None = None) -> None:
        """``fmu_paths`` (instance -> FMU file) overrides the files the scene names."""
        self.scene = scene
        self.names = list(scene.master.order)
        self.index = {n: i for i, n in enumerate(self.names)}
        #: what the orchestrator knows of each instance's FMU, in master order
        self.models = [scene.fmus[n].model for n in self.names]
        self.connections = scene.connections
        self.instances: list[FmuInstance] = []
        paths = {n: spec.path for n, spec in scene.fmus.items()} | (fmu_paths or {})
        self.paths: dict[str, Path] = paths
        #: the integration tolerance asked of the FMUs (set by the master's setup)
        self.tolerance: float | None = None
        try:
            for name in self.names:
                self.instances.append(FmuInstance(name, paths[name]))
        except Exception:
            self.close()
            raise
        # Values read from each instance after every step, one getReal and one getInteger
        # per instance: connection sources, recorded signals, and what masters watch.
        self.real_names: list[list[str]] = [[] for _ in self.names]
        self.int_names: list[list[str]] = [[] for _ in self.names]
        self.bool_names: list[list[str]] = [[] for _ in self.names]  # recorded Booleans
        self.feeds = [_Feed([], [], [], []) for _ in self.names]
        #: per connection, (source instance, slot) of a Real source, None for an Integer one
        self.connection_sources: list[tuple[int, int] | None] = []
        for c in scene.connections:
            src, dst = self.index[c.source[0]], self.index[c.target[0]]
            kind, slot = self._slot(src, c.source[1])
            self.connection_sources.append((src, slot) if kind == "real" else None)
            target_ref = self.instances[dst].refs([c.target[1]])
            if kind != ("int" if self.instances[dst].is_integer(c.target[1]) else "real"):
                raise RunError(f"connection {c.source} -> {c.target} joins Real and Integer")
            if kind == "int":
                self.feeds[dst].int_sources.append((src, slot))
                self.feeds[dst].int_refs.extend(target_ref)
            else:
                self.feeds[dst].real_sources.append((src, slot))
                self.feeds[dst].real_refs.extend(target_ref)
        self.record_slots = [
            (self.index[inst],) + self._slot(self.index[inst], var) for inst, var in scene.record
        ]
        # the same as (0 Real, 1 Integer, 2 Boolean; instance, slot): read off at every row
        self._record_plan = [
            (_KIND_LISTS.get(kind, 2), i, slot) for i, kind, slot in self.record_slots
        ]
        self.watches = [self._watch(i) for i in range(len(self.names))]
        self.stop_slot: tuple[int, int] | None = None
        if scene.stop_when is not None:
            inst, var = scene.stop_when.signal
            self.stop_slot = (self.index[inst], self._slot(self.index[inst], var)[1])
        self.real_refs = [
            inst.refs(n) for inst, n in zip(self.instances, self.real_names, strict=True)
        ]
        self.int_refs = [
            inst.refs(n) for inst, n in zip(self.instances, self.int_names, strict=True)
        ]
        # Prepared transfers (hot path); None where there is nothing to transfer.
        self._get_reals = [
            inst.getter(refs) if refs else None
            for inst, refs in zip(self.instances, self.real_refs, strict=True)
        ]
        self._get_ints = [
            inst.getter(refs, integer=True) if refs else None
            for inst, refs in zip(self.instances, self.int_refs, strict=True)
        ]
        self._set_reals = [
            inst.setter(f.real_refs) if f.real_refs else None
            for inst, f in zip(self.instances, self.feeds, strict=True)
        ]
        self._set_ints = [
            inst.setter(f.int_refs, integer=True) if f.int_refs else None
            for inst, f in zip(self.instances, self.feeds, strict=True)
        ]
        self._get_bools = [
            inst.getter(inst.refs(names), boolean=True) if names else None
            for inst, names in zip(self.instances, self.bool_names, strict=True)
        ]
        #: per instance, (its restore count, values) last set through ``feed``
        self._fed_reals: list[tuple[int, list[float]] | None] = [None for _ in self.names]
        self._fed_ints: list[tuple[int, list[int]] | None] = [None for _ in self.names]
        #: per instance, its (changes, moves) counts when its values were last read
        self._read_at: list[tuple[int, int] | None] = [None for _ in self.names]
        self.values: list[list[float]] = [[] for _ in self.names]
        self.ints: list[list[int]] = [[] for _ in self.names]
        self.bools: list[list[int]] = [[] for _ in self.names]
        self.record_header = [f"{inst}.{var}" for inst, var in scene.record]
        #: inputs that vary in time: fed around every doStep; masters land on breakpoints
        self.signals = scene_signals(scene)
        self.signals.bind(
            self.names, lambda n, v: self.instance(n).setter(self.instance(n).refs(v))
        )
        self._drive = self.signals.apply if self.signals else None  # hot path: no call
        #: FMUs not rolled back (their restore does not reproduce a step): no trial steps,
        #: reads, feeds or restores them; the master steps each once per macro step
        #: (``step_held_back``).  Empty for every scene whose FMUs restore faithfully.
        self.held_back: set[int] = set()
        #: doSteps of held-back FMUs the masters asked for and that were not taken
        self.skipped_steps = 0
        self.restore_checks: dict[int, RestoreCheck] = {}  # see watch_restores

    def _slot(self, i: int, var: str) -> tuple[str, int]:
        inst = self.instances[i]
        kind = "int" if inst.is_integer(var) else "bool" if inst.is_boolean(var) else "real"
        names = {"int": self.int_names, "bool": self.bool_names, "real": self.real_names}[kind][i]
        if var not in names:
            names.append(var)
            self._dependent = None  # one more value read: which FMUs to read again may change
        return kind, names.index(var)

    def _watch(self, i: int) -> Watch:
        """What the FMU declares for masters to watch (nothing, for a black box)."""
        model = self.scene.fmus[self.names[i]].model
        return Watch(
            regime=self._slot(i, model.regime)[1] if model.regime else None,
            indicators=[self._slot(i, n)[1] for n in model.indicators],
            indicator_names=list(model.indicators),
            t_event=self._slot(i, model.event_time)[1] if model.event_time else None,
        )

    def nominal(self, i: int, k: int) -> float:
        """The declared nominal of instance i's Real read slot k (0 where none is declared):
        the floor of a relative measure of that signal."""
        var = self.models[i].variables.get(self.real_names[i][k])
        nominal = var.nominal if var is not None else None
        return abs(nominal) if nominal is not None else 0.0

    def real_output_slot(self, i: int, var: str) -> int:
        """Slot of instance i's Real output ``var`` in its read values, read from now on."""
        kind, slot = self._slot(i, var)
        if kind != "real":
            raise RunError(f"{self.names[i]}.{var} is not a Real variable")
        inst = self.instances[i]
        self.real_refs[i] = inst.refs(self.real_names[i])
        self._get_reals[i] = inst.getter(self.real_refs[i])
        self.read(i)
        return slot

    # -- life cycle -------------------------------------------------------------------
    def initialize(self) -> None:
        """Instantiate every FMU with its parameters and start values, and the integration
        tolerance the master's setup asked of them (``tolerance``; None: their own)."""
        scene = self.scene
        for inst in self.instances:
            spec = scene.fmus[inst.name]
            values = {**spec.parameters, **spec.inputs}
            inst.initialize(scene.start, scene.stop, values, self.tolerance)
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
        if self.held_back and i in self.held_back:
            return  # its values stay those of the step start until its own step
        self._read(i)

    def _read(self, i: int, kinds: tuple[bool, bool, bool] = (True, True, True)) -> None:
        """Read instance i's Real, Integer and Boolean values, those of ``kinds``."""
        reals, ints, bools = kinds
        get = self._get_reals[i]
        if reals and get is not None:
            self.values[i] = get()
        get = self._get_ints[i]
        if ints and get is not None:
            self.ints[i] = get()
        get = self._get_bools[i]
        if bools and get is not None:
            self.bools[i] = get()
        inst = self.instances[i]
        self._read_at[i] = (inst.changes, inst.moves)

    def _read_again(self, i: int) -> None:
        """Read instance i again after a feed: nothing if no call since its last read could
        change its values; if only sets were made since, only its values that may depend on
        inputs (Integers, say, that are the FMU's own state stay as read)."""
        if self.held_back and i in self.held_back:
            return
        inst, at = self.instances[i], self._read_at[i]
        if at is None or at[1] != inst.moves:
            self.read(i)
            return
        if at[0] != inst.changes:
            self._read(i, self._dependent_kinds[i])

    def input_dependent(self) -> list[int]:
        """The instances some of whose read values may change when their inputs are set (an
        output the FMU declares to depend on an input, one it says nothing about, anything
        but an output): those to read again after a feed.  Our crank drive, for one, has
        none: its outputs follow its state."""
        if self._dependent is None:
            self._dependent_kinds = [
                tuple(self._reads_feedthrough(i, names[i]) for names in self._read_names)
                for i in range(len(self.names))
            ]
            self._dependent = [i for i, kinds in enumerate(self._dependent_kinds) if any(kinds)]
        return self._dependent

    def exchange(self) -> None:
        """Give every FMU the others' newest outputs and read again those whose read values
        may depend on their inputs: the values of one consistent instant."""
        for i in range(len(self.instances)):
            self.feed(i)
        for i in self.input_dependent():
            self._read_again(i)

    @property
    def _read_names(self) -> tuple[list[list[str]], ...]:
        return self.real_names, self.int_names, self.bool_names

    def _reads_feedthrough(self, i: int, names: list[str]) -> bool:
        """Whether some of ``names``, values read from instance i, may depend on its inputs."""
        model = self.models[i]
        for name in names:
            var = model.variables.get(name)
            if var is None or var.causality != "output":
                return True
            depends = model.dependencies.get(name)
            if depends is None or depends:
                return True
        return False

    def read_all(self) -> None:
        for i in range(len(self.instances)):
            self.read(i)

    def feed(
        self, i: int, reals: list[float] | None = None, ints: list[list[int]] | None = None
    ) -> None:
        """Set instance i's inputs from the latest values read from its sources (its Real
        inputs from ``reals`` instead, when given, in the order of ``feeds[i]``; its Integer
        inputs from ``ints``, values read like ``self.ints``, when given)."""
        if self.held_back and i in self.held_back:
            return  # fed the step start's values at its own step
        self._feed(i, reals, ints)

    def _feed(self, i: int, reals: list[float] | None, ints: list[list[int]] | None) -> None:
        feed = self.feeds[i]
        # Values equal to those the FMU holds are not set again: a set makes our FMUs
        # recompute their outputs, and a step's held inputs are often the ones the exchange
        # at its start set.  A restored state brings its own inputs (``restores``).
        restores = self.instances[i].restores
        set_reals = self._set_reals[i]
        if set_reals is not None:
            if reals is None:
                values = self.values
                reals = [values[s][k] for s, k in feed.real_sources]
            if self._fed_reals[i] != (restores, reals):
                set_reals(reals)
                self._fed_reals[i] = (restores, reals)
        set_ints = self._set_ints[i]
        if set_ints is not None:
            ints = self.ints if ints is None else ints
            values = [ints[s][k] for s, k in feed.int_sources]
            if self._fed_ints[i] != (restores, values):
                set_ints(values)
                self._fed_ints[i] = (restores, values)

    def step(self, i: int, t: float, h: float) -> None:
        if self.held_back and i in self.held_back:
            self.skipped_steps += 1
            return
        self._do_step(i, t, h)

    def _do_step(self, i: int, t: float, h: float) -> None:
        drive = self._drive
        if drive is None:
            self.instances[i].do_step(t, h)
        else:  # the signals' values at the step start, held over it (as FMPy, libcosim)
            drive(i, t)
            self.instances[i].do_step(t, h)

    def jump_signals(self, t: float) -> None:
        """At a signal's jump at t, located as a switch: every driven input takes its value
        after the jump (the row after the switch shows it, the exchange there carries it),
        and what depends on it is read again."""
        if self._drive is None:
            return
        for i in range(len(self.instances)):
            self._drive(i, t)
        for i in self.input_dependent():
            self.read(i)

    def record_row(self, t: float) -> list[float]:
        lists = (self.values, self.ints, self.bools)
        row = [t]
        row += [lists[kind][i][slot] for kind, i, slot in self._record_plan]
        return row

    def stop_indicator(self) -> float | None:
        """Signed distance to the scene's stop condition: reaches 0 when it is met."""
        if self.stop_slot is None:
            return None
        cond = self.scene.stop_when
        value = self.values[self.stop_slot[0]][self.stop_slot[1]]
        return cond.threshold - value if cond.rising else value - cond.threshold

    def regimes(self) -> list[int | None]:
        return [
            self.ints[i][w.regime] if w.regime is not None else None
            for i, w in enumerate(self.watches)
        ]

    def indicators(self) -> list[list[float]]:
        return [[self.values[i][k] for k in w.indicators] for i, w in enumerate(self.watches)]

    # -- state ------------------------------------------------------------------------
    def get_state(self) -> list[Any]:
        """Every FMU's state (None for one held back)."""
        if not self.held_back and not self.restore_checks:
            return [inst.get_state() for inst in self.instances]
        states = []
        for i, inst in enumerate(self.instances):
            state = None if i in self.held_back else inst.get_state()
            check = self.restore_checks.get(i)
            if check is not None and state is not None:
                check.saved(state)
            states.append(state)
        return states

    def set_state(
        self, state: list[Any], values: tuple[list[list[float]], list[list[int]]] | None = None
    ) -> None:
        """Restore every FMU and what was read from it: ``values``, the (Real, Integer)
        values read when the states were saved, when the caller has them (reading again
        gives the same numbers), else read again."""
        self.restore(state)
        if values is None:
            self.read_all()
        else:
            self.values, self.ints = list(values[0]), list(values[1])
            for i, get in enumerate(self._get_bools):  # recorded Booleans: read again
                if get is not None:
                    self.bools[i] = get()

    def restore(self, state: list[Any]) -> None:
        """Restore every FMU without reading it (``values`` keep what was read before): for
        a caller that feeds them given values and steps or reads them next."""
        if not self.held_back and not self.restore_checks:
            for inst, s in zip(self.instances, state, strict=True):
                inst.set_state(s)
            return
        for i, (inst, s) in enumerate(zip(self.instances, state, strict=True)):
            if s is None or i in self.held_back:
                continue
            inst.set_state(s)
            check = self.restore_checks.get(i)
            if check is not None:
                check.restored(s)

    def watch_restores(self, which: list[int]) -> None:
        """Check every restore of the instances ``which`` from now on: the outputs read
        just after it must be, bit for bit, those read when the state was saved; the first
        that are not are kept in ``restore_failures``."""
        for i in which:
            self.restore_checks[i] = RestoreCheck(self.instances[i])

    def restore_failures(self) -> dict[int, str]:
        """Instance -> what differed, for the watched instances a restore failed (each
        once: it is no longer watched)."""
        failed = {i: c.failure for i, c in self.restore_checks.items() if c.failure}
        for i in failed:
            del self.restore_checks[i]
        return failed

    def hold_back(self, i: int) -> None:
        """Roll instance i back no more: from the next macro step on it is stepped once per
        macro step by ``step_held_back``."""
        self.held_back.add(i)
        self.restore_checks.pop(i, None)

    def step_held_back(
        self, t: float, h: float, values: list[list[float]], ints: list[list[int]]
    ) -> list[int]:
        """Step every held-back FMU over [t, t+h] with its inputs from ``values`` and
        ``ints`` (the values read at t, as Jacobi feeds them), then read it; the instances
        stepped."""
        held = sorted(self.held_back)
        for i in held:
            self._feed(i, [values[s][k] for s, k in self.feeds[i].real_sources], ints)
            self._do_step(i, t, h)
        for i in held:
            self._read(i)
        return held

    def restore_faults(self, t: float, h: float) -> dict[str, str]:
        """The FMUs, not ours (ours carry our vendor annotation and restore bit for bit),
        that save and restore their state but whose restore does not reproduce a step of h
        from t: instance name -> what differs (``FmuInstance.restore_fault``).  Each is
        checked on a twin, initialized and fed as it is: a faulty restore could not leave
        the instance itself as it was.  A fault that acts only later is found at the restore
        (``watch_restores``)."""
        faults = {}
        for i, (name, model) in enumerate(zip(self.names, self.models, strict=True)):
            if model.annotated or not model.can_get_set_state:
                continue
            twin = FmuInstance(name, self.paths[name])
            try:
                fault = twin.restore_fault(self._twin_step(i, twin, t, h))
            finally:
                twin.close()
            if fault is not None:
                faults[name] = fault
        return faults

    def _twin_step(self, i: int, twin: FmuInstance, t: float, h: float) -> Callable[[], None]:
        """Initialize ``twin`` like instance i, give it the inputs instance i holds now, and
        return its step of h from t, driven by the scene's signals as ``step`` drives."""
        spec = self.scene.fmus[self.names[i]]
        twin.initialize(
            self.scene.start, self.scene.stop, {**spec.parameters, **spec.inputs}, self.tolerance
        )
        feed = self.feeds[i]
        if feed.real_refs:
            twin.set_real(feed.real_refs, [self.values[s][k] for s, k in feed.real_sources])
        if feed.int_refs:
            twin.fmu.setInteger(feed.int_refs, [self.ints[s][k] for s, k in feed.int_sources])
        driven = [(v, sig) for (n, v), sig in self.signals.driven.items() if n == self.names[i]]
        set_driven = twin.setter(twin.refs([v for v, _ in driven])) if driven else None

        def step() -> None:
            if set_driven is not None:
                set_driven([sig.value(t) for _, sig in driven])
            twin.do_step(t, h)
            if set_driven is not None:
                set_driven([sig.value(t + h) for _, sig in driven])

        return step

    def free_state(self, state: list[Any]) -> None:
        for i, (inst, s) in enumerate(zip(self.instances, state, strict=True)):
            if s is None:
                continue
            check = self.restore_checks.get(i)
            if check is not None:
                check.freed(s)
            inst.free_state(s)

    def instance(self, name: str) -> FmuInstance:
        try:
            return self.instances[self.index[name]]
        except KeyError:
            raise RunError(f"no FMU instance {name!r}") from None
