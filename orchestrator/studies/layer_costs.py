"""What each layer of a co-simulation costs per call: one run of a scene with every layer's
entry timed (``mechcosim bench overhead``).

The layers nest: the master calls the FMI functions (fmpy's prepared ctypes calls through
the FMU's C loader and pythonfmu's runtime), which call the slave (fmus/component_slave.py),
which calls the component.  Each layer's own cost is its time less that of the layers it
calls: the component's step and output updates; the slave's Python around them; the FMI
boundary (a call's time less the slave's); state save and restore (boundary and slave
together); the observers that record; the master's own Python (the run less all of these).
Every timed call adds two clock reads (about 0.1 us) to the layer that makes it.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from orchestrator import observers as observer_module
from orchestrator.fmu_instance import FmuInstance
from orchestrator.system import CoupledSystem


@dataclass
class Clock:
    """Calls and seconds spent inside one kind of call."""

    calls: int = 0
    seconds: float = 0.0


@dataclass
class LayerCosts:
    """The clocks of one run, by what was timed."""

    clocks: dict[str, Clock] = field(default_factory=dict)
    run_seconds: float = 0.0
    run_cpu_seconds: float = 0.0  # the process's CPU time over the same span
    macro_steps: int = 0

    def clock(self, name: str) -> Clock:
        return self.clocks.setdefault(name, Clock())

    def seconds(self, *names: str) -> float:
        return sum(self.clocks[n].seconds for n in names if n in self.clocks)

    def calls(self, *names: str) -> int:
        return sum(self.clocks[n].calls for n in names if n in self.clocks)

    def layers(self) -> list[tuple[str, int, float]]:
        """(layer, calls, its own seconds) from the outside in; the master's per macro step."""
        steps = self.seconds("component step")
        updates = self.seconds("component update_outputs")
        slave_step = self.seconds("slave do_step")
        slave_values = self.seconds("slave get", "slave set")
        fmi_step = self.seconds("fmi doStep")
        fmi_values = self.seconds("fmi get", "fmi set")
        state = self.seconds("fmi state")
        recording = self.seconds("recording")
        master = self.run_seconds - fmi_step - fmi_values - state - recording
        return [
            ("component step", self.calls("component step"), steps),
            (
                "component outputs recomputed after a set",
                self.calls("component update_outputs"),
                updates,
            ),  # fmt: skip
            ("slave do_step (its own Python)", self.calls("slave do_step"), slave_step - steps),
            (
                "slave get/set (its own Python)",
                self.calls("slave get", "slave set"),
                slave_values - updates,
            ),  # fmt: skip
            (
                "FMI doStep boundary (fmpy, loader, runtime)",
                self.calls("fmi doStep"),
                fmi_step - slave_step,
            ),  # fmt: skip
            ("FMI get/set boundary", self.calls("fmi get", "fmi set"), fmi_values - slave_values),
            ("state save/restore/free", self.calls("fmi state"), state),
            ("recording (observers)", self.calls("recording"), recording),
            ("master's own Python, per macro step", self.macro_steps, master),
        ]


def _timed(clock: Clock, function: Callable[..., Any]) -> Callable[..., Any]:
    now = time.perf_counter

    def timed(*args: Any, **kwargs: Any) -> Any:
        t0 = now()
        try:
            return function(*args, **kwargs)
        finally:
            clock.seconds += now() - t0
            clock.calls += 1

    return timed


def _patch(owner: Any, name: str, clock: Clock, undo: list) -> None:
    original = getattr(owner, name)
    setattr(owner, name, _timed(clock, original))
    undo.append((owner, name, original, name in vars(owner)))


def _patch_fmus(costs: LayerCosts, undo: list, done: set[int]) -> None:
    """Time the slaves and their components of every FMU loaded in this process (each
    build's own package: ``<build>.component_slave``), each class once (``done``)."""
    for module_name, module in list(sys.modules.items()):
        if not module_name.endswith(".component_slave") or module_name == "fmus.component_slave":
            continue
        base = module.ComponentSlave
        if id(base) in done:
            continue
        done.add(id(base))
        _patch(base, "do_step", costs.clock("slave do_step"), undo)
        for name in ("get_real", "get_integer"):
            _patch(base, name, costs.clock("slave get"), undo)
        for name in ("set_real", "set_integer"):
            _patch(base, name, costs.clock("slave set"), undo)
        for wrapper in base.__subclasses__():
            component = module._component_class(wrapper.component)
            if id(component) not in done:
                done.add(id(component))
                _patch(component, "step", costs.clock("component step"), undo)
                _patch(component, "update_outputs", costs.clock("component update_outputs"), undo)


def _patch_transfers(costs: LayerCosts, undo: list) -> None:
    """Time the prepared FMI transfers the masters make (``FmuInstance.getter``, ``setter``)."""
    for name, kind in (("getter", "fmi get"), ("setter", "fmi set")):
        prepare, clock = getattr(FmuInstance, name), costs.clock(kind)

        def timed_prepare(*args: Any, _prepare: Any = prepare, _clock: Clock = clock, **kw: Any):
            return _timed(_clock, _prepare(*args, **kw))

        setattr(FmuInstance, name, timed_prepare)
        undo.append((FmuInstance, name, prepare, True))


def measure(scene: Any, output_dir: Path) -> LayerCosts:
    """Run ``scene`` once (no reference, no plot) with every layer timed."""
    from orchestrator.run import run_scene

    costs = LayerCosts()
    undo: list = []
    _patch(FmuInstance, "do_step", costs.clock("fmi doStep"), undo)
    for name in ("get_state", "set_state", "free_state"):
        _patch(FmuInstance, name, costs.clock("fmi state"), undo)
    _patch_transfers(costs, undo)
    for name in ("TimeSeries", "RegimeLog", "EnergyBalance", "StepCounter"):
        _patch(getattr(observer_module, name), "step", costs.clock("recording"), undo)
    initialize = CoupledSystem.initialize
    done: set[int] = set()

    def initialize_timed(system: CoupledSystem) -> None:
        initialize(system)
        _patch_fmus(costs, undo, done)

    import orchestrator.run as run_module

    execute = run_module.execute

    def execute_timed(master: Any, *args: Any, **kwargs: Any) -> None:
        t0, cpu0 = time.perf_counter(), time.process_time()
        try:
            execute(master, *args, **kwargs)
        finally:
            costs.run_seconds += time.perf_counter() - t0
            costs.run_cpu_seconds += time.process_time() - cpu0
            costs.macro_steps += master.stats.steps

    CoupledSystem.initialize = initialize_timed  # type: ignore[method-assign]
    run_module.execute = execute_timed
    try:
        run_scene(
            scene, output_dir=output_dir, show_progress=False, compare_reference=False, plots=False
        )
    finally:
        CoupledSystem.initialize = initialize  # type: ignore[method-assign]
        run_module.execute = execute
        for owner, name, original, own in reversed(undo):
            if own:
                setattr(owner, name, original)
            else:
                delattr(owner, name)
    return costs


def print_layer_costs(costs: LayerCosts, title: str) -> None:
    total = costs.run_seconds
    print(
        f"\n{title}: {total:.3f} s ({costs.run_cpu_seconds:.3f} s CPU) in {costs.macro_steps} "
        "macro steps, by layer (its own time: less that of the layers it calls)"
    )
    print(f"{'layer':50s} {'calls':>7s} {'us/call':>9s} {'share':>7s}")
    for what, calls, seconds in costs.layers():
        per = seconds / calls * 1e6 if calls else 0.0
        print(f"{what:50s} {calls:7d} {per:9.2f} {seconds / total:7.1%}")
    kinds = {k: costs.calls(f"fmi {k}") for k in ("doStep", "get", "set", "state")}
    steps = max(costs.macro_steps, 1)
    print(
        f"FMI calls: {sum(kinds.values()) / steps:.1f} per macro step ("
        + ", ".join(f"{k} {n / steps:.1f}" for k, n in kinds.items())
        + "); every timed call adds about 0.1 us to the layer that makes it"
    )
