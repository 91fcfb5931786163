"""Compiled kernels: the hot paths of the physics compiled from Cython twins of the Python
code (``components/<name>.pyx``), loaded where they were built, the Python code otherwise.

A twin repeats its Python original operation for operation, so either path gives the same
bits.  Inside an FMU the kernel is shipped beside this module (built with the FMU); in the
source tree it is built once into the FMU cache (``fmus.kernel_build``).  Setting
``MECHCOSIM_PURE_PYTHON=1`` runs the Python code everywhere.
"""

from __future__ import annotations

import importlib
import importlib.util
import os
from pathlib import Path
from types import ModuleType

#: the environment variable that forces the Python code
PURE_PYTHON_VARIABLE = "MECHCOSIM_PURE_PYTHON"

_LOADED: dict[str, ModuleType | None] = {}


def pure_python() -> bool:
    """Whether the Python code is asked for (MECHCOSIM_PURE_PYTHON set and not 0)."""
    return os.environ.get(PURE_PYTHON_VARIABLE, "").strip() not in ("", "0")


def path_environment(pure: bool) -> dict[str, str]:
    """This process's environment for a process of one path: the Python code's
    (``MECHCOSIM_PURE_PYTHON=1``) or the compiled kernels' (the variable removed)."""
    env = {k: v for k, v in os.environ.items() if k != PURE_PYTHON_VARIABLE}
    if pure:
        env[PURE_PYTHON_VARIABLE] = "1"
    return env


def load_kernel(name: str) -> ModuleType | None:
    """The compiled kernel ``name``, or None where there is none (or the Python code is
    asked for): the caller then keeps its Python functions."""
    if pure_python():
        return None
    if name in _LOADED:
        return _LOADED[name]
    path: Path | None = Path(__file__).with_name(f"{name}.so")  # shipped inside an FMU
    if not path.is_file():
        path = None
        if __package__ == "components":  # the source tree: built into the FMU cache
            try:
                build = importlib.import_module("fmus.kernel_build")
            except ImportError:
                build = None
            if build is not None:
                path = build.kernel_library(name)
    module = None
    if path is not None:
        spec = importlib.util.spec_from_file_location(f"{__package__}.{name}", path)
        if spec is not None and spec.loader is not None:
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
    _LOADED[name] = module
    return module
