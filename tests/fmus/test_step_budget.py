"""The work of one doStep is bounded.  A doStep of 1e6 s asks an integrating FMU for some
1e10 internal steps at its largest step: it ends when its budget (``max_internal_steps``,
given small here) is spent, with fmi2Discard, the steps counted and the message saying so,
the last successful time the step's start (nothing of it kept), and the FMU state before
still good.  FMUs without internal integration take the step whole."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave, fmi2LastSuccessfulTime

from fmus.build import build_fmu

BUDGET = 300
#: FMUs whose steps are integrated with a budget; the values set to make them move
BUDGETED = {
    "GearTrain": {"spin": 3000.0},
    "ClockGearTrain": {},
    "CrankCouplerDrive": {},
    "VergeEscapement": {"phi_dot": 50.0},
    "DetachedLever": {},  # event by event: each piece between events counts
    "GearMesh": {},  # each smooth piece between contact changes counts
}
#: closed-form or event-free over any span: the step is taken whole
WHOLE = ("BrakeLoad", "Inertia", "SpragClutch", "SpringDamperInertia")


def _initialized(name: str, scratch: Path, values: dict) -> tuple[FMU2Slave, dict]:
    path = build_fmu(name)
    md = read_model_description(str(path))
    refs = {v.name: v for v in md.modelVariables}
    fmu = FMU2Slave(
        guid=md.guid,
        unzipDirectory=extract(str(path), str(scratch)),
        modelIdentifier=md.coSimulation.modelIdentifier,
        instanceName=name,
    )
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    for key, value in values.items():
        if refs[key].type == "Integer":
            fmu.setInteger([refs[key].valueReference], [int(value)])
        else:
            fmu.setReal([refs[key].valueReference], [float(value)])
    fmu.exitInitializationMode()
    return fmu, refs


@pytest.mark.parametrize("name", BUDGETED)
def test_a_step_too_long_ends_at_its_budget(
    name: str, tmp_path: Path, capfd: pytest.CaptureFixture
) -> None:
    fmu, refs = _initialized(name, tmp_path, {**BUDGETED[name], "max_internal_steps": BUDGET})
    assert refs["max_internal_steps"].start == "100000"  # the default, far from any scene
    fmu.doStep(0.0, 1e-3)
    before = fmu.getFMUstate()
    capfd.readouterr()
    with pytest.raises(FMICallException) as info:
        fmu.doStep(1e-3, 1e6)
    assert info.value.status == 2  # fmi2Discard
    said = capfd.readouterr().out
    assert "fmi2DoStep from t = 0.001 s over 1000000.0 s: " in said, said
    assert f"budget of {BUDGET} internal steps (max_internal_steps)" in said, said
    assert fmu.getRealStatus(fmi2LastSuccessfulTime) == 1e-3
    fmu.setFMUstate(before)  # back to step complete, and on from there
    fmu.doStep(1e-3, 1e-3)
    outputs = [v.valueReference for v in refs.values() if v.causality == "output"]
    outputs = [vr for vr in outputs if refs_type(refs, vr) == "Real"]
    assert all(math.isfinite(x) for x in fmu.getReal(outputs))
    fmu.freeFMUstate(before)
    fmu.terminate()
    fmu.freeInstance()


def refs_type(refs: dict, vr: int) -> str:
    return next(v.type for v in refs.values() if v.valueReference == vr)


@pytest.mark.parametrize("name", WHOLE)
def test_a_step_without_internal_integration_is_taken_whole(name: str, tmp_path: Path) -> None:
    fmu, refs = _initialized(name, tmp_path, {})
    assert "max_internal_steps" not in refs
    fmu.doStep(0.0, 1e6)
    fmu.doStep(1e6, 1.0)  # and the next starts where it ended
    fmu.terminate()
    fmu.freeInstance()
