"""Scenes exported as SSP 1.0 archives: schema-valid, complete, and runnable in libcosim."""

from __future__ import annotations

import json
import tomllib
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy.ssp.ssd import read_ssd

from orchestrator.errors import ScenarioError
from orchestrator.run import run_scene
from orchestrator.scenario import load_scene
from orchestrator.ssp_export import SSD, export_ssp
from orchestrator.ssp_import import load_ssp

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
SCENES = sorted(SCENARIOS.glob("*.toml")) + sorted((SCENARIOS / "stability").glob("*.toml"))


@pytest.mark.parametrize("path", SCENES, ids=lambda p: p.stem)
def test_every_scene_exports_a_valid_system(path: Path, tmp_path: Path) -> None:
    scene = load_scene(path)
    out = export_ssp(scene, tmp_path / f"{path.stem}.ssp")
    ssd = read_ssd(str(out), validate=True)  # FMPy checks it against the SSP 1.0 schema
    components = {c.name: c for c in ssd.system.elements}
    assert set(components) == set(scene.fmus)
    with zipfile.ZipFile(out) as archive:
        names = set(archive.namelist())
    for name, component in components.items():
        assert component.source in names
        connectors = {c.name: c for c in component.connectors}
        model = scene.fmus[name].model
        for var in model.variables.values():
            if var.causality in ("parameter", "input", "output") and var.type != "Enumeration":
                assert connectors[var.name].kind == var.causality
            elif var.type == "Enumeration":  # libcosim refuses them: only where needed
                assert var.name not in connectors or _needed(scene, name, var.name)
    wired = {
        (c.startElement, c.startConnector, c.endElement, c.endConnector)
        for c in ssd.system.connections
    }
    assert wired == {(*c.source, *c.target) for c in scene.connections}
    with zipfile.ZipFile(out) as archive:
        root = ET.fromstring(archive.read("SystemStructure.ssd"))
    experiment = root.find(f"{{{SSD}}}DefaultExperiment")  # FMPy's reader skips it
    assert float(experiment.get("stopTime")) == scene.stop


def _needed(scene, instance: str, variable: str) -> bool:
    ends = {end for c in scene.connections for end in (c.source, c.target)}
    spec = scene.fmus[instance]
    return (instance, variable) in ends or variable in spec.parameters | spec.inputs


def test_bound_values_are_the_scenes(tmp_path: Path) -> None:
    scene = load_scene(SCENARIOS / "m739.toml")
    out = export_ssp(scene, tmp_path / "m739.ssp")
    with zipfile.ZipFile(out) as archive:
        text = archive.read("SystemStructure.ssd").decode()
    # 30,000 rpm in SI, and the Integer impact connection is there.
    assert f'value="{scene.fmus["train"].parameters["spin"]!r}"' in text
    assert 'startConnector="impact_count"' in text
    assert 'baseStepSize="1e-06"' in text


@pytest.mark.parametrize(
    ("scene_file", "stop"),
    [("two_inertias.toml", 0.01), ("m739.toml", 0.002), ("press_feed_run1.toml", 0.005)],
)
def test_exported_system_runs_here_bit_for_bit(scene_file: str, stop: float, tmp_path: Path):
    """TOML scene -> .ssp -> run under our master (its [master] from a TOML beside the
    archive): every recorded signal equals the TOML scene's, bit for bit."""
    original = SCENARIOS / scene_file
    scene = load_scene(original, {"scene.stop": stop})
    ours = run_scene(scene, output_dir=tmp_path / "toml", show_progress=False, plots=False)
    archive = export_ssp(scene, tmp_path / "system.ssp")
    master = tomllib.loads(original.read_text())["master"]
    record = [f"{i}.{v}" for i, v in scene.record]
    (tmp_path / "system.toml").write_text(_toml({"master": master, "output": {"record": record}}))
    imported = load_ssp(archive)
    assert imported.master == scene.master and imported.stop == scene.stop
    theirs = run_scene(imported, output_dir=tmp_path / "ssp", show_progress=False, plots=False)
    assert theirs.status == ours.status == "completed"
    assert theirs.header == ours.header
    assert np.array_equal(theirs.data, ours.data)
    assert theirs.events == ours.events


def _toml(tables: dict) -> str:
    """Enough TOML for flat tables of strings, numbers and lists of strings."""
    lines = []
    for table, entries in tables.items():
        lines.append(f"[{table}]")
        for key, value in entries.items():
            lines.append(f"{key} = {json.dumps(value)}")
    return "\n".join(lines) + "\n"


def test_a_file_that_is_no_archive_is_refused_in_one_line(tmp_path: Path) -> None:
    bad = tmp_path / "bad.ssp"
    bad.write_text("not a zip")
    with pytest.raises(ScenarioError, match="not an SSP archive"):
        load_ssp(bad)
