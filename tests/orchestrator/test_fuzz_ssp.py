"""Fuzzing SSP archives: an exported system with its SystemStructure.ssd mutated (component
names, bound values, units, connections, the stop time) ends in a clear one-line error, or
loads as exactly the system the SSD describes: the same components, the same connections,
the same bound values.  Never a traceback, an internal error, or a silently changed system.

The default suite runs a few examples; ``-m slow`` many more.
"""

from __future__ import annotations

import copy
import tempfile
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import pytest

hypothesis = pytest.importorskip("hypothesis")
from fuzz_inputs import COMMON, WEIRD_TEXT, assert_clear  # noqa: E402
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from orchestrator.cli import main  # noqa: E402
from orchestrator.scenario import load_scene  # noqa: E402
from orchestrator.ssp_export import SSC, SSD, SSV, export_ssp  # noqa: E402
from orchestrator.ssp_import import load_ssp  # noqa: E402

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
NAMES = ["a", "b", "c", "", " ", "a b", "../x", "a.b", "1a", "ä", "a/b", "J", "phi"]
UNITS = ["rad", "deg", "rpm", "kg.m2", "N.m", "xyz", "", "1", "rad/s", "m"]
ATTRIBUTES = {"Component": ("name", "source"), "Connection": (
    "startElement", "startConnector", "endElement", "endConnector")}  # fmt: skip

_ARCHIVE: dict[str, bytes] = {}


def exported() -> dict[str, bytes]:
    """The two-inertias system as an SSP archive, its members by name (exported once)."""
    if not _ARCHIVE:
        with tempfile.TemporaryDirectory() as tmp:
            path = export_ssp(load_scene(SCENARIOS / "two_inertias.toml"), Path(tmp) / "t.ssp")
            with zipfile.ZipFile(path) as z:
                _ARCHIVE.update({n: z.read(n) for n in z.namelist()})
    return _ARCHIVE


def _elements(root: ET.Element, tag: str) -> list[ET.Element]:
    ns = SSV if tag in ("Parameter",) else SSC if tag in ("Unit", "BaseUnit") else SSD
    return list(root.iter(f"{{{ns}}}{tag}"))


@st.composite
def mutated_ssd(draw) -> bytes:
    root = ET.fromstring(exported()["SystemStructure.ssd"])
    for _ in range(draw(st.integers(1, 3))):
        kind = draw(
            st.sampled_from(
                ["rename", "drop", "value", "unit", "factor", "connection", "copy", "stop"]
            )
        )
        if kind in ("rename", "drop"):  # a component's or a connection's attribute
            tag = draw(st.sampled_from(sorted(ATTRIBUTES)))
            elements = _elements(root, tag)
            if not elements:
                continue
            element = draw(st.sampled_from(elements))
            attribute = draw(st.sampled_from(ATTRIBUTES[tag]))
            if kind == "drop":
                element.attrib.pop(attribute, None)
            else:
                element.set(attribute, draw(st.one_of(st.sampled_from(NAMES), st.text(max_size=6))))
        elif kind == "value":
            reals = [r for p in _elements(root, "Parameter") for r in p]
            if reals:
                text = draw(st.one_of(st.sampled_from(WEIRD_TEXT), st.floats().map(repr)))
                draw(st.sampled_from(reals)).set("value", text)
        elif kind == "unit":
            reals = [r for p in _elements(root, "Parameter") for r in p]
            if reals:
                draw(st.sampled_from(reals)).set("unit", draw(st.sampled_from(UNITS)))
        elif kind == "factor":
            bases = _elements(root, "BaseUnit")
            if bases:
                key = draw(st.sampled_from(["factor", "offset", "rad", "s", "kg"]))
                value = draw(st.one_of(st.sampled_from(WEIRD_TEXT), st.sampled_from(["0", "2"])))
                draw(st.sampled_from(bases)).set(key, value)
        elif kind == "connection":  # one dropped, or its ends swapped
            connections = root.find(f"{{{SSD}}}System/{{{SSD}}}Connections")
            if connections is not None and len(connections):
                c = draw(st.sampled_from(list(connections)))
                if draw(st.booleans()):
                    connections.remove(c)
                else:
                    a, b = c.get("startElement"), c.get("endElement")
                    c.set("startElement", b or "")
                    c.set("endElement", a or "")
        elif kind == "copy":  # a component or a connection twice
            tag = draw(st.sampled_from(["Component", "Connection"]))
            elements = _elements(root, tag)
            parent = root.find(
                f"{{{SSD}}}System/{{{SSD}}}{'Elements' if tag == 'Component' else 'Connections'}"
            )
            if elements and parent is not None:
                # A copy, not a serialized round trip: a renamed attribute may hold
                # characters XML cannot carry, which the archive's reader must refuse.
                parent.append(copy.deepcopy(draw(st.sampled_from(elements))))
        else:  # the stop time
            experiment = root.find(f"{{{SSD}}}DefaultExperiment")
            if experiment is not None:
                experiment.set("stopTime", draw(st.sampled_from(WEIRD_TEXT)))
    return ET.tostring(root, encoding="utf-8", xml_declaration=True)


def write_archive(path: Path, ssd: bytes) -> Path:
    with zipfile.ZipFile(path, "w") as z:
        for name, data in exported().items():
            z.writestr(name, ssd if name == "SystemStructure.ssd" else data)
    return path


def assert_same_system(path: Path, ssd: bytes) -> None:
    """A system that loads is the one the SSD describes, nothing merged, dropped or moved."""
    scene = load_ssp(path)
    root = ET.fromstring(ssd)
    components = [c.get("name") for c in _elements(root, "Component")]
    assert sorted(components) == sorted(scene.fmus), (components, list(scene.fmus))
    described = sorted(
        (
            (c.get("startElement"), c.get("startConnector")),
            (c.get("endElement"), c.get("endConnector")),
        )
        for c in _elements(root, "Connection")
    )
    loaded = sorted((tuple(c.source), tuple(c.target)) for c in scene.connections)
    assert loaded == described
    for component in _elements(root, "Component"):
        spec = scene.fmus[component.get("name")]
        for parameter in component.iter(f"{{{SSV}}}Parameter"):
            real = parameter.find(f"{{{SSV}}}Real")
            if real is None:
                continue
            var = spec.model.variables[parameter.get("name")]
            if real.get("unit") in (None, var.unit):  # in the FMU's own unit: as written
                bound = {**spec.parameters, **spec.inputs}[parameter.get("name")]
                assert bound == float(real.get("value"))


def check_archive(tmp_path: Path, capsys, ssd: bytes, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))  # the unpacked archives go here
    path = write_archive(tmp_path / "system.ssp", ssd)
    code = main(["check", str(path)])
    err = capsys.readouterr().err
    assert_clear(code, err, (0, 2))
    if code == 0:
        assert_same_system(path, ssd)


@settings(max_examples=25, **COMMON)
@given(ssd=mutated_ssd())
def test_mutated_ssp_archives_check_cleanly(tmp_path: Path, capsys, monkeypatch, ssd) -> None:
    check_archive(tmp_path, capsys, ssd, monkeypatch)


@pytest.mark.slow
@settings(max_examples=300, **(COMMON | {"derandomize": False}))
@given(ssd=mutated_ssd())
def test_mutated_ssp_archives_check_cleanly_many(tmp_path: Path, capsys, monkeypatch, ssd) -> None:
    check_archive(tmp_path, capsys, ssd, monkeypatch)
