"""Scenes written as libcosim's OSP-IS system structure (OspSystemStructure.xml)."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from orchestrator.cli import main
from orchestrator.osp_export import FILE_NAME, OSP_IS, export_osp
from orchestrator.scenario import load_scene

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"


def _q(tag: str) -> str:
    return f"{{{OSP_IS}}}{tag}"


@pytest.mark.parametrize("scene_file", ["m739.toml", "press_feed_run1.toml"])
def test_osp_file_holds_the_scene(scene_file: str, tmp_path: Path) -> None:
    scene = load_scene(SCENARIOS / scene_file)
    xml = export_osp(scene, tmp_path / "osp")
    assert xml == tmp_path / "osp" / FILE_NAME
    root = ET.parse(xml).getroot()
    assert root.tag == _q("OspSystemStructure") and root.get("version") == "0.1"
    assert float(root.find(_q("BaseStepSize")).text) == scene.master.step
    assert float(root.find(_q("StartTime")).text) == scene.start
    assert root.find(_q("Algorithm")).text == "fixedStep"
    simulators = {s.get("name"): s for s in root.iter(_q("Simulator"))}
    assert set(simulators) == set(scene.fmus)
    for name, simulator in simulators.items():
        assert (xml.parent / simulator.get("source")).is_file()
        values = {}
        for initial in simulator.iter(_q("InitialValue")):
            (typed,) = list(initial)
            values[initial.get("variable")] = float(typed.get("value"))
        spec = scene.fmus[name]
        assert values == {k: float(v) for k, v in {**spec.parameters, **spec.inputs}.items()}
    wired = [
        tuple((v.get("simulator"), v.get("name")) for v in c.iter(_q("Variable")))
        for c in root.iter(_q("VariableConnection"))
    ]
    assert wired == [(c.source, c.target) for c in scene.connections]  # output first


def test_export_command_writes_both(tmp_path: Path, capsys) -> None:
    scene = SCENARIOS / "m739.toml"
    code = main(["export", str(scene), str(tmp_path / "m739.ssp"), "--osp", str(tmp_path / "osp")])
    assert code == 0
    assert (tmp_path / "m739.ssp").is_file()
    assert (tmp_path / "osp" / FILE_NAME).is_file()
    assert sorted(p.name for p in (tmp_path / "osp").glob("*.fmu")) == ["train.fmu", "verge.fmu"]
    root = ET.parse(tmp_path / "osp" / FILE_NAME).getroot()
    impact = [
        c
        for c in root.iter(_q("VariableConnection"))
        if [v.get("name") for v in c.iter(_q("Variable"))] == ["impact_count", "impact_count"]
    ]
    assert len(impact) == 1  # the Integer connection is there


def test_osp_path_that_is_a_file_is_refused_in_one_line(tmp_path: Path, capsys) -> None:
    taken = tmp_path / "taken"
    taken.write_text("")
    scene = SCENARIOS / "two_inertias.toml"
    code = main(["export", str(scene), str(tmp_path / "t.ssp"), "--osp", str(taken)])
    err = capsys.readouterr().err
    assert code == 2 and "expected a directory" in err and err.count("\n") == 1
    assert not (tmp_path / "t.ssp").exists()  # nothing written before the refusal
