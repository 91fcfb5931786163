"""Which FMUs exist, read from the wrapper scripts ``fmus/*_fmu.py``: the name a scene uses (the
script's ComponentSlave class), the script, the component inside, and the example scenes that
couple it with other FMUs (listed in its documentation)."""

from __future__ import annotations

import ast
from dataclasses import dataclass
from functools import cached_property
from importlib import import_module
from pathlib import Path

from components.base import Component

_HERE = Path(__file__).resolve().parent


@dataclass(frozen=True)
class FmuWrapper:
    name: str  # model identifier, as a scene names it
    script: Path  # pythonfmu script with exactly one ComponentSlave subclass
    #: Scenes (paths relative to the project root) that couple this FMU with others, from the
    #: script's ``examples``; the FMU's documentation lists their connections.
    examples: tuple[str, ...] = ()

    @cached_property
    def component(self) -> str:
        """Dotted path of the component class, as the wrapper script names it (its
        ``component = "module.Class"`` inside the ``components`` package)."""
        for node in ast.walk(ast.parse(self.script.read_text())):
            if (
                isinstance(node, ast.Assign)
                and [getattr(t, "id", None) for t in node.targets] == ["component"]
                and isinstance(node.value, ast.Constant)
            ):
                return f"components.{node.value.value}"
        raise ValueError(f"{self.script} names no component (component = 'module.Class')")

    def component_class(self) -> type[Component]:
        """The component class itself (imports its module)."""
        module_name, class_name = self.component.rsplit(".", 1)
        return getattr(import_module(module_name), class_name)


def _literal(cls: ast.ClassDef, name: str) -> object:
    for node in cls.body:
        if isinstance(node, ast.Assign) and [getattr(t, "id", None) for t in node.targets] == [
            name
        ]:
            return ast.literal_eval(node.value)
    return None


def _wrappers() -> dict[str, FmuWrapper]:
    """Every ``*_fmu.py`` script here, by the name of its ComponentSlave class."""
    found: dict[str, FmuWrapper] = {}
    for script in sorted(_HERE.glob("*_fmu.py")):
        for node in ast.parse(script.read_text()).body:
            if isinstance(node, ast.ClassDef) and any(
                getattr(b, "id", None) == "ComponentSlave" for b in node.bases
            ):
                examples = _literal(node, "examples") or ()
                found[node.name] = FmuWrapper(node.name, script, tuple(examples))
    return found


#: Model identifier -> wrapper, derived from the wrapper scripts (one class each).
FMU_WRAPPERS: dict[str, FmuWrapper] = _wrappers()
