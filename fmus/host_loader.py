"""The loader that makes an FMU's Linux binary load in any FMI host, Python or not.

pythonfmu's runtime does not link libpython, so a host that is not Python cannot load it.
At build time ``fmus/loader/python_loader.c`` is compiled (against this Python's headers,
without linking libpython) and packed as ``binaries/linux64/<model>.so``; pythonfmu's
runtime moves beside it as ``libpythonfmu-export.so``, and ``resources/python.txt`` names
the Python that built the FMU (its executable and shared library).  The loader's comment
says what it does at run time.

Without a C compiler, Python headers or a shared libpython the build says so in one line
on standard error and the FMU keeps pythonfmu's runtime alone: it then loads in hosts that
run Python only.  What the loader's build depends on (its source, the compiler, this
Python) is part of every FMU's content hash, so a change to any of it is a new build.
"""

from __future__ import annotations

import hashlib
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import tempfile
from dataclasses import dataclass
from functools import cache
from pathlib import Path

from fmus.disk_memo import DiskMemo

LOADER_SOURCE = Path(__file__).resolve().parent / "loader" / "python_loader.c"
#: pythonfmu's runtime inside the FMU, beside the loader
RUNTIME_FILE = "libpythonfmu-export.so"
#: names the Python the loader starts where the host has none
PYTHON_FILE = "resources/python.txt"
#: the variable that names another Python executable
PYTHON_VARIABLE = "MECHCOSIM_PYTHON"
PLATFORM = "linux64"
# No -g and a stripped result: the binary holds no path of the build machine, so a build
# from the same sources, compiler and Python is the same file.
FLAGS = (
    "-std=c11",
    "-O2",
    "-fPIC",
    "-shared",
    "-fvisibility=hidden",
    "-Wall",
    "-Wextra",
    "-Wno-format-truncation",  # long paths are cut in messages, on purpose
    "-Wl,-z,defs",  # every symbol resolved at link time: no Python function called directly
    "-s",
)


@dataclass(frozen=True)
class LoaderPlan:
    """How this build environment packs the FMU's Linux binary."""

    compiler: str | None  # path of the C compiler, None: the plain runtime is packed
    why_not: str  # when there is no compiler or no Python to name: why, in one line
    identity: str  # what the loader's bytes depend on (for the content hash)
    python_record: str  # text of resources/python.txt

    @property
    def packs_loader(self) -> bool:
        return self.compiler is not None


def c_compiler() -> str | None:
    """Path of a C compiler ($CC if it resolves, else cc or gcc on PATH), or None."""
    for name in (os.environ.get("CC"), "cc", "gcc"):
        if name:
            found = shutil.which(name)
            if found:
                return found
    return None


#: compiler file and date -> its version line
_COMPILER_VERSIONS = DiskMemo("compiler-versions")


def compiler_version(compiler: str) -> str:
    """The first line of ``compiler --version``, kept in a memo keyed by the compiler's
    file and its date (``fmus.disk_memo``): asking it cost a process 5-10 ms a plan."""
    real = Path(compiler).resolve()
    key = f"{real}\x1f{real.stat().st_mtime_ns}"
    known = _COMPILER_VERSIONS.get(key)
    if isinstance(known, str):
        return known
    version = subprocess.run(
        [compiler, "--version"], capture_output=True, text=True, check=False
    ).stdout.split("\n")[0]
    _COMPILER_VERSIONS.put(key, version)
    return version


def python_library() -> str | None:
    """The shared libpython of the running Python (its executable may link it or not), if
    there is one."""
    libdir = sysconfig.get_config_var("LIBDIR")
    name = sysconfig.get_config_var("INSTSONAME") or sysconfig.get_config_var("LDLIBRARY")
    if not libdir or not name or ".so" not in name:  # a static build names its .a
        return None
    path = Path(libdir) / name
    return str(path) if path.is_file() else None


def python_record() -> str:
    """resources/python.txt: the Python that builds the FMU, as the loader reads it."""
    version = f"{sys.version_info.major}.{sys.version_info.minor}"
    return (
        "# The Python this FMU starts in a host process that has none (a C or C++ tool).\n"
        f"# ${PYTHON_VARIABLE}=/path/to/bin/python (a Python {version}) overrides it.\n"
        f"executable={sys.executable}\n"
        f"library={python_library() or ''}\n"
    )


@cache
def loader_plan() -> LoaderPlan:
    """What this environment can do, worked out once per process."""
    record = python_record()
    source = LOADER_SOURCE.read_bytes()
    include = Path(sysconfig.get_paths()["include"])
    compiler = c_compiler()
    why_not = ""
    if not sys.platform.startswith("linux"):
        why_not = "the loader is built on Linux only"
    elif compiler is None:
        why_not = "no C compiler (cc, gcc or $CC) on PATH"
    elif not (include / "Python.h").is_file():
        why_not = f"no Python headers ({include}/Python.h; python3-dev)"
    elif python_library() is None:
        why_not = f"{sys.executable} has no shared libpython"
    if why_not:
        return LoaderPlan(None, why_not, f"plain runtime: {why_not}", record)
    version = compiler_version(compiler)
    h = hashlib.sha256(source)
    h.update(" ".join(FLAGS).encode())
    h.update(version.encode())
    h.update((include / "patchlevel.h").read_bytes())
    h.update(record.encode())
    return LoaderPlan(compiler, "", f"loader {h.hexdigest()}", record)


_TOLD: set[str] = set()


def say_once(message: str) -> None:
    """One line on standard error, once per process."""
    if message not in _TOLD:
        _TOLD.add(message)
        print(message, file=sys.stderr, flush=True)


@cache
def compiled_loader(compiler: str, identity: str) -> bytes:
    """The loader's binary (the same for every FMU), compiled once per process and identity;
    raise RuntimeError with the compiler's words."""
    include = sysconfig.get_paths()["include"]
    with tempfile.TemporaryDirectory(prefix="mechcosim_loader_") as tmp:
        # compiled from a copy under a fixed name: nothing of the paths reaches the binary
        shutil.copyfile(LOADER_SOURCE, Path(tmp) / "python_loader.c")
        command = [compiler, *FLAGS, f"-I{include}", "python_loader.c", "-o", "loader.so"]
        command += ["-ldl", "-lpthread"]
        run = subprocess.run(command, cwd=tmp, capture_output=True, text=True, check=False)
        if run.returncode != 0:
            raise RuntimeError(f"{' '.join(command)}: {(run.stderr or run.stdout).strip()}")
        return (Path(tmp) / "loader.so").read_bytes()


def loader_binary(name: str) -> bytes | None:
    """The loader's binary for FMU ``name``; None (said in one line) where this environment
    cannot build it, and the FMU keeps pythonfmu's runtime alone."""
    plan = loader_plan()
    why_not = plan.why_not
    if plan.packs_loader:
        try:
            return compiled_loader(plan.compiler, plan.identity)
        except RuntimeError as exc:
            why_not = f"compiling the loader failed ({str(exc).strip().splitlines()[-1]})"
    say_once(
        f"{name}: {why_not}: the FMU's Linux binary is pythonfmu's runtime alone, which "
        "loads in hosts that run Python only"
    )
    return None


def pack_loader(members: dict[str, bytes], model_identifier: str, loader: bytes) -> None:
    """Put ``loader`` in place of pythonfmu's runtime in the FMU's ``members`` (the runtime
    moves beside it), with resources/python.txt."""
    binary = f"binaries/{PLATFORM}/{model_identifier}.so"
    members[f"binaries/{PLATFORM}/{RUNTIME_FILE}"] = members[binary]
    members[binary] = loader
    members[PYTHON_FILE] = loader_plan().python_record.encode()


def runtime_binary() -> bytes | None:
    """pythonfmu's Linux runtime as installed (what every FMU packs), or None."""
    import pythonfmu

    path = Path(pythonfmu.__file__).parent / "resources" / "binaries" / PLATFORM / RUNTIME_FILE
    return path.read_bytes() if path.is_file() else None


def newest_version_needed(binaries: list[bytes], prefix: bytes) -> str | None:
    """The newest symbol version named ``prefix`` + digits (b"GLIBC_", b"GLIBCXX_") the ELF
    ``binaries`` need, e.g. "2.34", from their version-need strings; None where none does."""
    found = {
        tuple(int(x) for x in m.split(b"."))
        for data in binaries
        for m in re.findall(re.escape(prefix) + rb"(\d+(?:\.\d+)+)", data)
    }
    return ".".join(str(x) for x in max(found)) if found else None
