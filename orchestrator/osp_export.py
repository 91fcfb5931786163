"""A scene as libcosim's OSP-IS system structure: ``OspSystemStructure.xml`` with the
FMUs beside it.

Open Simulation Platform Interface Specification, system structure file (schema
``OspSystemStructure.xsd`` 0.1, namespace ``http://opensimulationplatform.com/MSMI/
OSPSystemStructure``): start time, base step and the fixed-step algorithm; one Simulator
per FMU instance with the scene's parameter and input values as InitialValues (in the
unit the FMU declares, which is how the scene holds them); one VariableConnection per
coupled variable, output first.  OSP-IS carries no units and no stop time: libcosim takes
every value in the FMU's own unit and runs as long as it is told.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

from orchestrator.run import fmu_files
from orchestrator.scene_model import Scene
from orchestrator.signals import libcosim_scenario
from orchestrator.ssp_export import libcosim_step

OSP_IS = "http://opensimulationplatform.com/MSMI/OSPSystemStructure"
FILE_NAME = "OspSystemStructure.xml"
SCENARIO_FILE = "scenario.json"  # the scene's input signals, when it has some
ET.register_namespace("", OSP_IS)


def _q(tag: str) -> str:
    return f"{{{OSP_IS}}}{tag}"


def osp_system_structure(scene: Scene, sources: dict[str, str]) -> ET.Element:
    """The OspSystemStructure element of ``scene``; ``sources``: instance -> FMU file
    relative to the XML file."""
    root = ET.Element(_q("OspSystemStructure"), version="0.1")
    ET.SubElement(root, _q("StartTime")).text = repr(scene.start)
    ET.SubElement(root, _q("BaseStepSize")).text = libcosim_step(scene.master.step)
    ET.SubElement(root, _q("Algorithm")).text = "fixedStep"
    simulators = ET.SubElement(root, _q("Simulators"))
    for name, spec in scene.fmus.items():
        simulator = ET.SubElement(simulators, _q("Simulator"), name=name, source=sources[name])
        values = {**spec.parameters, **spec.inputs}
        if not values:
            continue
        initial = ET.SubElement(simulator, _q("InitialValues"))
        for var_name, value in values.items():
            var = spec.model.variables[var_name]
            entry = ET.SubElement(initial, _q("InitialValue"), variable=var_name)
            if var.type == "Real":
                ET.SubElement(entry, _q("Real"), value=repr(float(value)))
            elif var.is_integer:
                ET.SubElement(entry, _q("Integer"), value=str(int(value)))
            elif var.type == "Boolean":
                ET.SubElement(entry, _q("Boolean"), value="true" if value else "false")
            else:
                ET.SubElement(entry, _q("String"), value=str(value))
    if scene.connections:
        connections = ET.SubElement(root, _q("Connections"))
        for c in scene.connections:
            connection = ET.SubElement(connections, _q("VariableConnection"))
            for instance, variable in (c.source, c.target):
                ET.SubElement(connection, _q("Variable"), simulator=instance, name=variable)
    return root


def export_osp(scene: Scene, out_dir: Path, cache_dir: Path | None = None) -> Path:
    """Write ``out_dir/OspSystemStructure.xml`` and one FMU per instance beside it
    (``<instance>.fmu``); return the XML file's path."""
    out_dir = Path(out_dir)
    scenario = libcosim_scenario(scene, scene.master.step)  # refuses what it cannot carry
    out_dir.mkdir(parents=True, exist_ok=True)
    if scenario is not None:
        (out_dir / SCENARIO_FILE).write_text(json.dumps(scenario, indent=2))
    paths = fmu_files(scene, cache_dir)
    # One file per instance: two instances of one FMU may carry different builds.
    sources = {name: f"{name}.fmu" for name in scene.fmus}
    for name, path in paths.items():
        _copy_atomically(Path(path), out_dir / sources[name])
    root = osp_system_structure(scene, sources)
    ET.indent(root)
    xml = ET.tostring(root, encoding="UTF-8", xml_declaration=True)
    target = out_dir / FILE_NAME
    fd, part = tempfile.mkstemp(dir=out_dir, prefix=FILE_NAME, suffix=".part")
    with os.fdopen(fd, "wb") as handle:
        handle.write(xml)
    os.replace(part, target)
    return target


def _copy_atomically(source: Path, target: Path) -> None:
    fd, part = tempfile.mkstemp(dir=target.parent, prefix=target.name, suffix=".part")
    os.close(fd)
    try:
        shutil.copyfile(source, part)
        os.replace(part, target)
    finally:
        if os.path.exists(part):
            os.unlink(part)
