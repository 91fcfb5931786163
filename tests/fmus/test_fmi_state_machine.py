"""Every FMI call in every state of FMI 2.0's co-simulation state machine, on every one of
our FMUs (one instance each, brought from state to state): a call the standard allows
there answers as it should, any other is fmi2Error with a message naming the call and the
state.  Then random call sequences (hypothesis, in a process of its own with a timeout):
every answer is the one the state machine gives, none crashes or hangs.  And the refusals
that need the variables: a wrong GUID, a fixed parameter after initialization, a step
that does not start where the last ended, unknown and mistyped value references, another
FMU's state."""

from __future__ import annotations

import math
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from fmi_calls import ALLOWED, COMPLETE, ERROR, ERROR_STATUS, FAILED, OK, drive
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave

from fmus.build import build_fmu
from fmus.registry import FMU_RECORDS

ROOT = Path(__file__).resolve().parents[2]
#: calls whose answer in an allowed state depends on more than the state (checked apart)
TABLE_CALLS = tuple(ALLOWED)


@pytest.mark.parametrize("name", list(FMU_RECORDS))
def test_every_call_in_every_state(name: str, tmp_path: Path) -> None:
    d = drive(name, build_fmu(name), tmp_path)
    if name == "VergeEscapement":  # its step budget can make a step fail
        assert FAILED in d.states()
    try:
        for state in d.states():
            for call in TABLE_CALLS:
                d.put_in(state)
                d.messages.clear()
                got = d.call(call)
                expected = d.expect(call)
                assert got == expected, (name, state, call, got, d.messages)
                if expected == ERROR_STATUS:
                    fmi_name = "fmi2" + call[0].upper() + call[1:]
                    assert any(
                        m.startswith(f"{fmi_name}: not allowed in state {state}")
                        for m in d.messages
                    ), (name, state, call, d.messages)
    finally:
        d.fmu.freeInstance()


def _instance(name: str, scratch: Path, guid: str | None = None) -> tuple[FMU2Slave, dict]:
    path = build_fmu(name)
    md = read_model_description(str(path))
    fmu = FMU2Slave(
        guid=guid or md.guid,
        unzipDirectory=extract(str(path), str(scratch)),
        modelIdentifier=md.coSimulation.modelIdentifier,
        instanceName=name,
    )
    return fmu, {v.name: v.valueReference for v in md.modelVariables}


def _initialized(name: str, scratch: Path) -> tuple[FMU2Slave, dict]:
    fmu, refs = _instance(name, scratch)
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    return fmu, refs


def _status(call, *args) -> int:
    try:
        call(*args)
    except FMICallException as exc:
        return exc.status
    return OK


def test_a_wrong_guid_is_refused(tmp_path: Path, capfd: pytest.CaptureFixture) -> None:
    fmu, _ = _instance("Inertia", tmp_path, guid="00000000-0000-0000-0000-000000000000")
    with pytest.raises(Exception, match="Failed to instantiate"):
        fmu.instantiate()
    assert 'GUID "00000000-0000-0000-0000-000000000000" is not this FMU\'s' in (
        capfd.readouterr().out
    )


def test_refusals_that_need_the_variables(tmp_path: Path, capfd: pytest.CaptureFixture) -> None:
    """Each refused with fmi2Error and its reason; an FMU state taken before brings the
    instance back, and it steps on as if nothing had happened."""
    fmu, refs = _initialized("VergeEscapement", tmp_path / "v")
    fmu.doStep(0.0, 1e-3)
    good = fmu.getFMUstate()
    other, _ = _initialized("SpringDamperInertia", tmp_path / "s")
    foreign = other.getFMUstate()
    cases = [
        (fmu.setReal, [refs["spin"]], [1.0], "fmi2SetReal: spin is a fixed parameter"),
        (fmu.doStep, -1.0, 1e-3, "the last step ended at t = 0.001 s, where the next must"),
        (fmu.doStep, 5.0, 1e-3, "the last step ended at t = 0.001 s"),
        (fmu.getReal, [99999], "fmi2GetReal: no variable has value reference 99999"),
        (fmu.getReal, [refs["impact_count"]], "is impact_count, an Integer"),
        (fmu.setReal, [refs["impact_count"]], [1.0], "is impact_count, an Integer"),
        (fmu.getInteger, [refs["psi"]], "is psi, a Real"),
        (fmu.setReal, [refs["psi"]], [1.0], "psi is an output, which the host cannot set"),
        (fmu.setFMUstate, foreign, "the FMU state given is not one this FMU made"),
        (fmu.getBoolean, [refs["psi"]], "is psi, a Real"),
    ]
    capfd.readouterr()
    for call, *args, said in cases:
        assert _status(call, *args) == ERROR_STATUS, said
        assert said in capfd.readouterr().out, said
        assert _status(fmu.doStep, 1e-3, 1e-3) == ERROR_STATUS  # in the error state
        fmu.setFMUstate(good)
    fmu.doStep(1e-3, 1e-3)
    reference, _ = _initialized("VergeEscapement", tmp_path / "r")
    reference.doStep(0.0, 1e-3)
    reference.doStep(1e-3, 1e-3)
    assert fmu.getReal([refs["psi"]]) == reference.getReal([refs["psi"]])
    assert math.isfinite(fmu.getReal([refs["psi"]])[0])
    for f in (fmu, other, reference):
        f.terminate()
        f.freeInstance()


FUZZ = """
import sys
from pathlib import Path
from hypothesis import HealthCheck, given, settings, strategies as st
sys.path.insert(0, {tests!r})
from fmi_calls import ALLOWED, STATES, drive
from fmus.build import build_fmu

names = {names!r}
instances = {{n: drive(n, build_fmu(n), Path({scratch!r}) / n) for n in names}}

@settings(max_examples={examples}, deadline=None, derandomize=True,
          suppress_health_check=list(HealthCheck))
@given(st.sampled_from(names), st.sampled_from([s for s in STATES if s != "step failed"]),
       st.lists(st.sampled_from(sorted(ALLOWED)), max_size=12))
def sequences(name, start, calls):
    d = instances[name]
    d.put_in(start)
    for call in calls:
        got = d.call(call)
        expected = d.expect(call)
        assert got == expected, (name, start, calls, call, got, d.messages[-3:])

sequences()
print("fuzz done")
"""


def test_random_call_sequences_answer_as_the_state_machine(tmp_path: Path) -> None:
    script = FUZZ.format(
        tests=str(Path(__file__).parent),
        names=["Inertia", "GearTrain", "VergeEscapement"],
        scratch=str(tmp_path),
        examples=40,
    )
    run = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(script)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
        # a plain environment, but the suite's FMU cache: the FMUs are built once
        env={
            "PYTHONPATH": str(ROOT),
            "PATH": "/usr/bin:/bin",
            **{k: v for k, v in os.environ.items() if k in ("HOME", "MECHCOSIM_FMU_CACHE")},
        },
    )
    assert run.returncode == 0, (run.stdout[-2000:], run.stderr[-4000:])
    assert run.stdout.strip().endswith("fuzz done")


def test_the_error_state_allows_what_fmi_allows_after_fmi2_error() -> None:
    assert {c for c, states in ALLOWED.items() if ERROR in states} == {
        "reset",
        "setDebugLogging",
        "getReal",
        "getInteger",
        "getBoolean",
        "getString",
        "getFMUstate",
        "setFMUstate",
    }
    assert ALLOWED["doStep"] == {COMPLETE}
