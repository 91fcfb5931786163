"""Build component FMUs on demand, cached by content hash.

Every FMU packs the whole ``components`` package and the generic slave, so it runs
wherever Python with numpy and pythonfmu's runtime is present.  pythonfmu writes a model
description without units and with an incomplete ModelStructure; ``_complete_description``
adds the unit definitions, the unit of every Real, and the InitialUnknowns, so that the
FMU passes fmpy's validation with no message.
"""

from __future__ import annotations

import hashlib
import importlib
import os
import shutil
import tempfile
import zipfile
from pathlib import Path
from xml.dom.minidom import parseString
from xml.etree import ElementTree as ET

import pythonfmu
from pythonfmu.builder import FmuBuilder

from components.base import Component, Variable
from fmus.registry import FMU_WRAPPERS, FmuWrapper
from fmus.units import base_unit_exponents

FMUS_DIR = Path(__file__).resolve().parent
PROJECT_DIR = FMUS_DIR.parent
COMPONENTS_DIR = PROJECT_DIR / "components"
SLAVE_MODULE = FMUS_DIR / "component_slave.py"


def default_cache_dir() -> Path:
    """Where built FMUs live: $MECHCOSIM_FMU_CACHE, else the user cache directory."""
    env = os.environ.get("MECHCOSIM_FMU_CACHE")
    if env:
        return Path(env)
    base = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache"))
    return base / "mechcosim" / "fmus"


def content_hash(wrapper: FmuWrapper) -> str:
    """Hash of everything that ends up in the FMU (sources, slave, build code, pythonfmu)."""
    h = hashlib.sha256()
    files = sorted(COMPONENTS_DIR.rglob("*.py")) + [
        wrapper.script,
        SLAVE_MODULE,
        Path(__file__),
        FMUS_DIR / "units.py",
    ]
    for f in files:
        h.update(str(f.relative_to(PROJECT_DIR)).encode())
        h.update(f.read_bytes())
    h.update(pythonfmu.__version__.encode())
    return h.hexdigest()


def build_fmu(name: str, cache_dir: Path | None = None, force: bool = False) -> Path:
    """Return the path of the FMU for component ``name``, building it if not cached."""
    try:
        wrapper = FMU_WRAPPERS[name]
    except KeyError:
        raise KeyError(f"no FMU named {name!r}; known: {sorted(FMU_WRAPPERS)}") from None
    cache_dir = Path(cache_dir) if cache_dir else default_cache_dir()
    cache_dir.mkdir(parents=True, exist_ok=True)
    target = cache_dir / f"{name}-{content_hash(wrapper)[:16]}.fmu"
    if target.exists() and not force:
        return target
    with tempfile.TemporaryDirectory(prefix="mechcosim_build_") as tmp:
        built = FmuBuilder.build_FMU(
            wrapper.script,
            dest=tmp,
            project_files=[COMPONENTS_DIR, SLAVE_MODULE],
            canGetAndSetFMUstate=True,
        )
        component_class = _component_class(wrapper)
        _rewrite_description(Path(built), component_class)
        partial = target.with_suffix(".fmu.part")
        shutil.copyfile(built, partial)
        partial.replace(target)  # atomic: a parallel build never sees half a file
    return target


def build_all(cache_dir: Path | None = None, force: bool = False) -> dict[str, Path]:
    return {name: build_fmu(name, cache_dir, force) for name in FMU_WRAPPERS}


def _component_class(wrapper: FmuWrapper) -> type[Component]:
    module_name, class_name = wrapper.component.rsplit(".", 1)
    return getattr(importlib.import_module(module_name), class_name)


def _rewrite_description(fmu: Path, component_class: type[Component]) -> None:
    with zipfile.ZipFile(fmu) as z:
        members = {n: z.read(n) for n in z.namelist()}
    root = ET.fromstring(members["modelDescription.xml"])
    for element in root.iter():  # drop pythonfmu's indentation before printing anew
        element.text = element.text.strip() if element.text else None
        element.tail = None
    _complete_description(root, component_class)
    xml = parseString(ET.tostring(root, "UTF-8")).toprettyxml(indent="  ", encoding="UTF-8")
    members["modelDescription.xml"] = xml
    with zipfile.ZipFile(fmu, "w", zipfile.ZIP_DEFLATED) as z:
        for n, data in members.items():
            z.writestr(n, data)


def _complete_description(root: ET.Element, component_class: type[Component]) -> None:
    """Add units and InitialUnknowns to a pythonfmu model description, in place."""
    by_name: dict[str, Variable] = {v.name: v for v in component_class.VARIABLES}
    model_vars = root.find("ModelVariables")
    units_used: list[str] = []
    output_indices: list[int] = []
    for index, sv in enumerate(model_vars.findall("ScalarVariable"), start=1):
        var = by_name[sv.get("name")]
        real = sv.find("Real")
        if real is not None and var.unit != "1":
            real.set("unit", var.unit)
            if var.unit not in units_used:
                units_used.append(var.unit)
        if var.causality == "output":
            output_indices.append(index)

    if units_used:
        unit_defs = ET.Element("UnitDefinitions")
        for unit in units_used:
            u = ET.SubElement(unit_defs, "Unit", name=unit)
            exps = {k: str(v) for k, v in base_unit_exponents(unit).items() if v}
            ET.SubElement(u, "BaseUnit", exps)
        # FMI 2.0 order: CoSimulation, UnitDefinitions, TypeDefinitions, LogCategories, ...
        position = list(root).index(root.find("CoSimulation")) + 1
        root.insert(position, unit_defs)

    structure = root.find("ModelStructure")
    for child in list(structure):
        structure.remove(child)
    if output_indices:
        outputs = ET.SubElement(structure, "Outputs")
        initial = ET.SubElement(structure, "InitialUnknowns")
        for i in output_indices:
            ET.SubElement(outputs, "Unknown", index=str(i))
            ET.SubElement(initial, "Unknown", index=str(i))
