"""Every FMU's documentation/index.html: standalone, complete, and true to the project."""

from __future__ import annotations

import dataclasses
import re
import sys
import tomllib
from functools import cache
from html.parser import HTMLParser
from pathlib import Path

import pytest

from components.base import Component
from fmus.build import content_hash
from fmus.documentation import docstring_html, render_documentation
from fmus.registry import FMU_RECORDS

PROJECT_DIR = Path(__file__).resolve().parents[2]

NAMES = sorted(FMU_RECORDS)
REQUIREMENTS = ["numpy>=1.26", "scipy>=1.11"]  # GearMesh's


def component_class(name: str) -> type[Component]:
    return FMU_RECORDS[name].component_class


_VOID = {"br", "hr", "img", "input", "link", "meta", "wbr", "col", "area", "base", "source"}


class _Page(HTMLParser):
    """Checks that every element is closed in order; collects tables by id as cell texts."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.stack: list[str] = []
        self.tables: dict[str, list[tuple[str, list[str]]]] = {}
        self.hrefs: list[str] = []
        self.lead = ""
        self._table: str | None = None
        self._row: tuple[str, list[str]] | None = None
        self._cell: list[str] | None = None
        self._in_lead = False

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        a = dict(attrs)
        if tag not in _VOID:
            self.stack.append(tag)
        if tag == "a" and a.get("href") is not None:
            self.hrefs.append(a["href"] or "")
        if tag == "table":
            self._table = a.get("id") or f"anonymous-{len(self.tables)}"
            self.tables[self._table] = []
        elif tag == "tr" and self._table is not None:
            self._row = (a.get("class") or "", [])
        elif tag in ("td", "th") and self._row is not None:
            self._cell = []
        elif tag == "p" and a.get("class") == "lead":
            self._in_lead = True

    def handle_endtag(self, tag: str) -> None:
        if tag in _VOID:
            return
        assert self.stack and self.stack[-1] == tag, f"</{tag}> closes {self.stack[-1:]}"
        self.stack.pop()
        if tag in ("td", "th") and self._cell is not None and self._row is not None:
            self._row[1].append("".join(self._cell).strip())
            self._cell = None
        elif tag == "tr" and self._row is not None and self._table is not None:
            if self._row[1] and self._row[0] != "":  # body rows carry a class
                self.tables[self._table].append(self._row)
            self._row = None
        elif tag == "table":
            self._table = None
        elif tag == "p":
            self._in_lead = False

    def handle_data(self, data: str) -> None:
        if self._cell is not None:
            self._cell.append(data)
        if self._in_lead:
            self.lead += data


@cache
def _html(name: str) -> str:
    return render_documentation(FMU_RECORDS[name])


@cache
def _page(name: str) -> _Page:
    page = _Page()
    page.feed(_html(name))
    page.close()
    assert page.stack == [], f"unclosed elements {page.stack}"
    return page


def _rows(name: str, table: str, kind: str) -> list[list[str]]:
    return [cells for cls, cells in _page(name).tables[table] if kind in cls.split()]


@pytest.mark.parametrize("name", NAMES)
def test_page_is_standalone_well_formed_html5(name: str) -> None:
    html = _html(name)
    assert html.startswith('<!DOCTYPE html>\n<html lang="en">')
    assert "<style>" in html and "<script" not in html and "<link" not in html
    assert " src=" not in html
    page = _page(name)  # parses, every element closed in order
    assert all(h.startswith("#") for h in page.hrefs), page.hrefs  # in-page links only
    ids = set(re.findall(r' id="([^"]+)"', html))
    assert {h[1:] for h in page.hrefs} <= ids


@pytest.mark.parametrize("name", NAMES)
def test_names_identifier_and_the_wrapper_description(name: str) -> None:
    script = FMU_RECORDS[name].script.read_text()
    description = re.search(r'^\s+description = "(.*)"$', script, re.M).group(1)
    assert _page(name).lead == description.rstrip(".")
    assert f"<h1>{name}</h1>" in _html(name)


@pytest.mark.parametrize("name", NAMES)
def test_names_every_variable_with_its_table_entries(name: str) -> None:
    cls = component_class(name)
    rows = _rows(name, "variables-table", "variable")
    assert [r[0] for r in rows] == [v.name for v in cls.VARIABLES]
    for var, (vname, causality, _vtype, unit, _start, vmin, vmax, _desc, notes) in zip(
        cls.VARIABLES, rows, strict=True
    ):
        assert (causality, unit) == (var.causality, var.unit), vname
        assert (vmin == "") == (var.min is None) and (vmax == "") == (var.max is None), vname
        if var.causality == "input":
            assert ("sampled: the value is taken as a state" in notes) == var.sampled, vname
        if var.causality == "output":
            assert "direct feedthrough from: " in notes, vname
            for dep in var.depends_on:
                assert dep in notes, vname


@pytest.mark.parametrize("name", NAMES)
def test_lists_every_port_role(name: str) -> None:
    cls = component_class(name)
    for port, roles in cls.PORTS.items():
        rows = _rows(name, f"port-{port}", "role")
        assert [(r[0], r[1]) for r in rows] == list(roles.items())
        for role, variable, direction, *_ in rows:
            assert direction.startswith(cls.variable(variable).causality), role
    if not cls.PORTS:
        assert "no rotational ports" in _html(name)


@pytest.mark.parametrize("name", NAMES)
def test_lists_the_regimes_and_event_outputs(name: str) -> None:
    cls = component_class(name)
    names = getattr(cls, "REGIME_NAMES", {})
    page = _page(name)
    if names:
        rows = _rows(name, "regimes", "regime")
        assert [(int(c), n) for c, n in rows] == sorted(names.items())
    else:
        assert "regimes" not in page.tables
    html = _html(name)
    for var in cls.variables("output"):
        if var.name.startswith("ind_") or var.name == "t_event":
            assert f"<code>{var.name}</code>" in html


@pytest.mark.parametrize("name", [n for n in NAMES if FMU_RECORDS[n].example_paths])
def test_names_each_example_scene_and_none_of_its_values(name: str) -> None:
    html = _html(name)
    for example in FMU_RECORDS[name].example_paths:
        assert f"<li><code>{example}</code></li>" in html, example
    # The scenes' values are not shown: they are no part of the FMU (see the hash test).
    assert "30000 rpm" not in html


def test_host_requirements_and_tool_commands() -> None:
    assert FMU_RECORDS["GearMesh"].requirements() == REQUIREMENTS
    for line in REQUIREMENTS:
        assert line.replace(">", "&gt;") in _html("GearMesh")
    assert FMU_RECORDS["GearTrain"].requirements() == []
    html = _html("GearTrain")
    assert "No packages beyond the standard library" in html
    for text in (
        "MECHCOSIM_PYTHON=/path/to/venv/bin/python",
        "resources/python.txt",
        "no <code>LD_PRELOAD</code>",
        "cosim run-single GearTrain.fmu mu=0.1",
        "with debug logging off too",
        "pythonfmu deploy -f GearTrain.fmu",
        "fmpy info GearTrain.fmu",
        "fmpy simulate GearTrain.fmu --start-values mu 0.1",
        "simulate_fmu(",
        "connect_integer_variables",
        "canGetAndSetFMUstate",
        "fmi2Error",
    ):
        assert text in html, text
    assert "LD_PRELOAD=" not in html


def test_a_build_without_the_loader_says_which_hosts_it_loads_in() -> None:
    html = render_documentation(FMU_RECORDS["GearTrain"], loader=False)
    assert "pythonfmu's runtime alone" in html and "MECHCOSIM_PYTHON" not in html


def test_a_missing_example_scene_is_no_build_error() -> None:
    """An FMU names its example scenes and never reads them: the tests below check them."""
    record = dataclasses.replace(FMU_RECORDS["Inertia"], example_paths=("scenarios/nowhere.toml",))
    assert "scenarios/nowhere.toml" in render_documentation(record)
    assert content_hash(record) == content_hash(FMU_RECORDS["Inertia"])


def test_registry_examples_exist_and_instantiate_their_fmu() -> None:
    for name, record in FMU_RECORDS.items():
        for example in record.example_paths:
            scene = tomllib.loads((PROJECT_DIR / example).read_text())
            assert name in {spec["component"] for spec in scene["fmus"].values()}, example


def test_docstrings_keep_lists_equations_and_literals() -> None:
    html = docstring_html(
        """Title line.

        Text with ``a < b`` and *emphasis*,
        continued here.

            J phi'' = T                      (1)

        * first bullet
          continued
        * second

        0. zero
        1. one
        """
    )
    assert "<p>Title line.</p>" in html
    assert "<p>Text with <code>a &lt; b</code> and <em>emphasis</em>, continued here.</p>" in html
    assert "<pre>J phi&#x27;&#x27; = T                      (1)</pre>" in html
    assert "<ul><li>first bullet continued</li><li>second</li></ul>" in html
    assert '<ol><li value="0">zero</li><li value="1">one</li></ol>' in html


def test_editing_an_example_scene_rebuilds_no_fmu(tmp_path) -> None:
    """An FMU's identity is its code and declarations: a value an example scene sets, an
    instance it renames, a connection it drops, or the file itself gone change neither the
    build hash nor the documentation."""
    scene = tmp_path / "m739.toml"
    text = (PROJECT_DIR / "scenarios/m739.toml").read_text()
    last = text[text.rindex("[[connections]]") : text.index("[master]")]
    edits = [
        ("30000 rpm", "20000 rpm"),
        ("[fmus.train]", "[fmus.rotor_train]"),
        (last, ""),
    ]
    assert all(old in text for old, _ in edits)
    for name in ("GearTrain", "VergeEscapement"):
        # an absolute path stays itself under the project directory
        record = dataclasses.replace(FMU_RECORDS[name], example_paths=(str(scene),))
        scene.write_text(text)
        before = content_hash(record), render_documentation(record)
        for old, new in edits:
            scene.write_text(text.replace(old, new))
            assert (content_hash(record), render_documentation(record)) == before, new
        scene.unlink()
        assert (content_hash(record), render_documentation(record)) == before


def test_the_documentation_says_what_the_linux_binaries_need() -> None:
    from fmus.documentation import _host_section
    from fmus.host_loader import newest_version_needed

    # version-need strings as an ELF's .gnu.version_r holds them: the newest, by number
    data = b"\0GLIBC_2.7\0GLIBC_2.34\0GLIBC_2.14\0GLIBCXX_3.4.9\0GLIBCXX_3.4.30\0"
    assert newest_version_needed([data], b"GLIBC_") == "2.34"
    assert newest_version_needed([data], b"GLIBCXX_") == "3.4.30"
    assert newest_version_needed([b"none"], b"GLIBC_") is None
    html = _host_section(FMU_RECORDS["GearTrain"], loader=True)
    version = f"{sys.version_info.major}.{sys.version_info.minor}"
    assert re.search(r"needs glibc 2\.\d+ or later and a Python " + re.escape(version), html)
    assert re.search(r"needs libstdc\+\+ with GLIBCXX_3\.4\.\d+ and libgcc_s", html)
