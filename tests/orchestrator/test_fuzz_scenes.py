"""Fuzzing the example scenes: a mutated scene (keys dropped, values of the wrong type,
NaN, negative or huge, ``--set`` overrides) ends in a clear one-line error or loads and
runs to finite results; never a traceback, an internal error or a hang.

Most examples are checked the way ``mechcosim check`` checks; a few are run, cut to a few
milliseconds.  The default suite runs a small number of examples; ``-m slow`` many more.
"""

from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path
from typing import Any

import pytest

hypothesis = pytest.importorskip("hypothesis")
from fuzz_inputs import COMMON, WEIRD_TEXT, assert_clear  # noqa: E402
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from orchestrator.cli import main  # noqa: E402

PROJECT_DIR = Path(__file__).resolve().parents[2]
EXAMPLES = sorted((PROJECT_DIR / "scenarios").glob("*.toml"))
RAW = {p.name: tomllib.loads(p.read_text()) for p in EXAMPLES}
# Scenes short enough to run a few milliseconds of in the default suite.
RUNNABLE = ["two_inertias.toml", "press_feed_run1.toml", "m739.toml"]

INT64 = 2**63 - 1
WEIRD = st.one_of(
    st.sampled_from(WEIRD_TEXT),
    st.text(max_size=8),
    st.integers(-INT64, INT64),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0, -1, 1, 10**18, 0.0, -0.0, 1e308, -1e-308, math.nan, math.inf]),
    st.booleans(),
    st.lists(st.sampled_from([1, "a.phi", 2.5, "x"]), max_size=3),
    st.dictionaries(st.sampled_from(["a", "signal", "value"]), st.integers(), max_size=2),
)


def leaves(node: Any, path: tuple = ()) -> list[tuple]:
    """Every key path of the raw scene (tables, values, array items)."""
    out = [path] if path else []
    if isinstance(node, dict):
        for k, v in node.items():
            out += leaves(v, (*path, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            out += leaves(v, (*path, i))
    return out


def mutate(raw: Any, path: tuple, value: Any, drop: bool) -> None:
    node = raw
    for key in path[:-1]:
        node = node[key]
    if drop:
        del node[path[-1]]
    else:
        node[path[-1]] = value


def toml_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, list):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        items = ", ".join(f"{json.dumps(str(k))} = {toml_value(v)}" for k, v in value.items())
        return "{" + items + "}"
    raise TypeError(type(value))


def to_toml(raw: dict[str, Any]) -> str:
    return "\n".join(f"{json.dumps(k)} = {toml_value(v)}" for k, v in raw.items()) + "\n"


@st.composite
def mutated_scene(draw):
    name = draw(st.sampled_from([p.name for p in EXAMPLES]))
    raw = json.loads(json.dumps(RAW[name]))  # a deep copy (scenes hold no NaN)
    for _ in range(draw(st.integers(1, 3))):
        paths = leaves(raw)
        if not paths:
            break
        path = draw(st.sampled_from(paths))
        mutate(raw, path, draw(WEIRD), drop=draw(st.booleans()))
    overrides = []
    if draw(st.booleans()):
        paths = [".".join(map(str, p)) for p in leaves(RAW[name]) if not any(
            isinstance(k, int) for k in p)]  # fmt: skip
        key = draw(st.one_of(st.sampled_from(paths), st.text(min_size=1, max_size=12)))
        text = draw(st.one_of(st.sampled_from(WEIRD_TEXT), st.text(max_size=10)))
        overrides = ["--set", f"{key}={text}"]
    return name, raw, overrides


def exit_code(argv: list[str]) -> int:
    """The command's exit code, as the shell sees it: argparse's refusal of an argument (an
    override whose key starts with '-') exits from within main."""
    try:
        return main(argv)
    except SystemExit as stop:
        return stop.code


def check_example(tmp_path: Path, capsys, example) -> int:
    name, raw, overrides = example
    path = tmp_path / name
    path.write_text(to_toml(raw))
    code = exit_code(["check", str(path), *overrides])
    err = capsys.readouterr().err
    assert_clear(code, err, (0, 2))
    return code


def run_example(tmp_path: Path, capsys, example) -> None:
    name, raw, overrides = example
    path = tmp_path / name
    path.write_text(to_toml(raw))
    out = tmp_path / "out"
    cut = ["--set", "scene.stop=3 ms", "--set", "output.every=1"]
    code = exit_code(["run", str(path), "--no-progress", "--output", str(out), *overrides, *cut])
    err = capsys.readouterr().err
    assert_clear(code, err, (0, 1, 2))
    if code == 2:
        return
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == ("completed" if code == 0 else "failed"), summary["message"]
    if code == 0:  # a completed run has finite headline numbers (null: not finite)
        for q, entry in summary["headline"].items():
            assert entry["value"] is not None, q


@settings(max_examples=25, **COMMON)
@given(example=mutated_scene())
def test_mutated_scenes_check_cleanly(tmp_path: Path, capsys, example) -> None:
    check_example(tmp_path, capsys, example)


@st.composite
def mutated_runnable(draw):
    """FMU parameters and inputs dropped or set to odd numbers: what a short run exercises."""
    name = draw(st.sampled_from(RUNNABLE))
    raw = json.loads(json.dumps(RAW[name]))
    for _ in range(draw(st.integers(1, 2))):
        paths = [p for p in leaves(raw) if p[0] == "fmus" and len(p) == 4]
        if not paths:
            break
        path = draw(st.sampled_from(paths))
        value = draw(
            st.one_of(
                st.sampled_from([0, -1, 1e6, 1e-9, 0.0, 1e30, -1e30, math.nan, "1e3 rpm"]),
                st.floats(-1e12, 1e12),
            )
        )
        mutate(raw, path, value, drop=draw(st.booleans()))
    return name, raw, []


@settings(max_examples=3, **COMMON)
@given(example=mutated_runnable())
def test_mutated_scenes_run_to_a_clear_end(tmp_path: Path, capsys, example) -> None:
    run_example(tmp_path, capsys, example)


@pytest.mark.slow
@settings(max_examples=400, **(COMMON | {"derandomize": False}))
@given(example=mutated_scene())
def test_mutated_scenes_check_cleanly_many(tmp_path: Path, capsys, example) -> None:
    check_example(tmp_path, capsys, example)


@pytest.mark.slow
@settings(max_examples=40, **(COMMON | {"derandomize": False}))
@given(example=mutated_runnable())
def test_mutated_scenes_run_to_a_clear_end_many(tmp_path: Path, capsys, example) -> None:
    run_example(tmp_path, capsys, example)
