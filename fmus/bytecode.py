"""Compiled bytecode of an FMU's Python code, packed beside it.

An FMU is extracted into a new folder each time it is loaded, so Python compiled its code
(some 30 modules, pythonfmu's runtime included) anew on every instantiation: 0.06-0.1 s of a
run of two FMUs, as long as their initialization.  The build packs each module's bytecode in
``__pycache__`` as Python would write it, checked against the source's hash rather than its
date (PEP 552: the archive's dates are fixed), so a Python of the same version loads it and
any other compiles the source as before.  The bytecode is made in a process of its own with
a fixed hash seed: the same sources give the same bytes, as the rest of the archive does.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path, PurePosixPath

_COMPILE = """
import py_compile, sys
for source, target, shown in zip(*[iter(sys.argv[1:])] * 3):
    py_compile.compile(source, cfile=target, dfile=shown, doraise=True,
                       invalidation_mode=py_compile.PycInvalidationMode.CHECKED_HASH)
"""


def add_bytecode(members: dict[str, bytes], under: str = "resources/") -> None:
    """Add ``__pycache__/<module>.<tag>.pyc`` for every ``.py`` member under ``under``."""
    sources = sorted(n for n in members if n.startswith(under) and n.endswith(".py"))
    if not sources:
        return
    tag = sys.implementation.cache_tag
    if tag is None:  # a Python that writes no bytecode
        return
    with tempfile.TemporaryDirectory(prefix="mechcosim_bytecode_") as tmp:
        argv: list[str] = []
        targets: dict[str, Path] = {}
        for k, name in enumerate(sources):
            source = Path(tmp) / f"{k}.py"
            source.write_bytes(members[name])
            path = PurePosixPath(name)
            member = str(path.parent / "__pycache__" / f"{path.stem}.{tag}.pyc")
            targets[member] = Path(tmp) / f"{k}.pyc"
            argv += [str(source), str(targets[member]), name]
        env = {**os.environ, "PYTHONHASHSEED": "0"}  # set and frozenset constants in order
        subprocess.run([sys.executable, "-c", _COMPILE, *argv], env=env, check=True)
        for member, target in targets.items():
            members[member] = target.read_bytes()
