"""A scene as an SSP 1.0 archive: ``SystemStructure.ssd`` at the root, the FMUs in
``resources/``.

System Structure and Parameterization 1.0 (Modelica Association, 2019): one component per
FMU instance with its connectors (kind, type, unit), one connection per coupled variable
(ports expanded, Integer connections included), the scene's parameter and input values as
inline parameter bindings, the unit definitions, and the default experiment.  The default
experiment carries the annotation by which libcosim takes its fixed-step algorithm and
base step (type ``com.opensimulationplatform``), set to the scene's macro step.
"""

from __future__ import annotations

import os
import tempfile
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path
from typing import Any

from orchestrator.run import fmu_files
from orchestrator.scene_model import Scene
from orchestrator.signals import refuse_signals

SSD = "http://ssp-standard.org/SSP1/SystemStructureDescription"
SSC = "http://ssp-standard.org/SSP1/SystemStructureCommon"
SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
OSP = "http://opensimulationplatform.com/SSP/OSPAnnotations"
for _prefix, _uri in (("ssd", SSD), ("ssc", SSC), ("ssv", SSV), ("osp", OSP)):
    ET.register_namespace(_prefix, _uri)

#: FMI variable types that an SSD connector names.  An Enumeration would need the type's
#: definition in the SSD too, and libcosim refuses both an ssc:Enumeration connector and
#: an untyped one; so an Enumeration variable gets a connector (untyped: the type is left
#: to the FMU, as SSP allows) only when a connection or a value needs it.  SSP does not
#: ask for a connector per variable.
_CONNECTOR_TYPES = ("Real", "Integer", "Boolean", "String")
_KINDS = ("parameter", "input", "output")  # FMI causalities that are SSD connector kinds
_BASE_UNITS = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")


def _q(namespace: str, tag: str) -> str:
    return f"{{{namespace}}}{tag}"


def system_structure(scene: Scene, sources: dict[str, str]) -> ET.Element:
    """The SystemStructureDescription of ``scene``; ``sources``: instance -> FMU path in
    the archive."""
    root = ET.Element(_q(SSD, "SystemStructureDescription"), version="1.0", name=scene.name)
    system = ET.SubElement(root, _q(SSD, "System"), name=scene.name)
    if scene.description:
        system.set("description", scene.description)
    elements = ET.SubElement(system, _q(SSD, "Elements"))
    units: dict[str, tuple[tuple[tuple[str, int], ...], float]] = {}
    wired = {end for c in scene.connections for end in (c.source, c.target)}
    for name, spec in scene.fmus.items():
        component = ET.SubElement(
            elements,
            _q(SSD, "Component"),
            name=name,
            type="application/x-fmu-sharedlibrary",
            source=sources[name],
        )
        connectors = ET.SubElement(component, _q(SSD, "Connectors"))
        for var in spec.model.variables.values():
            if var.causality not in _KINDS:
                continue
            needed = (name, var.name) in wired or var.name in spec.parameters | spec.inputs
            if var.type not in _CONNECTOR_TYPES and not needed:
                continue
            connector = ET.SubElement(
                connectors, _q(SSD, "Connector"), name=var.name, kind=var.causality
            )
            if var.type in _CONNECTOR_TYPES:
                typed = ET.SubElement(connector, _q(SSC, var.type))
                if var.type == "Real" and var.unit:
                    typed.set("unit", var.unit)
                    base = spec.model.base_unit(var.unit)
                    if base is not None:
                        units.setdefault(var.unit, base)
        values = {**spec.parameters, **spec.inputs}
        if values:
            bindings = ET.SubElement(component, _q(SSD, "ParameterBindings"))
            binding = ET.SubElement(bindings, _q(SSD, "ParameterBinding"))
            holder = ET.SubElement(binding, _q(SSD, "ParameterValues"))
            parameter_set = ET.SubElement(holder, _q(SSV, "ParameterSet"), version="1.0", name=name)
            parameters = ET.SubElement(parameter_set, _q(SSV, "Parameters"))
            for var_name, value in values.items():
                _parameter(parameters, spec.model.variables[var_name], value)
    if scene.connections:  # the schema wants at least one Connection in Connections
        connections = ET.SubElement(system, _q(SSD, "Connections"))
        for c in scene.connections:
            ET.SubElement(
                connections,
                _q(SSD, "Connection"),
                startElement=c.source[0],
                startConnector=c.source[1],
                endElement=c.target[0],
                endConnector=c.target[1],
            )
    if units:
        unit_list = ET.SubElement(root, _q(SSD, "Units"))
        for unit, (exponents, factor) in sorted(units.items()):
            unit_element = ET.SubElement(unit_list, _q(SSC, "Unit"), name=unit)
            base = ET.SubElement(unit_element, _q(SSC, "BaseUnit"))
            for base_name, power in exponents:
                if base_name in _BASE_UNITS:
                    base.set(base_name, str(power))
            if factor != 1.0:
                base.set("factor", repr(factor))
    experiment = ET.SubElement(
        root, _q(SSD, "DefaultExperiment"), startTime=repr(scene.start), stopTime=repr(scene.stop)
    )
    annotations = ET.SubElement(experiment, _q(SSD, "Annotations"))
    annotation = ET.SubElement(
        annotations, _q(SSC, "Annotation"), type="com.opensimulationplatform"
    )
    algorithm = ET.SubElement(annotation, _q(OSP, "Algorithm"))
    step = libcosim_step(scene.master.step)
    ET.SubElement(algorithm, _q(OSP, "FixedStepAlgorithm"), baseStepSize=step)
    return root


def libcosim_step(step: float) -> str:
    """The macro step as written for libcosim.  libcosim keeps time in whole nanoseconds
    and truncates what it reads (50 µs converted to 4.9999999999999996e-05 s would step
    49999 ns), so a step within round-off of a whole number of nanoseconds is written as
    that number."""
    ns = round(step * 1e9)
    if ns >= 1 and abs(step * 1e9 - ns) <= 1e-6:
        return repr(ns / 1e9)
    return repr(step)


def _parameter(parent: ET.Element, var: Any, value: object) -> None:
    parameter = ET.SubElement(parent, _q(SSV, "Parameter"), name=var.name)
    if var.type == "Real":
        typed = ET.SubElement(parameter, _q(SSV, "Real"), value=repr(float(value)))  # type: ignore[arg-type]
        if var.unit:
            typed.set("unit", var.unit)
    elif var.type in ("Integer", "Enumeration"):
        ET.SubElement(parameter, _q(SSV, "Integer"), value=str(int(value)))  # type: ignore[call-overload]
    elif var.type == "Boolean":
        ET.SubElement(parameter, _q(SSV, "Boolean"), value="true" if value else "false")
    else:
        ET.SubElement(parameter, _q(SSV, "String"), value=str(value))


def export_ssp(scene: Scene, out: Path, cache_dir: Path | None = None) -> Path:
    """Write ``scene`` as the SSP archive ``out`` (atomically) and return its path."""
    out = Path(out)
    refuse_signals(scene, "SSP 1.0", "has no time-varying source (export --osp carries it)")
    paths = fmu_files(scene, cache_dir)
    # One file per instance: two instances of one FMU may carry different builds.
    sources = {name: f"resources/{name}.fmu" for name in scene.fmus}
    root = system_structure(scene, sources)
    ET.indent(root)
    xml = ET.tostring(root, encoding="UTF-8", xml_declaration=True)
    out.parent.mkdir(parents=True, exist_ok=True)
    fd, part = tempfile.mkstemp(dir=out.parent, prefix=out.name, suffix=".part")
    os.close(fd)
    try:
        with zipfile.ZipFile(part, "w", zipfile.ZIP_DEFLATED) as archive:
            archive.writestr("SystemStructure.ssd", xml)
            for name, path in paths.items():
                archive.write(path, sources[name])
        os.replace(part, out)
    finally:
        if os.path.exists(part):
            os.unlink(part)
    return out
