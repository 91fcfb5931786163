"""What a foreign FMU says reaches the user, and what it asks for is done.

The FMU's log messages are printf formats (FMI 2.0, 2.1.5) and arrive formatted; a failed
fmi2GetReal, fmi2GetFMUstate or fmi2Instantiate ends in one line naming the FMU, the call
and what the FMU logged, with summary.json written; model descriptions that cannot be
used (duplicate names, FMI 1.0 / 3.0) are refused by name; an FMU that asks to end the
simulation ends it, completed; Boolean outputs are recorded as 0/1, Strings refused."""

from __future__ import annotations

import json
import re
import zipfile
from pathlib import Path

import foreign_fmus
import numpy as np
import pytest
from foreign_fmus import TORSION_BODY_SCENE
from scene_run import run_file

from orchestrator.errors import RunError, ScenarioError
from orchestrator.scenario import load_scene

if foreign_fmus.c_compiler() is None:
    pytest.skip("no C compiler to build the foreign test FMUs", allow_module_level=True)

FAULT_TIME = 0.01


@pytest.fixture(scope="module")
def build(tmp_path_factory: pytest.TempPathFactory):  # noqa: ANN201 - a factory
    d = tmp_path_factory.mktemp("failing")

    def scene(fault: str | None = None, record: str | None = None, **kw: object) -> Path:
        try:
            fmu = foreign_fmus.build_torsion_body(d, fault=fault, fault_time=FAULT_TIME, **kw)
        except foreign_fmus.ForeignFmuError as exc:
            pytest.skip(str(exc))
        return write_scene(d, fmu, f"{fault or 'plain'}{'_flags' if kw else ''}", record)

    return scene


def write_scene(d: Path, fmu: Path, name: str, record: str | None = None) -> Path:
    text = TORSION_BODY_SCENE.format(fmu=fmu, phi0=0.1).replace(
        'name = "deg_parameter"', f'name = "{name}"'
    )
    if record:
        text = text.replace('"c.flange.tau"]', f'"c.flange.tau", "{record}"]')
    path = d / f"{name}.toml"
    path.write_text(text)
    return path


def with_description(fmu: Path, target: Path, edit) -> Path:  # noqa: ANN001 - str -> str
    """A copy of ``fmu`` whose modelDescription.xml is ``edit``ed."""
    with zipfile.ZipFile(fmu) as src, zipfile.ZipFile(target, "w") as dst:
        for info in src.infolist():
            data = src.read(info)
            if info.filename == "modelDescription.xml":
                data = edit(data.decode()).encode()
            dst.writestr(info, data)
    return target


def run(path: Path, out: Path, overrides: dict | None = None):  # noqa: ANN201 - RunResult
    return run_file(path, out, overrides)


def summary(out: Path) -> dict:
    return json.loads((out / "summary.json").read_text())


def test_log_messages_are_formatted_with_their_arguments(build, tmp_path: Path) -> None:
    # TorsionBody logs "need finite body.J > 0, ...; got %g, %g, %g" with its values
    path = build()
    negative = tmp_path / "negative_J.toml"
    negative.write_text(
        path.read_text().replace('"body.J" = "1e-4 kg*m^2"', '"body.J" = "-1 kg*m^2"')
    )
    result = run(negative, tmp_path / "run")
    assert result.status == "failed"
    assert "FMU 'c'" in result.message
    assert "need finite body.J > 0, spring.k >= 0, spring.d >= 0; got -1, 2, 0.002" in (
        result.message
    )


def test_a_failed_get_real_names_fmu_call_and_what_it_logged(build, tmp_path: Path) -> None:
    result = run(build("get_real"), tmp_path)
    assert result.status == "failed"
    assert result.message.startswith("FMU 'c', t = 0.01 s: fmi2GetReal failed (fmi2Error)")
    assert "fmi2GetReal: sensor flange.tau lost at t = 0.01 s" in result.message
    s = summary(tmp_path)
    assert s["status"] == "failed" and s["message"] == result.message
    rows = np.loadtxt(tmp_path / "timeseries.csv", delimiter=",", skiprows=1)
    assert rows[-1, 0] == pytest.approx(0.009)  # every step before is kept


def test_a_failed_get_fmu_state_names_fmu_and_call(build, tmp_path: Path) -> None:
    master = {"master.algorithm": "regime-aware", "master.tolerance": 1e-3}
    result = run(build("get_state"), tmp_path, master)
    assert result.status == "failed"
    assert "FMU 'c'" in result.message and "fmi2GetFMUstate failed (fmi2Error)" in result.message
    assert re.search(r"no memory for a snapshot of \d+ bytes", result.message)
    assert summary(tmp_path)["status"] == "failed"


def test_a_null_instance_names_fmu_and_what_it_logged(build, tmp_path: Path) -> None:
    with pytest.raises(RunError) as info:
        run(build("instantiate"), tmp_path)
    message = str(info.value)
    assert message == (
        "FMU 'c': fmi2Instantiate returned NULL: cannot open the license file torsion.lic (error 2)"
    )
    s = summary(tmp_path)  # the run had started: its summary says why it ended
    assert s["status"] == "failed" and s["message"] == message


def test_duplicate_variable_names_are_refused_by_name(build, tmp_path: Path) -> None:
    fmu = foreign_fmus.build_torsion_body(tmp_path)
    bad = with_description(
        fmu, tmp_path / "dup.fmu", lambda xml: xml.replace('name="spring.d"', 'name="spring.k"')
    )
    with pytest.raises(ScenarioError) as info:
        load_scene(write_scene(tmp_path, bad, "dup"))
    message = str(info.value)
    assert "[fmus.c.fmu]" in message and "dup.fmu" in message
    assert "declares the variable 'spring.k' twice (ScalarVariable 2 and 3)" in message


@pytest.mark.parametrize("version", ["1.0", "3.0"])
def test_fmi_1_and_3_are_refused_by_name(version: str, tmp_path: Path) -> None:
    fmu = foreign_fmus.build_torsion_body(tmp_path)
    bad = with_description(
        fmu,
        tmp_path / f"v{version}.fmu",
        lambda xml: xml.replace('fmiVersion="2.0"', f'fmiVersion="{version}"'),
    )
    with pytest.raises(ScenarioError) as info:
        load_scene(write_scene(tmp_path, bad, "old"))
    message = str(info.value)
    assert f"FMI {version} FMUs are not supported: " in message
    assert "[fmus.c.fmu]" in message and f"v{version}.fmu" in message


def test_an_fmu_that_asks_to_terminate_ends_the_run_completed(build, tmp_path: Path) -> None:
    result = run(build("terminate"), tmp_path)
    assert result.status == "completed"
    note = "terminated by FMU 'c' at t = 0.01 s: end stop reached at t = 0.01 s"
    assert result.notes == [note] and result.message == note
    assert result.time_reached == pytest.approx(FAULT_TIME)
    assert result.data[-1, 0] == pytest.approx(FAULT_TIME) and len(result.data) == 11
    assert summary(tmp_path)["status"] == "completed"


def test_boolean_outputs_are_recorded_as_0_1(build, tmp_path: Path) -> None:
    result = run(build(record="c.body.ahead", flags=True), tmp_path)
    assert result.status == "completed"
    ahead = result.signal("c.body.ahead")
    expected = result.signal("c.body.phi") > result.signal("a.phi")
    # the flange input is the inertia's angle, set before the outputs are read
    assert set(np.unique(ahead)) <= {0.0, 1.0} and 0 < ahead.sum() < len(ahead)
    np.testing.assert_array_equal(ahead[1:], expected[1:].astype(float))


def test_a_string_output_is_refused_in_output_record(build) -> None:
    with pytest.raises(ScenarioError) as info:
        load_scene(build(record="c.body.label", flags=True))
    assert "[output.record] c.body.label is a String" in str(info.value)
