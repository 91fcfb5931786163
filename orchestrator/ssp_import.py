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
import tempfile
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path
from typing import Any

from orchestrator.errors import ScenarioError
from orchestrator.scenario import Scene, read_toml, scene_from_table
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
    raw = scene_table(root, unpacked)
    companion = path.with_suffix(".toml")
    if companion.is_file():
        extra = read_toml(companion)
        for table in COMPANION_TABLES:
            if isinstance(extra.get(table), dict):
                raw.setdefault(table, {}).update(extra[table])
    return scene_from_table(path, raw, overrides, cache_dir, force)


def _unpack(path: Path) -> tuple[ET.Element, Path]:
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise ScenarioError(path, "", "file not found") from None
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


def scene_table(root: ET.Element, unpacked: Path) -> dict[str, Any]:
    """The raw scene table (as read from a TOML scene) of a SystemStructureDescription."""
    system = root.find(f"{{{SSD}}}System")
    if system is None:
        raise ScenarioError(unpacked / "SystemStructure.ssd", "System", "missing")
    name = root.get("name") or system.get("name") or "ssp"
    raw: dict[str, Any] = {"scene": {"name": name}, "fmus": {}, "connections": []}
    if system.get("description"):
        raw["scene"]["description"] = system.get("description")
    for component in system.iter(f"{{{SSD}}}Component"):
        inputs = {
            c.get("name") for c in component.iter(f"{{{SSD}}}Connector") if c.get("kind") == "input"
        }
        entry: dict[str, Any] = {"fmu": str(unpacked / component.get("source", ""))}
        for parameter in component.iter(f"{{{SSV}}}Parameter"):
            value = _value(parameter)
            if value is not None:
                table = "inputs" if parameter.get("name") in inputs else "parameters"
                entry.setdefault(table, {})[parameter.get("name")] = value
        raw["fmus"][component.get("name")] = entry
    for c in system.iter(f"{{{SSD}}}Connection"):
        raw["connections"].append(
            {
                "from": f"{c.get('startElement')}.{c.get('startConnector')}",
                "to": f"{c.get('endElement')}.{c.get('endConnector')}",
            }
        )
    experiment = root.find(f"{{{SSD}}}DefaultExperiment")
    if experiment is not None:
        for key, attribute in (("start", "startTime"), ("stop", "stopTime")):
            if experiment.get(attribute) is not None:
                raw["scene"][key] = float(experiment.get(attribute))
        fixed = experiment.find(
            f".//{{{SSC}}}Annotation/{{{OSP}}}Algorithm/{{{OSP}}}FixedStepAlgorithm"
        )
        if fixed is not None and fixed.get("baseStepSize") is not None:
            raw["master"] = {"algorithm": "jacobi", "step": float(fixed.get("baseStepSize"))}
    return raw


def _value(parameter: ET.Element) -> float | int | bool | str | None:
    for child in parameter:
        tag = child.tag.rsplit("}", 1)[-1]
        text = child.get("value")
        if text is None:
            return None
        if tag == "Real":
            return float(text)
        if tag in ("Integer", "Enumeration"):
            return int(text)
        if tag == "Boolean":
            return text.strip().lower() in ("true", "1")
        return text
    return None
