"""Initialization from inputs a host may leave as they come: every input at 0 (a host that
sets each connected input to 0 before the first exchange), or not finite.  Each FMU either
starts and steps (where a zero is physical) or answers fmi2Error naming the input and why;
never fmi2Fatal, never a Python error text."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave

from fmus.build import build_fmu
from fmus.registry import FMU_RECORDS

#: the FMUs for which some input at zero means nothing physical, and the words naming it
NOT_PHYSICAL_AT_ZERO = {"VergeEscapement": "input J_ref = 0.0 kg.m2 at initialization"}


def _started(name: str, scratch: Path) -> tuple[FMU2Slave, dict]:
    path = build_fmu(name)
    md = read_model_description(str(path))
    fmu = FMU2Slave(
        guid=md.guid,
        unzipDirectory=extract(str(path), str(scratch)),
        modelIdentifier=md.coSimulation.modelIdentifier,
        instanceName=f"{name}_zero",
    )
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    return fmu, {v.name: v for v in md.modelVariables}


@pytest.mark.parametrize("name", list(FMU_RECORDS))
def test_every_input_at_zero(name: str, tmp_path: Path, capfd: pytest.CaptureFixture) -> None:
    fmu, variables = _started(name, tmp_path)
    inputs = [v for v in variables.values() if v.causality == "input"]
    real = [v.valueReference for v in inputs if v.type == "Real"]
    integer = [v.valueReference for v in inputs if v.type != "Real"]
    fmu.setReal(real, [0.0] * len(real))
    fmu.setInteger(integer, [0] * len(integer))
    status = 0
    try:
        fmu.exitInitializationMode()
        step = float(read_model_description(str(build_fmu(name))).defaultExperiment.stepSize)
        fmu.doStep(0.0, step)
        assert all(math.isfinite(x) for x in fmu.getReal(real))
    except FMICallException as exc:
        status = exc.status
    said = capfd.readouterr().out
    if name in NOT_PHYSICAL_AT_ZERO:
        assert status == 3, said  # fmi2Error, the instance not lost
        assert NOT_PHYSICAL_AT_ZERO[name] in said, said
        assert "fmi2ExitInitializationMode: " in said
    else:
        assert status == 0, said
    assert "Traceback" not in said and "division" not in said, said
    fmu.freeInstance()


@pytest.mark.parametrize("value", [math.nan, math.inf, -math.inf])
def test_a_non_finite_input_is_refused_by_name(
    value: float, tmp_path: Path, capfd: pytest.CaptureFixture
) -> None:
    fmu, variables = _started("SpringDamperInertia", tmp_path)
    with pytest.raises(FMICallException) as info:
        fmu.setReal([variables["phi_in"].valueReference], [value])
    assert info.value.status == 3
    assert f"fmi2SetReal: phi_in = {value} is not finite" in capfd.readouterr().out
    fmu.freeInstance()
