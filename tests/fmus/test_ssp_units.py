"""Values of another tool's FMU in units that are not SI (a 'deg' parameter) go out in
the unit the FMU declares, and come in converted to it."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import foreign_fmus
import pytest
from foreign_fmus import TORSION_BODY_SCENE

from orchestrator.errors import ScenarioError
from orchestrator.run import run_scene
from orchestrator.scenario import load_scene
from orchestrator.ssp_export import SSC, SSD, SSV, export_ssp
from orchestrator.ssp_import import load_ssp
from orchestrator.studies.crosscheck import REQUIRED, crosscheck

PHI0 = 0.1  # rad, given to the scene as a quantity


@pytest.fixture(scope="module")
def scene_file(tmp_path_factory) -> Path:
    if foreign_fmus.c_compiler() is None:
        pytest.skip("no C compiler")
    d = tmp_path_factory.mktemp("deg")
    fmu = foreign_fmus.build_torsion_body(d, phi0_in_degrees=True)
    path = d / "deg_parameter.toml"
    path.write_text(TORSION_BODY_SCENE.format(fmu=fmu, phi0=PHI0))
    return path


def _binding(archive: Path, instance: str, name: str) -> ET.Element:
    with zipfile.ZipFile(archive) as z:
        root = ET.fromstring(z.read("SystemStructure.ssd"))
    for component in root.iter(f"{{{SSD}}}Component"):
        if component.get("name") == instance:
            for p in component.iter(f"{{{SSV}}}Parameter"):
                if p.get("name") == name:
                    return p.find(f"{{{SSV}}}Real")
    raise AssertionError(f"{instance}.{name} is not bound")


def test_deg_parameter_is_exported_in_deg(scene_file: Path, tmp_path: Path) -> None:
    scene = load_scene(scene_file)
    in_deg = math.degrees(PHI0)
    assert scene.fmus["c"].model.variables["body.phi0"].unit == "deg"
    assert scene.fmus["c"].parameters["body.phi0"] == pytest.approx(in_deg, rel=1e-15)
    archive = export_ssp(scene, tmp_path / "deg.ssp")
    real = _binding(archive, "c", "body.phi0")
    assert real.get("unit") == "deg"
    assert float(real.get("value")) == pytest.approx(in_deg, rel=1e-15)
    with zipfile.ZipFile(archive) as z:
        root = ET.fromstring(z.read("SystemStructure.ssd"))
    (deg,) = [u for u in root.iter(f"{{{SSC}}}Unit") if u.get("name") == "deg"]
    base = deg.find(f"{{{SSC}}}BaseUnit")
    assert base.get("rad") == "1" and float(base.get("factor")) == pytest.approx(math.pi / 180)
    # The FMU, given degrees, starts the body at PHI0 rad, under our master and in libcosim
    # (which takes bound values as they are, whatever their unit) reading the archive.
    ours = run_scene(scene, output_dir=tmp_path / "ours", show_progress=False, plots=False)
    assert ours.signal("c.body.phi")[0] == pytest.approx(PHI0, rel=1e-15)
    check = crosscheck(scene_file, tools=("libcosim",))
    for o in check.outcomes:
        assert o.cannot_run is None and o.agreement.worst[1] <= REQUIRED, o.tool


def test_a_value_bound_in_another_unit_is_converted_on_import(
    scene_file: Path, tmp_path: Path
) -> None:
    """An SSD made elsewhere may bind body.phi0 in rad (SSP 1.0 lets a tool convert)."""
    scene = load_scene(scene_file)
    archive = export_ssp(scene, tmp_path / "deg.ssp")
    edited = tmp_path / "rad.ssp"
    with zipfile.ZipFile(archive) as z, zipfile.ZipFile(edited, "w") as out:
        for item in z.infolist():
            data = z.read(item)
            if item.filename == "SystemStructure.ssd":
                text = data.decode()
                old = f'value="{math.degrees(PHI0)!r}" unit="deg"'
                assert old in text
                data = text.replace(old, f'value="{PHI0!r}" unit="rad"').encode()
            out.writestr(item, data)
    imported = load_ssp(edited)
    assert imported.fmus["c"].parameters["body.phi0"] == pytest.approx(
        math.degrees(PHI0), rel=1e-15
    )
    # a unit of another dimension is refused in one line, naming the file and parameter
    wrong = tmp_path / "wrong.ssp"
    with zipfile.ZipFile(edited) as z, zipfile.ZipFile(wrong, "w") as out:
        for item in z.infolist():
            data = z.read(item)
            if item.filename == "SystemStructure.ssd":
                data = data.replace(b'value="0.1" unit="rad"', b'value="0.1" unit="m"')
            out.writestr(item, data)
    with pytest.raises(ScenarioError, match=r"body\.phi0.*'m'.*'deg'"):
        load_ssp(wrong)
