"""Build component FMUs on demand, cached by content hash.

Each FMU stands alone.  Its Python code (the generic slave and the modules of
``components`` its component imports) is packed as a package whose name carries the
build's hash, ``mechcosim_<hash>``, and the wrapper module pythonfmu's runtime imports is
named after the hash too.  So any number of our FMUs, and two builds of one FMU with
different code, run each their own code in one process.  The third-party modules that
code imports are written to ``resources/requirements.txt`` (pythonfmu's deploy command
installs them), and ``documentation/index.html`` tells a user of another tool how to use
the FMU.  ``fmus.description`` completes the model description.  On Linux the FMU's binary
is a small loader (``fmus.host_loader``) that starts Python where the host has none and
forwards to pythonfmu's runtime, so the FMU loads in C and C++ hosts too; it also serves
FMI 2.0 input derivatives where the component takes an input's rate
(``fmus.input_derivatives``).  The archive's entries carry a fixed date: the same sources
and build environment give the same file.
"""

from __future__ import annotations

import hashlib
import re
import shutil
import sys
import tempfile
import uuid
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

import pythonfmu
from pythonfmu.builder import FmuBuilder

from components.base import Component
from fmus.atomic_file import write_whole
from fmus.bytecode import add_bytecode
from fmus.description import complete_description
from fmus.host_loader import LOADER_SOURCE, loader_binary, loader_plan, pack_loader
from fmus.input_derivatives import declare_input_derivatives
from fmus.kernel_build import (
    KERNEL_SOURCES,
    compiled_kernel,
    default_cache_dir,
    kernel_identity,
)
from fmus.registry import FMU_RECORDS, FmuRecord, RecordError

FMUS_DIR = Path(__file__).resolve().parent
PROJECT_DIR = FMUS_DIR.parent
SLAVE_MODULE = FMUS_DIR / "component_slave.py"
#: Code that shapes every FMU: a change to any of it is a new build.
BUILD_CODE = (
    SLAVE_MODULE,
    Path(__file__),
    FMUS_DIR / "registry.py",
    FMUS_DIR / "description.py",
    FMUS_DIR / "documentation.py",
    FMUS_DIR / "ports.py",
    FMUS_DIR / "units.py",
    FMUS_DIR / "host_loader.py",
    FMUS_DIR / "kernel_build.py",
    FMUS_DIR / "input_derivatives.py",
    FMUS_DIR / "bytecode.py",
    LOADER_SOURCE,
)
#: where component code loads a compiled kernel (``components.kernels.load_kernel``)
_LOAD_KERNEL = re.compile(r"""load_kernel\(\s*["'](\w+)["']\s*\)""")
#: the date of every entry of an FMU archive (the earliest a zip file can hold)
ZIP_DATE = (1980, 1, 1, 0, 0, 0)


class BuildError(RuntimeError):
    """An FMU cannot be built (unknown name, unwritable cache, undeclared requirement)."""


def content_hash(record: FmuRecord) -> str:
    """Hash of everything that ends up in the FMU: its code and declarations, the build
    code and pythonfmu (no scene file: the example scenes are named, not read)."""
    h = hashlib.sha256()
    for f in record.modules():
        h.update(f"components/{f.name}".encode())
        h.update(f.read_bytes())
    for f in [record.script, *BUILD_CODE]:
        h.update(str(f.relative_to(PROJECT_DIR)).encode())
        h.update(f.read_bytes())
    h.update(pythonfmu.__version__.encode())
    h.update(loader_plan().identity.encode())  # the compiler and the Python it names
    for kernel in _kernels(record.modules()):  # compiled kernels: source, Cython, compiler
        h.update(kernel_identity(kernel).encode())
    return h.hexdigest()


def build_fmu(name: str, cache_dir: Path | None = None, force: bool = False) -> Path:
    """Return the path of the FMU for component ``name``, building it if not cached."""
    try:
        record = FMU_RECORDS[name]
    except KeyError:
        raise BuildError(f"no FMU named {name!r}; known: {sorted(FMU_RECORDS)}") from None
    cache_dir = Path(cache_dir) if cache_dir else default_cache_dir()
    try:
        cache_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise BuildError(f"cannot use {cache_dir} as the FMU cache: {exc}") from None
    digest = content_hash(record)[:16]
    target = cache_dir / f"{name}-{digest}.fmu"
    if target.exists() and not force:
        return target
    try:
        needs = record.requirements()
    except RecordError as exc:
        raise BuildError(str(exc)) from None
    with tempfile.TemporaryDirectory(prefix="mechcosim_build_") as tmp:
        built = _build(record, digest, needs, Path(tmp))
        try:  # parallel builds of one FMU never see half a file or each other's part
            write_whole(target, built.read_bytes())
        except OSError as exc:
            raise BuildError(f"cannot write {target}: {exc}") from None
    return target


def _kernels(modules: list[Path]) -> list[str]:
    """The compiled kernels an FMU ships: those its code loads (``load_kernel("name")``),
    so that an FMU carries, and its hash depends on, only the kernels it runs."""
    named = set()
    for module in modules:
        named.update(_LOAD_KERNEL.findall(module.read_text(encoding="utf-8")))
    return sorted(named & set(KERNEL_SOURCES))


def package_name(digest: str) -> str:
    """The package an FMU's Python code is packed as: unique to the build."""
    return f"mechcosim_{digest}"


def _build(record: FmuRecord, digest: str, needs: list[str], tmp: Path) -> Path:
    package = package_name(digest)
    modules = record.modules()
    stage = tmp / "stage"
    code = stage / package
    (code / "components").mkdir(parents=True)
    (code / "__init__.py").write_text('"""Python code of one mechcosim FMU build."""\n')
    shutil.copy2(SLAVE_MODULE, code)
    for module in modules:
        shutil.copy2(module, code / "components")
    for kernel in _kernels(modules):  # beside the Python code; without it that code runs
        binary = compiled_kernel(kernel)
        if binary is not None:
            (code / "components" / f"{kernel}.so").write_bytes(binary)
    script = stage / f"{record.script.stem}_{digest}.py"
    script.write_text(
        re.sub(
            r"^from component_slave import",
            f"from {package}.component_slave import",
            record.script.read_text(),
            flags=re.M,
        )
    )
    (stage / "requirements.txt").write_text("".join(f"{line}\n" for line in needs))
    from fmus.documentation import render_documentation  # only a build needs it (0.02 s)

    docs = tmp / "documentation"
    docs.mkdir()
    loader = loader_binary(record.name)
    (docs / "index.html").write_text(render_documentation(record, loader=loader is not None))
    modules_before = set(sys.modules)
    try:
        built = FmuBuilder.build_FMU(
            script,
            dest=tmp / "out",
            project_files=[code, stage / "requirements.txt"],
            documentation_folder=docs,
            canGetAndSetFMUstate=True,
        )
    finally:
        # The builder imports the staged code from a folder that is about to go: forget it.
        for module in set(sys.modules) - modules_before:
            if module.startswith((package, script.stem)):
                del sys.modules[module]
        while str(stage) in sys.path:
            sys.path.remove(str(stage))
    _finish(Path(built), record.component_class, record.name, digest, loader)
    return Path(built)


def _finish(
    fmu: Path, component_class: type[Component], name: str, digest: str, loader: bytes | None
) -> None:
    """Complete the model description, put the loader in, and write the archive anew."""
    from xml.dom.minidom import parseString

    with zipfile.ZipFile(fmu) as z:
        members = {n: z.read(n) for n in z.namelist()}
    root = ET.fromstring(members["modelDescription.xml"])
    # pythonfmu's GUID and date are of the moment: the GUID follows the content instead
    root.set("guid", str(uuid.uuid5(uuid.NAMESPACE_URL, f"mechcosim:{name}:{digest}")))
    root.attrib.pop("generationDateAndTime", None)
    for element in root.iter():  # drop pythonfmu's indentation before printing anew
        element.text = element.text.strip() if element.text else None
        element.tail = None
    complete_description(root, component_class)
    if loader is not None:  # it serves input derivatives (pythonfmu's runtime does not)
        declare_input_derivatives(root, members, component_class)
    xml = parseString(ET.tostring(root, "UTF-8")).toprettyxml(indent="  ", encoding="UTF-8")
    members["modelDescription.xml"] = xml
    if loader is not None:
        pack_loader(members, name, loader)
    add_bytecode(members)
    with zipfile.ZipFile(fmu, "w", zipfile.ZIP_DEFLATED) as z:
        for n in sorted(members):
            info = zipfile.ZipInfo(n, ZIP_DATE)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = (0o755 if n.startswith("binaries/") else 0o644) << 16
            z.writestr(info, members[n])
