"""The project's modules import each other without a cycle, function-level imports
included, and so are imports made at run time: ``importlib.import_module`` and the
"package.module:function" entries a registry resolves.  Each module can be read knowing
only the modules below it."""

from __future__ import annotations

import ast
import re
from pathlib import Path

PROJECT_DIR = Path(__file__).resolve().parents[2]
PACKAGES = ("components", "fmus", "orchestrator")
#: A registry entry naming a callable: "package.module:attribute".
ENTRY = re.compile(r"^([A-Za-z_][\w.]*):[A-Za-z_]\w*$")


def _modules() -> dict[str, Path]:
    found = {}
    for package in PACKAGES:
        for path in (PROJECT_DIR / package).rglob("*.py"):
            parts = path.relative_to(PROJECT_DIR).with_suffix("").parts
            name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
            found[name] = path
    return found


def _imports(name: str, path: Path, modules: dict[str, Path]) -> set[str]:
    """The project modules ``name`` imports anywhere in its body."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    targets: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            targets.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([*parts, base] if base else parts)
            targets.add(base)
            targets.update(f"{base}.{a.name}" for a in node.names)
        elif isinstance(node, ast.Constant) and isinstance(node.value, str):
            if entry := ENTRY.match(node.value):  # resolved by importlib when used
                targets.add(entry.group(1))
        elif isinstance(node, ast.Call) and _calls_import_module(node):
            targets.update(_runtime_targets(node.args[0], name, package, modules))
    return {t for t in targets if t in modules and t != name}


def _calls_import_module(node: ast.Call) -> bool:
    func = node.func
    called = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
    return called == "import_module" and bool(node.args)


def _runtime_targets(arg: ast.expr, name: str, package: str, modules: dict[str, Path]):
    """What ``import_module(arg)`` may import: a constant names one module; a name built
    at run time on ``__name__`` or a package prefix may be any module under that prefix."""
    if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
        return {arg.value}
    prefix = ""
    if isinstance(arg, ast.JoinedStr) and arg.values:
        first = arg.values[0]
        if isinstance(first, ast.FormattedValue) and getattr(first.value, "id", "") == "__name__":
            prefix = f"{name}."
        elif isinstance(first, ast.Constant):
            prefix = str(first.value)
    if not prefix:  # a name from elsewhere (e.g. an entry string, seen where it is written)
        return set()
    return {m for m in modules if m.startswith(prefix)}


def _cycle(graph: dict[str, set[str]]) -> list[str]:
    """One import cycle of ``graph`` ([] when there is none)."""
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    path: list[str] = []

    def visit(module: str) -> list[str]:
        state[module] = 1
        path.append(module)
        for target in sorted(graph[module]):
            if state.get(target) == 1:
                return [*path[path.index(target) :], target]
            if target not in state and (found := visit(target)):
                return found
        path.pop()
        state[module] = 2
        return []

    for module in sorted(graph):
        if module not in state and (found := visit(module)):
            return found
    return []


def test_no_module_imports_itself_through_others() -> None:
    modules = _modules()
    assert "orchestrator.cli" in modules and "fmus.registry" in modules
    graph = {name: _imports(name, path, modules) for name, path in modules.items()}
    assert "orchestrator.scenario" in graph["orchestrator.cli"]  # a function-level import
    # a run-time import (import_module on a built name) and a registry entry string
    assert "orchestrator.scenes.m739" in graph["orchestrator.scenes"]
    assert "orchestrator.scenes.m739.report" in graph["orchestrator.scenes.m739"]
    assert _cycle(graph) == []


def test_run_time_imports_are_seen(tmp_path) -> None:
    source = (
        "from importlib import import_module\n"
        "ENTRY = 'pkg.c:run'\n"
        "def load(n):\n"
        "    return import_module(f'{__name__}.{n}'), import_module('pkg.d')\n"
    )
    (tmp_path / "a.py").write_text(source)
    modules = {"pkg": tmp_path / "a.py", "pkg.b": tmp_path / "b.py", "pkg.c": tmp_path / "c.py"}
    modules["pkg.d"] = tmp_path / "d.py"
    assert _imports("pkg", tmp_path / "a.py", modules) == {"pkg.b", "pkg.c", "pkg.d"}


def test_a_cycle_is_found() -> None:
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert _cycle(graph) == ["a", "b", "c", "a"]


def test_no_test_module_imports_another() -> None:
    """Shared fixtures live in conftest.py, shared texts and functions in modules whose names
    do not start with test_: a test module is read on its own."""
    found = []
    for path in sorted((PROJECT_DIR / "tests").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                names = [node.module or ""]
            tests = [n for n in names if n.rpartition(".")[2].startswith("test_")]
            found += [f"{path.name}: {n}" for n in tests]
    assert found == []
