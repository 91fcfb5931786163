"""What the orchestrator knows of an FMU: read from the FMU file and nothing else.

Plain FMI 2.0 gives the variables (causality, type, unit, start, range), the unit
definitions, the output dependencies and the capabilities.  Our own FMUs declare more in
a vendor annotation (``fmus/description.py``): ports as groups of variables by role, the
sampled inputs, the event indicators, the output that reports an internal event's time,
the regime output, whose names come from its Enumeration type, and each variable's
coupling role (``components.base.Role``), which masters read through ``role_of`` and
``with_role`` (never from names).  An FMU from another tool has none of these and is a
black box: no ports, no indicators, no roles, every input held.
"""

from __future__ import annotations

import math
import zipfile
from dataclasses import dataclass, field
from functools import cache
from pathlib import Path
from typing import Any
from xml.etree import ElementTree as ET

from fmpy import read_model_description

from components.base import ROLE_CAUSALITY, ROLES_OF, Role
from fmus.description import TOOL
from orchestrator import model_info_memo
from orchestrator.units import pint_unit

#: FMI types read and written with fmi2GetInteger / fmi2SetInteger
INTEGER_TYPES = ("Integer", "Enumeration")


class ModelInfoError(ValueError):
    """An FMU file that cannot be used: not an FMI 2.0 co-simulation FMU, unreadable."""


@dataclass(frozen=True)
class VariableInfo:
    name: str
    value_reference: int
    causality: str  # parameter, calculatedParameter, input, output, local, independent
    variability: str
    type: str  # Real, Integer, Enumeration, Boolean, String
    unit: str | None  # None: the FMU declares none
    start: str | None
    min: float | None
    max: float | None
    description: str
    #: the declared ``nominal`` of a Real (None where the FMU declares none)
    nominal: float | None = None

    @property
    def is_integer(self) -> bool:
        return self.type in INTEGER_TYPES


@dataclass(frozen=True)
class ModelInfo:
    path: Path
    model_name: str
    model_identifier: str
    guid: str
    generation_tool: str
    variables: dict[str, VariableInfo]
    can_get_set_state: bool
    can_handle_variable_step: bool
    #: per output: the inputs it depends on directly; None where the FMU does not say
    dependencies: dict[str, tuple[str, ...] | None]
    #: unit name -> (base-unit exponents, factor, offset) from UnitDefinitions
    unit_definitions: dict[str, tuple[tuple[tuple[str, int], ...], float, float]]
    ports: dict[str, dict[str, str]] = field(default_factory=dict)
    sampled: frozenset[str] = frozenset()
    indicators: tuple[str, ...] = ()
    event_time: str | None = None
    regime: str | None = None
    regime_names: dict[int, str] = field(default_factory=dict)
    annotated: bool = False  # carries our vendor annotation
    #: variable name -> its coupling role (our vendor annotation only)
    roles: dict[str, Role] = field(default_factory=dict)
    #: FMI 2.0 capabilities beyond the two above (the standard's defaults where not declared)
    can_interpolate_inputs: bool = False
    max_output_derivative_order: int = 0

    def role_of(self, name: str) -> Role | None:
        """The coupling role of variable ``name``; None where it has none."""
        return self.roles.get(name)

    def with_role(self, kind: str, of: str | None = None) -> VariableInfo | None:
        """The variable with the role ``kind`` (of variable ``of``, for the kinds that name
        one); None where the FMU declares none."""
        for name, role in self.roles.items():
            if role.kind == kind and role.of == of:
                return self.variables[name]
        return None

    def of(self, causality: str) -> list[VariableInfo]:
        return [v for v in self.variables.values() if v.causality == causality]

    def base_unit(self, unit: str | None) -> tuple[tuple[tuple[str, int], ...], float] | None:
        """(base-unit exponents, factor to base) of a unit name; None when unknown."""
        if unit is None:
            return None
        if unit in self.unit_definitions:
            exponents, factor, offset = self.unit_definitions[unit]
            return (exponents, factor) if offset == 0.0 else None
        return base_of_unit_name(unit)


def base_of_unit_name(unit: str) -> tuple[tuple[tuple[str, int], ...], float] | None:
    """A unit name read by pint: (exponents over kg, m, s, A, K, mol, cd, rad; factor)."""
    try:
        q = (1.0 * pint_unit(unit)).to_base_units()
    except Exception:  # pint raises many kinds for names it cannot read
        return None
    names = {"[mass]": "kg", "[length]": "m", "[time]": "s", "[current]": "A"}
    names |= {"[temperature]": "K", "[substance]": "mol", "[luminosity]": "cd"}
    exponents: dict[str, int] = {}
    for dim, power in q.dimensionality.items():
        if dim not in names or power != int(power):
            return None
        exponents[names[dim]] = int(power)
    if "radian" in str(q.units):  # pint keeps the radian as a unit, not a dimension
        exponents["rad"] = int(dict(q.units._units).get("radian", 0))
    return tuple(sorted((k, v) for k, v in exponents.items() if v)), float(q.magnitude)


@cache
def model_info(path: Path) -> ModelInfo:
    """Read an FMU file (cached per path: built FMUs are named by their content hash; and
    between processes by the file's hash, ``orchestrator.model_info_memo``)."""
    path = Path(path)
    known = model_info_memo.recall(path)
    if known is not None:
        return known
    info = _read_model_info(path)
    model_info_memo.remember(path, info)
    return info


def _read_model_info(path: Path) -> ModelInfo:
    _check_description(path, _description(path))
    try:
        md = read_model_description(str(path), validate=False)
    except Exception as exc:  # fmpy raises zip, XML and its own errors
        raise ModelInfoError(f"cannot read {path} as an FMU: {exc}") from None
    if md.fmiVersion != "2.0":
        raise ModelInfoError(f"{path} is FMI {md.fmiVersion}; expected FMI 2.0")
    if md.coSimulation is None:
        raise ModelInfoError(f"{path} has no co-simulation interface (Model Exchange only)")
    variables = {v.name: _variable(v) for v in md.modelVariables}
    dependencies: dict[str, tuple[str, ...] | None] = {}
    for unknown in md.outputs:
        deps = unknown.dependencies
        dependencies[unknown.variable.name] = None if deps is None else tuple(d.name for d in deps)
    units = {}
    for u in md.unitDefinitions:
        b = u.baseUnit
        if b is None:
            continue
        exps = [(k, getattr(b, k)) for k in ("kg", "m", "s", "A", "K", "mol", "cd", "rad")]
        units[u.name] = (tuple(sorted((k, v) for k, v in exps if v)), b.factor, b.offset)
    info: dict[str, Any] = dict(
        path=path,
        model_name=md.modelName,
        model_identifier=md.coSimulation.modelIdentifier,
        guid=md.guid,
        generation_tool=md.generationTool or "",
        variables=variables,
        can_get_set_state=bool(md.coSimulation.canGetAndSetFMUstate),
        can_handle_variable_step=bool(md.coSimulation.canHandleVariableCommunicationStepSize),
        can_interpolate_inputs=bool(md.coSimulation.canInterpolateInputs),
        max_output_derivative_order=int(md.coSimulation.maxOutputDerivativeOrder or 0),
        dependencies=dependencies,
        unit_definitions=units,
    )
    annotation = _annotation(path)
    if annotation is not None:
        info |= _coupling(annotation, variables, md)
    return ModelInfo(**info)


def _description(path: Path) -> ET.Element:
    """The root of an FMU's modelDescription.xml."""
    try:
        with zipfile.ZipFile(path) as z:
            return ET.fromstring(z.read("modelDescription.xml"))
    except KeyError:
        raise ModelInfoError(f"{path} has no modelDescription.xml: not an FMU") from None
    except (OSError, zipfile.BadZipFile, ET.ParseError, ValueError) as exc:
        raise ModelInfoError(f"cannot read {path} as an FMU: {exc}") from None


def _check_description(path: Path, root: ET.Element) -> None:
    """What must hold before fmpy reads the description: the FMI version (fmpy reads FMI
    1.0 and 3.0 descriptions its own way, and this orchestrator calls FMI 2.0 only) and
    unique variable names (fmpy would keep the last of two, silently)."""
    version = root.get("fmiVersion")
    if root.tag == "fmiModelDescription" and version is not None and version != "2.0":
        major = version.split(".")[0]
        label = {"1": "1.0", "3": "3.0"}.get(major, version)
        raise ModelInfoError(
            f"FMI {label} FMUs are not supported: {path} is FMI {version}; expected an FMI 2.0 "
            "co-simulation FMU"
        )
    seen: dict[str, int] = {}
    for i, v in enumerate(root.iterfind("ModelVariables/ScalarVariable"), start=1):
        name = v.get("name")
        if name in seen:
            raise ModelInfoError(
                f"{path}: modelDescription.xml declares the variable {name!r} twice "
                f"(ScalarVariable {seen[name]} and {i}); variable names must be unique"
            )
        seen[name] = i


def _variable(v: Any) -> VariableInfo:
    declared = v.declaredType
    unit = v.unit or (declared.unit if declared is not None else None)
    return VariableInfo(
        name=v.name,
        value_reference=v.valueReference,
        causality=v.causality,
        variability=v.variability,
        type=v.type,
        unit=unit or None,
        start=v.start,
        min=_bound(v.min if v.min is not None else getattr(declared, "min", None)),
        max=_bound(v.max if v.max is not None else getattr(declared, "max", None)),
        description=v.description or "",
        nominal=_bound(getattr(v, "nominal", None)),
    )


def _bound(text: str | None) -> float | None:
    if text is None:
        return None
    try:
        value = float(text)
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def _annotation(path: Path) -> ET.Element | None:
    """Our vendor annotation's Coupling element, if the FMU carries one."""
    with zipfile.ZipFile(path) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    for tool in root.iterfind("VendorAnnotations/Tool"):
        if tool.get("name") == TOOL and tool.find("Coupling") is not None:
            return tool.find("Coupling")
    return None


def _coupling(node: ET.Element, variables: dict[str, VariableInfo], md: Any) -> dict[str, Any]:
    def names(tag: str) -> list[str]:
        found = [v.get("name") for v in node.iterfind(f"{tag}/Variable")]
        unknown = [n for n in found if n not in variables]
        if unknown:
            raise ModelInfoError(f"{md.modelName}: annotation names unknown variables {unknown}")
        return found

    ports = {
        port.get("name"): {r.get("name"): r.get("variable") for r in port.iterfind("Role")}
        for port in node.iterfind("Ports/Port")
    }
    event_time = node.find("EventTime")
    regime = node.find("Regime")
    regime_var = regime.get("variable") if regime is not None else None
    regime_names: dict[int, str] = {}
    if regime_var is not None:
        declared = next(v for v in md.modelVariables if v.name == regime_var).declaredType
        if declared is not None:
            regime_names = {int(item.value): item.name for item in declared.items}
    return dict(
        roles=_roles(node, variables, md.modelName),
        ports=ports,
        sampled=frozenset(names("SampledInputs")),
        indicators=tuple(names("EventIndicators")),
        event_time=event_time.get("variable") if event_time is not None else None,
        regime=regime_var,
        regime_names=regime_names,
        annotated=True,
    )


def _roles(node: ET.Element, variables: dict[str, VariableInfo], model: str) -> dict[str, Role]:
    """The annotation's coupling roles, each checked against the variables it names."""
    roles: dict[str, Role] = {}
    for element in node.iterfind("Roles/Variable"):
        name, kind, of = element.get("name"), element.get("role"), element.get("of")
        where = f"{model}: the annotation's role of {name!r}"
        if kind not in ROLE_CAUSALITY:
            raise ModelInfoError(f"{where} is {kind!r}; expected one of {sorted(ROLE_CAUSALITY)}")
        own, other = ROLE_CAUSALITY[kind]
        var = variables.get(name)
        if var is None or var.causality != own:
            raise ModelInfoError(f"{where}, {kind}: expected an {own} of that name")
        if (of is not None) != (kind in ROLES_OF):
            raise ModelInfoError(f"{where}, {kind}: 'of' is {'missing' if of is None else 'extra'}")
        if other is not None and (of not in variables or variables[of].causality != other):
            raise ModelInfoError(f"{where}, {kind} {of}: expected {of!r} to be an {other}")
        roles[name] = Role(kind, of)
    return roles
