"""SSP archives, exports and scene names are checked: every error names the file and the
element or key, and nothing is silently changed or destroyed."""

from __future__ import annotations

import re
import zipfile
from collections.abc import Callable
from pathlib import Path

import pytest

from orchestrator.cli import main
from orchestrator.errors import ScenarioError
from orchestrator.scenario import load_scene
from orchestrator.ssp_export import export_ssp
from orchestrator.ssp_import import load_ssp

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
TWO = SCENARIOS / "two_inertias.toml"


@pytest.fixture(scope="module")
def archive(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return export_ssp(load_scene(TWO), tmp_path_factory.mktemp("ssp") / "two.ssp")


def mutated(archive: Path, target: Path, edit: Callable[[str], str]) -> Path:
    """A copy of ``archive`` whose SystemStructure.ssd is ``edit``ed (its text)."""
    with zipfile.ZipFile(archive) as src, zipfile.ZipFile(target, "w") as dst:
        for info in src.infolist():
            data = src.read(info)
            if info.filename == "SystemStructure.ssd":
                data = edit(data.decode()).encode()
            dst.writestr(info, data)
    return target


def ssd_text(archive: Path) -> str:
    with zipfile.ZipFile(archive) as z:
        return z.read("SystemStructure.ssd").decode()


def refused(path: Path) -> str:
    with pytest.raises(ScenarioError) as info:
        load_ssp(path)
    return str(info.value)


def first_component(text: str) -> str:
    return re.search(r'<ssd:Component [^>]*name="(\w+)"', text).group(1)


# -- SSP import ------------------------------------------------------------------------------
def test_duplicate_component_names_are_refused(archive: Path, tmp_path: Path) -> None:
    text = ssd_text(archive)
    names = re.findall(r'<ssd:Component [^>]*name="(\w+)"', text)
    assert len(names) == 2
    rename = f'<ssd:Component name="{names[1]}"'
    assert rename in text
    bad = mutated(
        archive,
        tmp_path / "dup.ssp",
        lambda t: t.replace(rename, f'<ssd:Component name="{names[0]}"'),
    )
    message = refused(bad)
    assert "dup.ssp: SystemStructure.ssd" in message
    assert f"[Component {names[0]!r}] declared twice" in message


def test_a_component_without_a_name_is_refused(archive: Path, tmp_path: Path) -> None:
    name = first_component(ssd_text(archive))
    bad = mutated(
        archive,
        tmp_path / "anon.ssp",
        lambda t: re.sub(rf'(<ssd:Component [^>]*)name="{name}"', r"\1", t, count=1),
    )
    message = refused(bad)
    assert "anon.ssp: SystemStructure.ssd: [Component 1] has no name" in message


def test_a_non_numeric_value_names_component_and_parameter(archive: Path, tmp_path: Path) -> None:
    text = ssd_text(archive)
    m = re.search(r'<ssv:Parameter name="([^"]+)">\s*<ssv:Real value="([^"]+)"', text)
    assert m is not None
    bad = mutated(
        archive,
        tmp_path / "value.ssp",
        lambda t: t.replace(
            m.group(0), m.group(0).replace(f'value="{m.group(2)}"', 'value="fast"'), 1
        ),
    )
    message = refused(bad)
    assert f"Parameter {m.group(1)!r}] Real value 'fast' is not a number" in message
    assert "value.ssp: SystemStructure.ssd: [Component " in message


def test_a_non_numeric_stop_time_names_the_attribute(archive: Path, tmp_path: Path) -> None:
    bad = mutated(
        archive, tmp_path / "stop.ssp", lambda t: re.sub(r'stopTime="[^"]+"', 'stopTime="soon"', t)
    )
    assert "[DefaultExperiment stopTime] 'soon' is not a number" in refused(bad)


def test_a_non_numeric_unit_factor_names_the_unit(archive: Path, tmp_path: Path) -> None:
    text = ssd_text(archive)
    unit = re.search(r'<ssc:Unit name="([^"]+)">\s*<ssc:BaseUnit ', text)
    assert unit is not None
    bad = mutated(
        archive,
        tmp_path / "unit.ssp",
        lambda t: t.replace(unit.group(0), unit.group(0) + 'factor="x" ', 1),
    )
    assert f"[Unit {unit.group(1)!r} BaseUnit factor] 'x' is not a number" in refused(bad)


def test_a_boolean_that_is_no_boolean_is_refused(archive: Path, tmp_path: Path) -> None:
    # no Boolean is bound in two_inertias: turn a Real binding into a bad Boolean one
    text = ssd_text(archive)
    m = re.search(r'<ssv:Parameter name="([^"]+)">\s*<ssv:Real value="[^"]+"[^/]*/>', text)
    bad = mutated(
        archive,
        tmp_path / "bool.ssp",
        lambda t: t.replace(
            m.group(0), f'<ssv:Parameter name="{m.group(1)}"><ssv:Boolean value="maybe"/>', 1
        ),
    )
    assert "Boolean value 'maybe'; expected true or false" in refused(bad)


# -- export ----------------------------------------------------------------------------------
def test_export_never_replaces_its_input(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    scene = tmp_path / "s.toml"
    scene.write_text(TWO.read_text())
    before = scene.read_bytes()
    for extra in ([], ["--force"]):
        assert main(["export", str(scene), str(scene), *extra]) == 2
        err = capsys.readouterr().err
        assert f"{scene}: is the scene being exported" in err
    assert scene.read_bytes() == before


def test_export_never_replaces_another_scene(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    other = tmp_path / "other.ssp"  # a scene, whatever its name says
    other.write_text(TWO.read_text())
    assert main(["export", str(TWO), str(other), "--force"]) == 2
    assert f"{other}: is a scene file" in capsys.readouterr().err
    assert other.read_text() == TWO.read_text()


def test_export_replaces_an_archive_only_with_force(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    out = tmp_path / "two.ssp"
    assert main(["export", str(TWO), str(out)]) == 0
    first = out.stat().st_mtime_ns
    assert main(["export", str(TWO), str(out)]) == 2
    assert f"{out}: exists; give --force to replace it" in capsys.readouterr().err
    assert out.stat().st_mtime_ns == first
    assert main(["export", str(TWO), str(out), "--force"]) == 0


# -- scene name and description --------------------------------------------------------------
@pytest.mark.parametrize("name", ["", "  ", "../x", "a/b", "..", "a\\b"])
def test_a_scene_name_is_not_a_path(name: str) -> None:
    with pytest.raises(ScenarioError) as info:
        load_scene(TWO, {"scene.name": name})
    assert "[scene.name]" in str(info.value) and str(TWO) in str(info.value)


def test_a_scene_description_is_text() -> None:
    with pytest.raises(ScenarioError, match=r"\[scene.description\] expected text, got 5"):
        load_scene(TWO, {"scene.description": 5})
