"""The slave's outputs are computed once per step and again only when a set changes an
input they depend on (fmus/component_slave.py), bit for bit what a fresh computation gives."""

from __future__ import annotations

import struct

import pytest

import fmus.component_slave as slave_module
from components.base import Component, Variable
from components.rotational import SpringDamperInertia
from fmus.component_slave import ComponentSlave


class Counted(Component):
    """y = 3 a (direct feedthrough of a); b only moves the state in a step."""

    VARIABLES = (
        Variable("a", "input", "1", 1.0),
        Variable("b", "input", "1", 0.0),
        Variable("x", "output", "1", 0.0),
        Variable("y", "output", "1", 0.0, depends_on=("a",)),
    )
    STEP_TAKES_INPUTS = True  # its step reads a itself: no update before a step
    updates = 0

    def update_outputs(self) -> None:
        Counted.updates += 1
        self.y = 3.0 * self.a + self.x

    def step(self, t: float, h: float) -> None:
        self.x += self.b * h
        self.y = 3.0 * self.a + self.x


def _slave(component: type[Component], monkeypatch: pytest.MonkeyPatch) -> ComponentSlave:
    classes = {"test.Component": component, "base.ComponentError": RuntimeError}
    monkeypatch.setattr(slave_module, "_component_class", classes.__getitem__)

    class Slave(ComponentSlave):
        pass

    Slave.component = "test.Component"
    Slave.description = "test"
    Slave.default_run = (0.0, 1.0, 0.1)
    slave = Slave(instance_name="cache")
    slave.setup_experiment(0.0, None, None)
    slave.enter_initialization_mode()
    slave.exit_initialization_mode()
    return slave


def _vr(slave: ComponentSlave, name: str) -> int:
    return slave._names.index(name)


def _bits(values: list[float]) -> list[bytes]:
    return [struct.pack("<d", v) for v in values]


def test_a_set_recomputes_only_what_it_changes(monkeypatch: pytest.MonkeyPatch) -> None:
    s = _slave(Counted, monkeypatch)
    a, b, y = _vr(s, "a"), _vr(s, "b"), _vr(s, "y")
    assert s.get_real([y]) == [3.0]
    Counted.updates = 0
    s.set_real([a], [2.0])  # y depends on a: read again, it is recomputed
    assert s.get_real([y]) == [6.0]
    assert Counted.updates == 1
    s.set_real([b], [5.0])  # no output depends on b: nothing to recompute
    s.set_real([a], [2.0])  # the value held, outputs computed from it: nothing either
    assert s.get_real([y]) == [6.0]
    assert Counted.updates == 1
    s.do_step(0.0, 0.5)  # x = 2.5: the step's own outputs
    assert s.get_real([y]) == [8.5]
    assert Counted.updates == 1
    # After a step a set of an input an output depends on recomputes, even to its value.
    s.set_real([a], [2.0])
    assert s.get_real([y]) == [8.5]
    assert Counted.updates == 2


def test_zero_and_minus_zero_are_different_values(monkeypatch: pytest.MonkeyPatch) -> None:
    s = _slave(Counted, monkeypatch)
    a, y = _vr(s, "a"), _vr(s, "y")
    s.set_real([a], [0.0])
    s.get_real([y])
    Counted.updates = 0
    s.set_real([a], [-0.0])
    s.get_real([y])
    assert Counted.updates == 1


def test_get_after_set_is_a_fresh_computation(monkeypatch: pytest.MonkeyPatch) -> None:
    """The slave's outputs after steps and sets against the component stepped and updated
    directly: equal bit for bit, whichever sets were skipped."""
    params = {"J": 2e-4, "k": 3.0, "d": 1e-3, "w0": 4.0}
    s = _slave(SpringDamperInertia, monkeypatch)
    for name, value in params.items():
        s.model.__dict__[name] = value
    s.model.initialize(0.0)
    plain = SpringDamperInertia(**params)
    plain.initialize(0.0)
    outs = ["phi", "w", "tau", "stored_energy", "dissipated_work"]
    refs = [_vr(s, n) for n in outs]
    ins = [_vr(s, "phi_in"), _vr(s, "w_in")]
    t, h = 0.0, 1e-3
    for k, (phi_in, w_in) in enumerate([(0.1, 2.0), (0.1, 2.0), (0.3, -1.0), (0.3, -1.0)]):
        s.set_real(ins, [phi_in, w_in])
        plain.phi_in, plain.w_in = phi_in, w_in
        plain.update_outputs()
        assert _bits(s.get_real(refs)) == _bits(plain.values(outs)), k
        s.set_real(ins, [phi_in, w_in])  # again, the same: the same bits
        assert _bits(s.get_real(refs)) == _bits(plain.values(outs)), k
        s.do_step(t, h)
        plain.step(t, h)
        t += h
        assert _bits(s.get_real(refs)) == _bits(plain.values(outs)), k


def test_a_restored_state_brings_its_outputs_state(monkeypatch: pytest.MonkeyPatch) -> None:
    s = _slave(Counted, monkeypatch)
    a, y = _vr(s, "a"), _vr(s, "y")
    s.do_step(0.0, 0.5)
    saved = s._get_fmu_state()
    s.set_real([a], [4.0])
    assert s.get_real([y]) == [12.0]
    s._set_fmu_state(saved)  # the step's outputs again, a = 1: a set of 1 recomputes
    Counted.updates = 0
    s.set_real([a], [1.0])
    assert s.get_real([y]) == [3.0]
    assert Counted.updates == 1


def test_a_reference_set_twice_in_one_call_keeps_the_last(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    s = _slave(Counted, monkeypatch)
    a, y = _vr(s, "a"), _vr(s, "y")
    assert s.get_real([y]) == [3.0]
    Counted.updates = 0
    s.set_real([a, a], [1.0, 4.0])  # the held value first, a new one second: recomputed
    assert s.get_real([y]) == [12.0]
    assert Counted.updates == 1
    s.set_real([a, a], [4.0, 4.0])  # the value held, twice: nothing to recompute
    assert s.get_real([y]) == [12.0]
    assert Counted.updates == 1
    with pytest.raises(ValueError, match="2 references but 1 values"):
        s._set([a, a], [1.0], float)
