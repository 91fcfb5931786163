"""An SSP 1.0 archive as a scene: the system made elsewhere, run under our masters.

The archive is unpacked once per content (into the temporary directory, named by its
hash); its ``SystemStructure.ssd`` gives the FMUs, the parameter and input values bound
inline, the connections and the default experiment.  The master is fixed-step Jacobi at
the libcosim annotation's base step (or the scene default) unless a small TOML beside the
archive, ``<name>.toml``, says otherwise: its ``[master]``, ``[output]`` and ``[report]``
tables (and ``[scene]`` keys other than the FMUs and connections) are taken as they are.
Everything then goes through the same checks as a TOML scene.
"""

from __future__ import annotations

import hashlib
import math
import tempfile
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path
from typing import Any

from orchestrator.errors import ScenarioError
from orchestrator.model_info import ModelInfo, ModelInfoError, base_of_unit_name, model_info
from orchestrator.regular_files import ARCHIVE_LIMIT, NotARegularFile, read_regular
from orchestrator.scenario import read_toml, scene_from_table
from orchestrator.scene_model import Scene
from orchestrator.ssp_export import OSP, SSC, SSD, SSV

#: Tables a companion TOML may give (the system itself comes from the archive).
COMPANION_TABLES = ("master", "output", "report", "scene")


def load_ssp(
    path: str | Path,
    overrides: dict[str, Any] | None = None,
    cache_dir: Path | None = None,
    force: bool = False,
) -> Scene:
    """Read an .ssp archive (and its optional companion TOML) as a checked Scene."""
    path = Path(path)
    root, unpacked = _unpack(path)
    raw = scene_table(root, unpacked, f"{path}: SystemStructure.ssd")
    companion = path.with_suffix(".toml")
    if companion.is_file():
        extra = read_toml(companion)
        for table in COMPANION_TABLES:
            if isinstance(extra.get(table), dict):
                raw.setdefault(table, {}).update(extra[table])
    return scene_from_table(path, raw, overrides, cache_dir, force)


def _unpack(path: Path) -> tuple[ET.Element, Path]:
    try:
        data = read_regular(path, ARCHIVE_LIMIT)
    except FileNotFoundError:
        raise ScenarioError(path, "", "file not found") from None
    except NotARegularFile as exc:
        raise ScenarioError(path, "", str(exc.strerror)) from None
    digest = hashlib.sha256(data).hexdigest()[:16]
    target = Path(tempfile.gettempdir()) / "mechcosim-ssp" / f"{path.stem}-{digest}"
    try:
        with zipfile.ZipFile(path) as archive:
            if not target.is_dir():
                target.parent.mkdir(parents=True, exist_ok=True)
                part = Path(tempfile.mkdtemp(dir=target.parent))
                archive.extractall(part)
                try:
                    part.rename(target)
                except OSError:  # another process unpacked it first: use that one
                    pass
            root = ET.fromstring(archive.read("SystemStructure.ssd"))
    except (zipfile.BadZipFile, KeyError) as exc:
        raise ScenarioError(
            path, "", f"not an SSP archive with SystemStructure.ssd at its root ({exc})"
        ) from None
    except ET.ParseError as exc:
        raise ScenarioError(path, "SystemStructure.ssd", f"not well-formed XML: {exc}") from None
    return root, target


def scene_table(
    root: ET.Element, unpacked: Path, source: str | Path | None = None
) -> dict[str, Any]:
    """The raw scene table (as read from a TOML scene) of a SystemStructureDescription.
    ``source`` names the SSD in errors (default: the unpacked file); each error names the
    SSD element that is wrong."""
    ssd = source if source is not None else unpacked / "SystemStructure.ssd"
    system = root.find(f"{{{SSD}}}System")
    if system is None:
        raise ScenarioError(ssd, "System", "missing")
    name = root.get("name") or system.get("name") or "ssp"
    raw: dict[str, Any] = {"scene": {"name": name}, "fmus": {}, "connections": []}
    if system.get("description"):
        raw["scene"]["description"] = system.get("description")
    units = _unit_definitions(root, ssd)
    for i, component in enumerate(system.iter(f"{{{SSD}}}Component"), start=1):
        instance = component.get("name")
        if not instance:
            where = f"Component {i}"
            raise ScenarioError(
                ssd,
                where,
                f"has no name (source {component.get('source')!r}); every "
                "component needs one, unique in its system",
            )
        if instance in raw["fmus"]:
            raise ScenarioError(
                ssd, f"Component {instance!r}", "declared twice; component names must be unique"
            )
        inputs = {
            c.get("name") for c in component.iter(f"{{{SSD}}}Connector") if c.get("kind") == "input"
        }
        fmu = unpacked / component.get("source", "")
        entry: dict[str, Any] = {"fmu": str(fmu)}
        for parameter in component.iter(f"{{{SSV}}}Parameter"):
            name = parameter.get("name")
            where = f"Component {instance!r} Parameter {name!r}"
            if not name:
                raise ScenarioError(ssd, f"Component {instance!r} Parameter", "has no name")
            value = _value(parameter, ssd, where)
            if value is None:
                continue
            real = parameter.find(f"{{{SSV}}}Real")
            if real is not None and real.get("unit"):
                value = _in_declared_unit(fmu, name, value, real.get("unit"), units, (ssd, where))
            table = "inputs" if name in inputs else "parameters"
            entry.setdefault(table, {})[name] = value
        raw["fmus"][instance] = entry
    for i, c in enumerate(system.iter(f"{{{SSD}}}Connection"), start=1):
        ends = [c.get(k) for k in ("startElement", "startConnector", "endElement", "endConnector")]
        if not all(ends):
            missing = [
                k
                for k, v in zip(
                    ("startElement", "startConnector", "endElement", "endConnector"),
                    ends,
                    strict=True,
                )
                if not v
            ]
            raise ScenarioError(ssd, f"Connection {i}", f"has no {', '.join(missing)}")
        raw["connections"].append({"from": f"{ends[0]}.{ends[1]}", "to": f"{ends[2]}.{ends[3]}"})
    experiment = root.find(f"{{{SSD}}}DefaultExperiment")
    if experiment is not None:
        for key, attribute in (("start", "startTime"), ("stop", "stopTime")):
            if experiment.get(attribute) is not None:
                raw["scene"][key] = _number(
                    experiment.get(attribute), ssd, f"DefaultExperiment {attribute}"
                )
        fixed = experiment.find(
            f".//{{{SSC}}}Annotation/{{{OSP}}}Algorithm/{{{OSP}}}FixedStepAlgorithm"
        )
        if fixed is not None and fixed.get("baseStepSize") is not None:
            step = _number(fixed.get("baseStepSize"), ssd, "FixedStepAlgorithm baseStepSize")
            raw["master"] = {"algorithm": "jacobi", "step": step}
    return raw


def _number(text: str, ssd: str | Path, where: str) -> float:
    """A Real attribute of the SSD, or an error naming its element."""
    try:
        return float(text)
    except ValueError:
        raise ScenarioError(ssd, where, f"{text!r} is not a number") from None


Unit = tuple[tuple[tuple[str, int], ...], float, float]  # base exponents, factor, offset


def _unit_definitions(root: ET.Element, ssd: str | Path) -> dict[str, Unit]:
    """The SSD's own unit definitions (SSP 1.0, ssc:Unit with its ssc:BaseUnit)."""
    units: dict[str, Unit] = {}
    for unit in root.iter(f"{{{SSC}}}Unit"):
        base = unit.find(f"{{{SSC}}}BaseUnit")
        if unit.get("name") is None or base is None:
            continue
        where = f"Unit {unit.get('name')!r} BaseUnit"
        exponents = []
        for k, v in base.attrib.items():
            if k in ("factor", "offset"):
                continue
            try:
                exponents.append((k, int(v)))
            except ValueError:
                raise ScenarioError(
                    ssd, f"{where} {k}", f"{v!r} is not an integer exponent"
                ) from None
        exponents = tuple((k, v) for k, v in sorted(exponents) if v)
        factor = _number(base.get("factor", "1"), ssd, f"{where} factor")
        offset = _number(base.get("offset", "0"), ssd, f"{where} offset")
        if not (math.isfinite(factor) and factor != 0.0 and math.isfinite(offset)):
            raise ScenarioError(
                ssd,
                f"{where} factor",
                f"factor {factor!r} and offset {offset!r} must be finite, the factor not zero",
            )
        units[unit.get("name")] = (exponents, factor, offset)
    return units


def _in_declared_unit(
    fmu: Path,
    name: str,
    value: float,
    unit: str,
    ssd_units: dict[str, Unit],
    where: tuple[str | Path, str] | None = None,
) -> float:
    """A bound Real value in the unit its FMU declares for the variable (SSP 1.0: a
    parameter value's unit may differ from the connector's; the tool converts).  The scene
    holds values in the declared units, which is what the FMU is given."""
    try:
        model = model_info(fmu)
    except ModelInfoError:
        return value  # the scene check names the unreadable FMU
    var = model.variables.get(name)
    if var is None or var.unit is None or var.unit == unit:
        return value
    source, target = _base(unit, ssd_units, model), _base(var.unit, ssd_units, model)
    if source is None or target is None or source[0] != target[0]:
        ssd, key = where or (fmu.parent.parent / "SystemStructure.ssd", name)
        raise ScenarioError(
            ssd,
            key,
            f"bound in {unit!r}, which cannot be converted to the FMU's unit {var.unit!r}",
        )
    in_base = value * source[1] + source[2]
    return (in_base - target[2]) / target[1]


def _base(unit: str, ssd_units: dict[str, Unit], model: ModelInfo) -> Unit | None:
    if unit in ssd_units:
        return ssd_units[unit]
    if unit in model.unit_definitions:
        return model.unit_definitions[unit]
    known = base_of_unit_name(unit)
    return None if known is None else (*known, 0.0)


def _value(parameter: ET.Element, ssd: str | Path, where: str) -> float | int | bool | str | None:
    """The value bound by an ssv:Parameter, or an error naming it."""
    for child in parameter:
        tag = child.tag.rsplit("}", 1)[-1]
        text = child.get("value")
        if text is None:
            return None
        try:
            if tag == "Real":
                return float(text)
            if tag in ("Integer", "Enumeration"):
                return int(text)
        except ValueError:
            raise ScenarioError(ssd, where, f"{tag} value {text!r} is not a number") from None
        if tag == "Boolean":
            word = text.strip().lower()
            if word not in ("true", "false", "1", "0"):
                raise ScenarioError(ssd, where, f"Boolean value {text!r}; expected true or false")
            return word in ("true", "1")
        return text
    return None
