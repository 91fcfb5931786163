"""Which FMUs exist, one record each, read from the wrapper scripts ``fmus/*_fmu.py``.

A record holds everything the project states about one FMU: the name a scene uses (the
script's ComponentSlave class), the script, the component inside (its class, ports and
variables), the slave's description and default experiment, the modules of
``components`` it packs and the third-party packages they need, and the example scenes
that couple it with other FMUs.  The build, the FMU's documentation and the scene loader
all read these records; nothing else parses a wrapper script or resolves its
``component = "module.Class"`` (the slave inside a built FMU resolves it once more, in
the build's own copy of ``components``).
"""

from __future__ import annotations

import ast
import hashlib
import sys
from collections.abc import Mapping
from dataclasses import dataclass
from functools import cache, cached_property
from importlib import import_module
from pathlib import Path

from components.base import Component, Variable
from fmus.disk_memo import DiskMemo

FMUS_DIR = Path(__file__).resolve().parent
PROJECT_DIR = FMUS_DIR.parent
COMPONENTS_DIR = PROJECT_DIR / "components"
#: Requirement lines for the third-party modules component code may import.
REQUIREMENTS = {"numpy": "numpy>=1.26", "scipy": "scipy>=1.11"}
#: What a wrapper script's slave class states, as literals: name -> (required, meaning).
_SLAVE_KEYS = {
    "component": (True, "'module.Class' in the components package"),
    "description": (True, "one line saying what the FMU models"),
    "default_run": (True, "(start, stop, step) in seconds of the FMU's default experiment"),
    "examples": (False, "scene paths from the project root that couple it with other FMUs"),
}


class RecordError(ValueError):
    """A wrapper script or what it names cannot make a record (a missing key, an unknown
    requirement)."""


@dataclass(frozen=True)
class FmuRecord:
    name: str  # model identifier, as a scene names it
    script: Path  # pythonfmu script with exactly one ComponentSlave subclass
    component: str  # dotted path of the component class, "components.<module>.<Class>"
    description: str
    default_run: tuple[float, float, float]  # (start, stop, step) of `fmpy simulate` alone
    #: Scenes (paths relative to the project root) that couple this FMU with others; the
    #: FMU's documentation names them (never reads them: an FMU depends on no scene file).
    example_paths: tuple[str, ...] = ()

    @cached_property
    def component_class(self) -> type[Component]:
        """The component class itself (imports its module)."""
        module_name, class_name = self.component.rsplit(".", 1)
        return getattr(import_module(module_name), class_name)

    @property
    def ports(self) -> dict[str, dict[str, str]]:
        return self.component_class.PORTS

    @property
    def variables(self) -> tuple[Variable, ...]:
        return self.component_class.VARIABLES

    def modules(self) -> list[Path]:
        """The modules of ``components`` the component imports, itself included."""
        return component_modules(self.component)

    def requirements(self) -> list[str]:
        """Requirement lines for the third-party modules the packed code imports."""
        return requirements(self.modules())


def component_modules(component: str) -> list[Path]:
    """The modules of ``components`` that ``component`` ("components.<module>.<Class>")
    imports, its own included."""
    start = COMPONENTS_DIR / f"{component.split('.')[1]}.py"
    found: list[Path] = [COMPONENTS_DIR / "__init__.py"]
    todo = [start]
    while todo:
        module = todo.pop()
        if module in found:
            continue
        found.append(module)
        stat = module.stat()
        for name in _relative_imports(module, stat.st_mtime_ns, stat.st_size):
            todo.append(COMPONENTS_DIR / f"{name}.py")
    return sorted(found)


@cache
def _relative_imports(module: Path, mtime_ns: int, size: int) -> tuple[str, ...]:
    """The modules ``module`` imports as ``from .name import``.  Kept per file version (its
    modification time and size) in the process, and per content hash between processes
    (``fmus.disk_memo``): parsing every module again cost 0.12 s a scene load, 10 s of an
    80-sample study, and 0.1-0.2 s of each process."""
    source = module.read_bytes()
    key = hashlib.sha256(source).hexdigest()
    known = _IMPORTS_MEMO.get(key)
    if isinstance(known, list) and all(isinstance(n, str) for n in known):
        return tuple(known)
    found = tuple(
        node.module
        for node in ast.walk(ast.parse(source))
        if isinstance(node, ast.ImportFrom) and node.level == 1 and node.module
    )
    _IMPORTS_MEMO.put(key, list(found))
    return found


#: source hash -> its relative imports (the memo's name changes with how they are found)
_IMPORTS_MEMO = DiskMemo("relative-imports-1")


def requirements(modules: list[Path]) -> list[str]:
    """Requirement lines for the third-party modules that ``modules`` import."""
    names: set[str] = set()
    for module in modules:
        for node in ast.walk(ast.parse(module.read_text())):
            if isinstance(node, ast.Import):
                names.update(a.name.split(".")[0] for a in node.names)
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names.add(node.module.split(".")[0])
    third_party = sorted(names - set(sys.stdlib_module_names) - {"__future__"})
    unknown = [n for n in third_party if n not in REQUIREMENTS]
    if unknown:
        raise RecordError(f"components import {unknown}: add them to fmus.registry.REQUIREMENTS")
    return [REQUIREMENTS[n] for n in third_party]


# -- the wrapper scripts, read without importing them -------------------------------------
# Parsed, not imported: a script imports ``component_slave``, which is a top-level module
# only inside a built FMU.
def read_script(script: Path) -> FmuRecord:
    """The record of one wrapper script (its one ComponentSlave subclass)."""
    slaves = [
        node
        for node in ast.parse(script.read_text(), filename=str(script)).body
        if isinstance(node, ast.ClassDef)
        and any(getattr(b, "id", None) == "ComponentSlave" for b in node.bases)
    ]
    if len(slaves) != 1:
        raise RecordError(f"{script}: expected one subclass of ComponentSlave, found {len(slaves)}")
    cls = slaves[0]
    found: dict[str, object] = {}
    for stmt in cls.body:
        if not (isinstance(stmt, ast.Assign) and len(stmt.targets) == 1):
            continue
        key = getattr(stmt.targets[0], "id", None)
        if key in _SLAVE_KEYS:
            try:
                found[key] = ast.literal_eval(stmt.value)
            except ValueError:
                raise RecordError(f"{script}: {cls.name}.{key} is not a literal") from None
    for key, (required, meaning) in _SLAVE_KEYS.items():
        if required and key not in found:
            raise RecordError(f"{script}: {cls.name} states no {key} ({meaning})")
    component, description = found["component"], found["description"]
    run, examples = found["default_run"], found.get("examples", ())
    if not (isinstance(component, str) and component.count(".") == 1):
        raise RecordError(f"{script}: {cls.name}.component: expected 'module.Class'")
    if not (isinstance(description, str) and description.strip()):
        raise RecordError(f"{script}: {cls.name}.description: expected a line of text")
    if not (
        isinstance(run, tuple) and len(run) == 3 and all(isinstance(x, int | float) for x in run)
    ):
        raise RecordError(f"{script}: {cls.name}.default_run: expected (start, stop, step)")
    if not (isinstance(examples, tuple) and all(isinstance(p, str) for p in examples)):
        raise RecordError(f"{script}: {cls.name}.examples: expected a tuple of scene paths")
    start, stop, step = (float(x) for x in run)
    return FmuRecord(
        name=cls.name,
        script=script,
        component=f"components.{component}",
        description=description,
        default_run=(start, stop, step),
        example_paths=examples,
    )


def _records() -> dict[str, FmuRecord]:
    """Every ``*_fmu.py`` script here, by the name of its ComponentSlave class."""
    found: dict[str, FmuRecord] = {}
    for script in sorted(FMUS_DIR.glob("*_fmu.py")):
        record = read_script(script)
        found[record.name] = record
    return found


#: Model identifier -> record, one per wrapper script.
FMU_RECORDS: Mapping[str, FmuRecord] = _records()
