"""The FMI 2.0 capabilities masters rely on, checked in one place (orchestrator/capabilities.py):
what each master needs, and the one-line refusals and fallbacks naming FMU and capability."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from orchestrator import capabilities
from orchestrator.errors import RunError


def fmu(variable_step: bool = True, state: bool = True, interpolate: bool = False):
    return SimpleNamespace(
        can_handle_variable_step=variable_step,
        can_get_set_state=state,
        can_interpolate_inputs=interpolate,
    )


def system(signals: bool = False, **models) -> SimpleNamespace:
    return SimpleNamespace(names=list(models), models=list(models.values()), signals=signals)


def test_lacking_names_each_fmu_and_capability_in_order() -> None:
    s = system(a=fmu(), b=fmu(variable_step=False, state=False), c=fmu(state=False))
    assert [str(x) for x in capabilities.regime_aware_shortfalls(s)] == [
        "FMU 'b' cannot save and restore its state (canGetAndSetFMUstate is false)",
        "FMU 'b' cannot take communication steps of varying size "
        "(canHandleVariableCommunicationStepSize is false)",
        "FMU 'c' cannot save and restore its state (canGetAndSetFMUstate is false)",
    ]
    assert capabilities.lacking(s, [capabilities.INTERPOLATE_INPUTS])[0].fmu == "a"
    assert capabilities.regime_aware_shortfalls(system(a=fmu(), b=fmu())) == []


def test_fixed_step_on_a_grid_needs_no_variable_step() -> None:
    s = system(a=fmu(variable_step=False))
    capabilities.check_fixed_step(s, 0.0, 0.2, 1e-3)  # 200 equal steps
    capabilities.check_fixed_step(s, 0.0, 1.0, 0.1)  # 10 steps, 0.1 not exact in binary


def test_fixed_step_that_shortens_its_last_step_is_refused() -> None:
    s = system(a=fmu(), b=fmu(variable_step=False))
    with pytest.raises(RunError) as error:
        capabilities.check_fixed_step(s, 0.0, 0.2, 3e-3)
    assert str(error.value) == (
        "FMU 'b': cannot take communication steps of varying size "
        "(canHandleVariableCommunicationStepSize is false), which the fixed-step master needs "
        "with a step of 0.003 s that does not divide the span 0.2 s"
    )
    capabilities.check_fixed_step(system(a=fmu()), 0.0, 0.2, 3e-3)  # every FMU can


def test_fixed_step_landing_on_input_signals_is_refused() -> None:
    with pytest.raises(RunError, match=r"^FMU 'a': .* input signals, whose breakpoints"):
        capabilities.check_fixed_step(system(True, a=fmu(variable_step=False)), 0.0, 0.2, 1e-3)


def test_unknown_capability_is_named() -> None:
    with pytest.raises(KeyError, match="canDoMagic"):
        capabilities.has(fmu(), "canDoMagic")
