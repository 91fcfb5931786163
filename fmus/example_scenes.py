"""An FMU's example scenes, as its documentation shows them: which FMUs they hold and how
they are connected, variable by variable.

Only a scene's structure is read (``[fmus.<instance>] component`` and ``[[connections]]``),
never its values: the FMU's documentation, and so the FMU's build hash, follow how the
scene couples the FMU, not the parameters it happens to set (editing a scene's spin rate
rebuilds nothing).
"""

from __future__ import annotations

import json
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from components.base import Component
from fmus.ports import PortError, PortSide, join_ports


class ExampleSceneError(ValueError):
    """An example scene that cannot be shown (missing, unreadable, a broken connection)."""


@dataclass(frozen=True)
class ExampleConnection:
    source: tuple[str, str]  # (instance, variable), an output
    target: tuple[str, str]  # (instance, variable), an input
    type: str  # "Real" or "Integer"
    via: str  # the scene entry it comes from


@dataclass(frozen=True)
class ExampleScene:
    path: str  # from the project root
    instances: tuple[tuple[str, str], ...]  # (instance, FMU model identifier), scene order
    #: the [[connections]] entries as written: ("ports", a, b) or ("signal", from, to)
    entries: tuple[tuple[str, str, str], ...]
    connections: tuple[ExampleConnection, ...]  # the entries, variable by variable

    def identity(self) -> str:
        """What of the scene the documentation shows: the input of the FMU's build hash."""
        return json.dumps([self.path, self.instances, self.entries])


def read_example_scene(
    project_dir: Path, path: str, fmu: str, classes: Mapping[str, type[Component]]
) -> ExampleScene:
    """The structure of the scene at ``project_dir / path``, an example of FMU ``fmu``;
    ``classes``: the component class of every FMU, by name."""
    file = project_dir / path
    if not file.is_file():
        raise ExampleSceneError(f"{fmu}: example scene {path} does not exist in {project_dir}")
    try:
        scene = tomllib.loads(file.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise ExampleSceneError(f"{path}: not valid TOML: {exc}") from None
    instances: dict[str, str] = {}
    for instance, spec in scene.get("fmus", {}).items():
        model = spec.get("component") if isinstance(spec, dict) else None
        if model not in classes:
            raise ExampleSceneError(f"{path}: fmus.{instance}: unknown component {model!r}")
        instances[instance] = model
    if fmu not in instances.values():
        raise ExampleSceneError(f"{path}: no instance of {fmu}, yet listed as its example")
    by_instance = {inst: classes[model] for inst, model in instances.items()}
    entries = tuple(
        _entry(f"{path}: connections[{i}]", entry, by_instance)
        for i, entry in enumerate(scene.get("connections", []))
    )
    connections = tuple(
        c for i, entry in enumerate(entries) for c in _expand(path, i, entry, by_instance)
    )
    return ExampleScene(path, tuple(instances.items()), entries, connections)


def _entry(
    key: str, entry: dict[str, object], classes: Mapping[str, type[Component]]
) -> tuple[str, str, str]:
    if "ports" in entry:
        ports = entry["ports"]
        if not (isinstance(ports, list) and len(ports) == 2):
            raise ExampleSceneError(f"{key}: expected two ports")
        for port in ports:
            _split(key, port, classes)
        return ("ports", ports[0], ports[1])
    if "from" not in entry or "to" not in entry:
        raise ExampleSceneError(f"{key}: expected 'ports' or 'from' and 'to'")
    for ref in (entry["from"], entry["to"]):
        _split(key, ref, classes)
    return ("signal", str(entry["from"]), str(entry["to"]))


def _expand(
    path: str, i: int, entry: tuple[str, str, str], classes: Mapping[str, type[Component]]
) -> list[ExampleConnection]:
    """One connection entry as variable-level connections (the port rule)."""
    key = f"{path}: connections[{i}]"
    kind, a, b = entry
    (ia, pa), (ib, pb) = _split(key, a, classes), _split(key, b, classes)
    ca, cb = classes[ia], classes[ib]
    if kind == "signal":
        return [ExampleConnection((ia, pa), (ib, pb), ca.variable(pa).type, "signal")]
    if pa not in ca.PORTS or pb not in cb.PORTS:
        raise ExampleSceneError(f"{key}: unknown port in {[a, b]}")
    sides = (
        PortSide(ia, pa, ca.PORTS[pa], lambda name: ca.variable(name).causality),
        PortSide(ib, pb, cb.PORTS[pb], lambda name: cb.variable(name).causality),
    )
    try:
        links = join_ports(*sides)
    except PortError as exc:
        raise ExampleSceneError(f"{key}: {exc}") from None
    via = f"{ia}.{pa} \u2194 {ib}.{pb}"
    return [
        ExampleConnection(
            link.source,
            link.target,
            classes[link.source[0]].variable(link.source[1]).type,
            f"{via}: {link.role}",
        )
        for link in links
    ]


def _split(key: str, ref: object, classes: Mapping[str, type[Component]]) -> tuple[str, str]:
    instance, _, name = str(ref).partition(".")
    if not isinstance(ref, str) or instance not in classes or not name:
        raise ExampleSceneError(f"{key}: {ref!r} is not '<instance>.<name>' of a known instance")
    return instance, name
