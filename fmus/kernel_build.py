"""Build the compiled kernels (``components/<name>.pyx``, see ``components.kernels``).

Cython translates a kernel to C and the C compiler of the loader (``fmus.host_loader``)
builds it against this Python's headers.  The flags keep every result the Python code's:
no fast math, no contraction of a multiply and an add into one rounding, and no built-in
libm functions (GCC would fold ``pow(x, 2.0)`` into ``x * x``, which differs from libm's
pow in the last bit about once in 1200 values).  An FMU built here ships the kernel
beside its Python code; the orchestrator's own process builds it once into the FMU cache
(``kernels/``), keyed by the kernel's source and this build environment.  Without Cython or
a compiler the build says so in one line and the Python code runs.
"""

from __future__ import annotations

import hashlib
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from dataclasses import dataclass
from functools import cache
from pathlib import Path

from fmus.atomic_file import write_whole
from fmus.cache_dir import default_cache_dir
from fmus.disk_memo import installed_version
from fmus.host_loader import c_compiler, compiler_version, say_once

COMPONENTS_DIR = Path(__file__).resolve().parent.parent / "components"
#: kernel name -> its Cython source
KERNEL_SOURCES = {
    name: COMPONENTS_DIR / f"{name}.pyx"
    for name in ("m739_kernel", "clock_train_kernel", "press_feed_kernel")
}
FLAGS = (
    "-O2",
    "-fPIC",
    "-shared",
    "-fno-builtin",
    "-fno-fast-math",
    "-ffp-contract=off",
    "-fno-strict-aliasing",
    "-fwrapv",
    "-s",
)


@dataclass(frozen=True)
class KernelPlan:
    """How this environment builds kernels."""

    compiler: str | None  # None: no kernels (why_not says why)
    why_not: str
    identity: str  # what a kernel's bytes depend on besides its source


@cache
def kernel_plan() -> KernelPlan:
    """What this environment can do, worked out once per process."""
    include = Path(sysconfig.get_paths()["include"])
    compiler = c_compiler()
    cython_version = installed_version("Cython") or ""  # found, not imported
    why_not = ""
    if not sys.platform.startswith("linux"):
        why_not = "kernels are built on Linux only"
    elif not cython_version:
        why_not = "no Cython (pip install cython)"
    elif compiler is None:
        why_not = "no C compiler (cc, gcc or $CC) on PATH"
    elif not (include / "Python.h").is_file():
        why_not = f"no Python headers ({include}/Python.h; python3-dev)"
    if why_not:
        return KernelPlan(None, why_not, f"no kernels: {why_not}")
    version = compiler_version(compiler)
    h = hashlib.sha256(" ".join(FLAGS).encode())
    h.update(version.encode())
    h.update(cython_version.encode())
    h.update((include / "patchlevel.h").read_bytes())
    h.update(sysconfig.get_config_var("EXT_SUFFIX").encode())
    h.update(Path(__file__).read_bytes())  # how it is built
    return KernelPlan(compiler, "", f"kernels {h.hexdigest()}")


def kernel_identity(name: str) -> str:
    """Hash of kernel ``name``'s source and build environment (part of the FMU hash)."""
    h = hashlib.sha256(KERNEL_SOURCES[name].read_bytes())
    h.update(kernel_plan().identity.encode())
    return h.hexdigest()


def compiled_kernel(name: str) -> bytes | None:
    """The kernel's shared library: from the FMU cache's ``kernels/``, built there if
    missing (one compilation serves every process that builds FMUs); None (said in one
    line) where it cannot be built."""
    library = kernel_library(name)
    if library is not None:
        return library.read_bytes()
    return _compiled(name, kernel_identity(name))


@cache
def _compiled(name: str, identity: str) -> bytes | None:
    """The kernel compiled in this process, once per identity; None where it cannot be."""
    plan = kernel_plan()
    why_not = plan.why_not
    if plan.compiler is not None:
        try:
            return _compile(name, plan.compiler)
        except RuntimeError as exc:
            why_not = f"compiling it failed ({str(exc).strip().splitlines()[-1]})"
    say_once(f"kernel {name}: {why_not}: the physics runs as Python code (the same results)")
    return None


def _compile(name: str, compiler: str) -> bytes:
    include = sysconfig.get_paths()["include"]
    with tempfile.TemporaryDirectory(prefix="mechcosim_kernel_") as tmp:
        # from a copy under a fixed name: nothing of the paths reaches the library
        shutil.copyfile(KERNEL_SOURCES[name], Path(tmp) / f"{name}.pyx")
        steps = [
            [sys.executable, "-m", "cython", "-3", f"{name}.pyx", "-o", f"{name}.c"],
            [compiler, *FLAGS, f"-I{include}", f"{name}.c", "-o", f"{name}.so"],
        ]
        for command in steps:
            run = subprocess.run(command, cwd=tmp, capture_output=True, text=True, check=False)
            if run.returncode != 0:
                words = (run.stderr or run.stdout).strip() or f"exit {run.returncode}"
                raise RuntimeError(f"{' '.join(command)}: {words}")
            if command[0] == sys.executable:
                _python_messages(Path(tmp) / f"{name}.c")
        return (Path(tmp) / f"{name}.so").read_bytes()


def _python_messages(source: Path) -> None:
    """Cython's division by zero says "float division"; Python's "float division by zero".
    A message can reach a result (a run's failure reason), so the kernel says Python's."""
    text = source.read_text()
    source.write_text(
        text.replace(
            'PyExc_ZeroDivisionError, "float division")',
            'PyExc_ZeroDivisionError, "float division by zero")',
        )
    )


def kernel_library(name: str, cache_dir: Path | None = None) -> Path | None:
    """The kernel's library in the FMU cache (``kernels/<name>-<hash>.so``), built if
    missing; None where it cannot be built."""
    if cache_dir is None:
        cache_dir = default_cache_dir()
    target = Path(cache_dir) / "kernels" / f"{name}-{kernel_identity(name)[:16]}.so"
    if target.is_file():
        return target
    binary = _compiled(name, kernel_identity(name))
    if binary is None:
        return None
    try:
        write_whole(target, binary)  # parallel builders never see half a file
    except OSError as exc:
        say_once(f"kernel {name}: cannot write {target} ({exc}): the physics runs as Python code")
        return None
    return target
