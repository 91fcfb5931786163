"""Bad scenario input is refused before anything runs, with file, key and expectation."""

from __future__ import annotations

from pathlib import Path

import pytest

from orchestrator.errors import ScenarioError
from orchestrator.scenario import load_scene
from orchestrator.units import to_si

GOOD = """
[scene]
name = "t"
stop = "0.01 s"

[fmus.a]
component = "Inertia"
parameters = { J = "2e-4 kg*m^2", w0 = "10 rad/s" }

[fmus.b]
component = "SpringDamperInertia"
parameters = { J = "1e-4 kg*m^2", k = "2 N*m/rad" }

[[connections]]
ports = ["a.flange", "b.coupling"]

[master]
algorithm = "jacobi"
step = "1 ms"
"""


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "scene.toml"
    path.write_text(text)
    return path


def expect_error(path: Path, key: str, *fragments: str) -> None:
    with pytest.raises(ScenarioError) as info:
        load_scene(path)
    message = str(info.value)
    assert str(path) in message
    assert f"[{key}]" in message, message
    for fragment in fragments:
        assert fragment in message, message


def test_good_scene_loads_with_si_values(tmp_path: Path) -> None:
    scene = load_scene(write(tmp_path, GOOD))
    assert scene.fmus["a"].parameters == {"J": pytest.approx(2e-4), "w0": 10.0}
    assert scene.master.step == pytest.approx(1e-3)
    pairs = {(c.source, c.target) for c in scene.connections}
    assert (("a", "phi"), ("b", "phi_in")) in pairs
    assert (("b", "tau"), ("a", "tau")) in pairs


def test_unknown_key(tmp_path: Path) -> None:
    expect_error(
        write(tmp_path, GOOD.replace('stop = "0.01 s"', 'stop = "0.01 s"\nstpo = 1')),
        "scene.stpo",
        "unknown key",
    )


def test_unknown_parameter(tmp_path: Path) -> None:
    expect_error(
        write(tmp_path, GOOD.replace('w0 = "10 rad/s"', 'omega = "10 rad/s"')),
        "fmus.a.parameters.omega",
        "unknown key",
        "'w0'",
    )


def test_missing_required_value(tmp_path: Path) -> None:
    expect_error(write(tmp_path, GOOD.replace('step = "1 ms"', "")), "master.step", "missing")


def test_wrong_unit(tmp_path: Path) -> None:
    expect_error(
        write(tmp_path, GOOD.replace('"2e-4 kg*m^2"', '"2 in"')),
        "fmus.a.parameters.J",
        "cannot be converted to kg.m2",
    )


def test_connection_to_missing_port(tmp_path: Path) -> None:
    expect_error(
        write(tmp_path, GOOD.replace('"b.coupling"', '"b.shaft"')),
        "connections[0].ports",
        "no port 'shaft'",
        "coupling",
    )


def test_connection_to_missing_variable(tmp_path: Path) -> None:
    text = GOOD.replace('ports = ["a.flange", "b.coupling"]', 'from = "a.phi"\nto = "b.phi_inn"')
    expect_error(write(tmp_path, text), "connections[0].to", "no input variable 'phi_inn'")


def test_negative_step(tmp_path: Path) -> None:
    expect_error(
        write(tmp_path, GOOD.replace('step = "1 ms"', 'step = "-1 ms"')),
        "master.step",
        "must be positive",
    )


def test_unknown_component(tmp_path: Path) -> None:
    expect_error(
        write(tmp_path, GOOD.replace('"Inertia"', '"Flywheel"')),
        "fmus.a.component",
        "unknown 'Flywheel'",
    )


def test_not_toml(tmp_path: Path) -> None:
    with pytest.raises(ScenarioError, match="not valid TOML"):
        load_scene(write(tmp_path, "[scene\nname="))


def test_units_convert_once_to_si() -> None:
    assert to_si("0.4701 in", "m") == pytest.approx(0.01194054)
    assert to_si("30000 rpm", "rad/s") == pytest.approx(3141.5926535897)
    assert to_si("160 lbf*in", "N.m") == pytest.approx(18.0775726)
    assert to_si("10 N*m*s/rad", "N.m.s/rad") == pytest.approx(10.0)
    assert to_si(2.5, "kg.m2") == 2.5


def test_the_former_report_analysis_key_names_report_family(tmp_path: Path) -> None:
    text = GOOD + '\n[report]\nanalysis = "m739"\n'
    expect_error(write(tmp_path, text), "report.analysis", "renamed", "report.family", "'m739'")


def test_an_unknown_family_is_refused(tmp_path: Path) -> None:
    text = GOOD + '\n[report]\nfamily = "m793"\n'
    expect_error(write(tmp_path, text), "report.family", "unknown 'm793'", "'m739'")


def test_a_scenario_error_survives_the_way_back_from_a_worker() -> None:
    import pickle

    error = ScenarioError("scene.toml", "fmus.b.parameters.J", "must be > 0, got -1e-05")
    back = pickle.loads(pickle.dumps(error))
    assert (type(back), str(back), back.key) == (ScenarioError, str(error), error.key)
