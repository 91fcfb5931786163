"""The complete model description of a component FMU.

pythonfmu writes a model description without units, ranges or a ModelStructure worth
the name.  ``complete_description`` adds, from the component's VARIABLES table:

* the unit definitions and the unit of every Real, and each parameter's valid range
  (``min``/``max``); a Real's ``nominal`` where the component declares one;
* the regime as an Enumeration type whose items name the regimes;
* an honest ModelStructure: each output lists the inputs it depends on directly
  (``dependencies=""`` where it depends on none), so that other masters see no false
  algebraic loops;
* a vendor annotation (tool ``mechcosim``) with what a master needs and FMI 2.0 cannot
  say: ports as groups of variables by role, the sampled inputs, the event indicators, the
  output that reports the time of an internal event, the regime output, and each
  variable's coupling role (``components.base.Role``: rate of, step mean of, own copy of,
  early return, reached time).  Any master may ignore it; ours read it
  (``orchestrator/model_info.py``).
"""

from __future__ import annotations

from xml.etree import ElementTree as ET

from components.base import Component, Variable, role_problem
from fmus.units import base_unit_exponents

#: The vendor annotation's tool name, and the version of its layout.
TOOL = "mechcosim"
ANNOTATION_VERSION = "2"  # 2: with Roles
#: Outputs named so are event indicators: a regime switch happens where one crosses zero.
INDICATOR_PREFIX = "ind_"
EVENT_TIME = "t_event"
REGIME = "regime"


def complete_description(root: ET.Element, component_class: type[Component]) -> None:
    """Complete pythonfmu's model description ``root`` in place."""
    model = root.get("modelName")
    by_name: dict[str, Variable] = {v.name: v for v in component_class.VARIABLES}
    regime_names: dict[int, str] = getattr(component_class, "REGIME_NAMES", {})
    regime_type = f"{model}.Regime"
    units: list[str] = []
    index_of: dict[str, int] = {}
    for index, sv in enumerate(root.find("ModelVariables").findall("ScalarVariable"), start=1):
        var = by_name[sv.get("name")]
        index_of[var.name] = index
        real = sv.find("Real")
        if real is not None:
            if var.unit != "1":
                real.set("unit", var.unit)
                if var.unit not in units:
                    units.append(var.unit)
            _set_range(real, var)
            if var.nominal is not None:
                real.set("nominal", repr(float(var.nominal)))
        elif var.name == REGIME and regime_names:
            integer = sv.find("Integer")
            sv.remove(integer)
            ET.SubElement(sv, "Enumeration", declaredType=regime_type)
        else:
            _set_range(sv.find("Integer"), var)

    # FMI 2.0 order: CoSimulation, UnitDefinitions, TypeDefinitions, LogCategories,
    # DefaultExperiment, VendorAnnotations, ModelVariables, ModelStructure.
    position = list(root).index(root.find("CoSimulation")) + 1
    if units:
        root.insert(position, _unit_definitions(units))
        position += 1
    if regime_names:
        root.insert(position, _regime_type(regime_type, regime_names))
    position = list(root).index(root.find("ModelVariables"))
    root.insert(position, _vendor_annotation(component_class))
    _model_structure(root.find("ModelStructure"), component_class, index_of)


def _set_range(element: ET.Element, var: Variable) -> None:
    for key in ("min", "max"):
        bound = getattr(var, key)
        if bound is not None:
            element.set(key, repr(int(bound) if var.type == "Integer" else float(bound)))


def _unit_definitions(units: list[str]) -> ET.Element:
    definitions = ET.Element("UnitDefinitions")
    for unit in units:
        u = ET.SubElement(definitions, "Unit", name=unit)
        exps = {k: str(v) for k, v in base_unit_exponents(unit).items() if v}
        ET.SubElement(u, "BaseUnit", exps)
    return definitions


def _regime_type(name: str, regime_names: dict[int, str]) -> ET.Element:
    types = ET.Element("TypeDefinitions")
    simple = ET.SubElement(types, "SimpleType", name=name, description="regime (mode)")
    enumeration = ET.SubElement(simple, "Enumeration")
    for value, item in sorted(regime_names.items()):
        ET.SubElement(enumeration, "Item", name=item, value=str(value))
    return types


def _vendor_annotation(component_class: type[Component]) -> ET.Element:
    annotations = ET.Element("VendorAnnotations")
    tool = ET.SubElement(annotations, "Tool", name=TOOL)
    ours = ET.SubElement(tool, "Coupling", version=ANNOTATION_VERSION)
    ports = ET.SubElement(ours, "Ports")
    for port, roles in component_class.PORTS.items():
        p = ET.SubElement(ports, "Port", name=port)
        for role, variable in roles.items():
            ET.SubElement(p, "Role", name=role, variable=variable)
    sampled = ET.SubElement(ours, "SampledInputs")
    outputs = component_class.variables("output")
    for var in component_class.variables("input"):
        if var.sampled:
            ET.SubElement(sampled, "Variable", name=var.name)
    indicators = ET.SubElement(ours, "EventIndicators")
    for var in outputs:
        if var.name.startswith(INDICATOR_PREFIX):
            ET.SubElement(indicators, "Variable", name=var.name)
    names = {v.name for v in outputs}
    if EVENT_TIME in names:
        ET.SubElement(ours, "EventTime", variable=EVENT_TIME)
    if REGIME in names:
        ET.SubElement(ours, "Regime", variable=REGIME)
    roles = ET.SubElement(ours, "Roles")
    by_name = {v.name: v for v in component_class.VARIABLES}
    for var in component_class.VARIABLES:
        if var.role is None:
            continue
        problem = role_problem(var, by_name)
        if problem is not None:
            raise ValueError(f"{component_class.__name__}: {problem}")
        of = {"of": var.role.of} if var.role.of else {}
        ET.SubElement(roles, "Variable", name=var.name, role=var.role.kind, **of)
    return annotations


def _model_structure(
    structure: ET.Element, component_class: type[Component], index_of: dict[str, int]
) -> None:
    for child in list(structure):
        structure.remove(child)
    outputs = component_class.variables("output")
    if not outputs:
        return
    listed = ET.SubElement(structure, "Outputs")
    initial = ET.SubElement(structure, "InitialUnknowns")
    for var in outputs:
        deps = " ".join(str(i) for i in sorted(index_of[name] for name in var.depends_on))
        ET.SubElement(listed, "Unknown", index=str(index_of[var.name]), dependencies=deps)
        ET.SubElement(initial, "Unknown", index=str(index_of[var.name]))
