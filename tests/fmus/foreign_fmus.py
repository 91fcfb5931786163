"""FMI 2.0 co-simulation FMUs that were not built with pythonfmu, for testing the orchestrator.

Tests import this module as ``import foreign_fmus``: the test folders have no ``__init__.py``,
so pytest puts ``tests/fmus/`` on ``sys.path`` (rootdir-relative "prepend" import mode).

* ``build_torsion_body`` compiles ``tests/fmus/foreign/torsion_body.c`` (a body on a torsional
  spring–damper, integrated with RK4 substeps) with the system C compiler and packs it with
  a model description written here.  Variables have Modelica-style dotted names
  (``body.J``, ``spring.k``, ``flange.phi``, ...) under ``variableNamingConvention=
  "structured"``, and the ``canGetAndSetFMUstate`` flag is chosen at build time.
* ``build_container`` wraps one TorsionBody FMU in FMPy's own container FMU
  (``fmpy.container_fmu``: a precompiled Rust binary plus ``resources/container.json``).
* ``torsion_body_reference`` is a pure-float fixed-step Jacobi co-simulation of the project's
  ``Inertia`` coupled to TorsionBody, with the C model's arithmetic replicated operation by
  operation, so an FMU run agrees with it to round-off.

What FMPy 0.3.32's container FMU can and cannot do (read from ``fmpy/container_fmu`` and
measured against its Linux binary; ``test_foreign_fmus.py`` pins the main points):

* Variable naming: the container's variables are whatever ``ModelVariable`` objects the
  ``Configuration``'s model description lists, under any names, each mapped to a list of
  (component, inner variable) pairs; so it carries the TorsionBody's dotted names, units and
  ModelStructure and can stand where the TorsionBody stands.  Start values go into
  ``container.json`` as strings (the binary rejects numbers there) and are set on the inner
  FMU at instantiation.
* Value references: ``create_container_fmu`` numbers the model variables 0..n-1, but the
  binary takes vr 0 to be the time and vr i to be mapping i-1 (the FMI 3.0 layout), so a
  plain FMI 2.0 container is off by one (reading ``spring.k`` returns ``body.J``).
  ``build_container`` puts an independent ``time`` variable first to line them up.
* FMU state: no.  ``fmi2GetFMUstate``/``SetFMUstate``/``FreeFMUstate`` are one stub that
  logs "Function is not implemented." and returns fmi2Error, whatever the inner FMU
  supports; serialization likewise.  The container declares ``canGetAndSetFMUstate=false``.
* Step sizes: the inner FMUs are always stepped with ``fixedStepSize`` (from
  ``CoSimulation.fixedInternalStepSize`` of the configuration; FMI 2.0 XML cannot carry it).
  ``fmi2DoStep`` takes any communication step that is a whole multiple of it (several
  internal steps) and rejects any other with fmi2Error ("must be an even multiple of
  fixedStepSize").  Round-off is tolerated: at fixedStepSize 1e-3 a step off by up to about
  2e-7 s passes, and is then taken as the exact multiple (the container's time is a
  multiple of fixedStepSize).  Zero, negative, NaN and infinite steps are rejected by the
  container itself.  ``currentCommunicationPoint`` must match the container's own time
  (mismatches of 1e-6 s are rejected, 1e-7 s accepted at fixedStepSize 1e-3), so a master
  cannot skip or repeat time.
* Direct feedthrough works: ``fmi2SetReal`` on the container sets the inner input at once
  and ``fmi2GetReal`` reads the inner output, with no step in between.
* ``create_container_fmu`` needs its scratch folder to exist (it ``rmtree``s it first) and
  packs a stray, truncated ``Container.zip`` into the FMU; ``build_container`` drops it.
"""

from __future__ import annotations

import copy
import math
import platform
import subprocess
import sys
import tempfile
import uuid
import zipfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from xml.dom.minidom import parseString
from xml.etree import ElementTree as ET

import fmpy
import numpy as np
from fmpy import read_model_description
from fmpy.container_fmu import Configuration
from fmpy.container_fmu.cli import create_container_fmu
from fmpy.container_fmu.config import Component
from fmpy.model_description import (
    BaseUnit,
    CoSimulation,
    DefaultExperiment,
    ModelDescription,
    ModelVariable,
    Unit,
    Unknown,
)

from fmus.host_loader import c_compiler  # the same compiler the FMU build uses

FOREIGN_DIR = Path(__file__).resolve().parent / "foreign"
TORSION_BODY_SOURCE = FOREIGN_DIR / "torsion_body.c"
MODEL_IDENTIFIER = "TorsionBody"

# Model variables in ModelVariables order: (name, value reference, type, causality, unit,
# start, description).  The value references match the enum in torsion_body.c.
TORSION_BODY_VARIABLES: tuple[tuple[str, int, str, str, str | None, str | None, str], ...] = (
    ("body.J", 0, "Real", "parameter", "kg.m2", "1e-4", "moment of inertia of the body"),
    ("spring.k", 1, "Real", "parameter", "N.m/rad", "2.0", "torsional stiffness"),
    ("spring.d", 2, "Real", "parameter", "N.m.s/rad", "2e-3", "torsional damping"),
    ("body.phi0", 3, "Real", "parameter", "rad", "0.0", "initial angle of the body"),
    ("body.w0", 4, "Real", "parameter", "rad/s", "0.0", "initial speed of the body"),
    ("n_sub", 10, "Integer", "parameter", None, "10", "RK4 substeps per communication step"),
    ("flange.phi", 5, "Real", "input", "rad", "0.0", "angle of the other body's flange"),
    ("flange.w", 6, "Real", "input", "rad/s", "0.0", "speed of the other body's flange"),
    ("body.phi", 7, "Real", "output", "rad", None, "angle of the body"),
    ("body.w", 8, "Real", "output", "rad/s", None, "speed of the body"),
    ("flange.tau", 9, "Real", "output", "N.m", None, "torque on the other body"),
)
VALUE_REFERENCES: dict[str, int] = {v[0]: v[1] for v in TORSION_BODY_VARIABLES}
# With flags=True (TORSION_BODY_FLAGS): a Boolean and a String output.
FLAG_VARIABLES: tuple[tuple[str, int, str, str, str | None, str | None, str], ...] = (
    ("body.ahead", 0, "Boolean", "output", None, None, "body ahead of the flange"),
    ("body.label", 0, "String", "output", None, None, "name of the model"),
)

# FMI base-unit exponents, written out so this fixture depends on nothing in the project.
UNITS: dict[str, dict[str, int]] = {
    "kg.m2": {"kg": 1, "m": 2},
    "N.m/rad": {"kg": 1, "m": 2, "s": -2, "rad": -1},
    "N.m.s/rad": {"kg": 1, "m": 2, "s": -1, "rad": -1},
    "rad": {"rad": 1},
    "rad/s": {"s": -1, "rad": 1},
    "N.m": {"kg": 1, "m": 2, "s": -2},
}

# Dependencies by name.  Outputs: only inputs count (body.phi/body.w are states, so none).
# Initial unknowns: inputs and exact parameters the initial value is computed from.
OUTPUT_DEPENDENCIES: dict[str, tuple[str, ...]] = {
    "body.phi": (),
    "body.w": (),
    "flange.tau": ("flange.phi", "flange.w"),
}
INITIAL_DEPENDENCIES: dict[str, tuple[str, ...]] = {
    "body.phi": ("body.phi0",),
    "body.w": ("body.w0",),
    "flange.tau": ("spring.k", "spring.d", "body.phi0", "body.w0", "flange.phi", "flange.w"),
}
DEFAULT_EXPERIMENT = {"startTime": "0.0", "stopTime": "0.1", "stepSize": "1e-3"}


class ForeignFmuError(RuntimeError):
    """A foreign test FMU cannot be built here (no compiler, unsupported platform)."""


def fmi2_platform() -> tuple[str, str]:
    """(FMI 2.0 platform folder, shared-library suffix) of the running interpreter."""
    machine = platform.machine().lower()
    is_64bit = sys.maxsize > 2**32
    if sys.platform.startswith("linux") and machine in ("x86_64", "amd64") and is_64bit:
        return "linux64", ".so"
    if sys.platform == "darwin" and is_64bit:
        return "darwin64", ".dylib"
    raise ForeignFmuError(
        f"no FMI 2.0 platform folder for {sys.platform}/{platform.machine()}; "
        "the foreign test FMUs are built on 64-bit Linux (x86_64) and macOS only"
    )


def fmi_headers_dir() -> Path:
    """FMPy's copy of the standard FMI 2.0 headers."""
    return Path(fmpy.__file__).resolve().parent / "c-code"


# Misbehaviours a TorsionBody can be built with (torsion_body.c, TORSION_BODY_FAULT).
FAULTS = (
    "segfault",  # doStep writes through a null pointer (SIGSEGV)
    "abort",  # doStep calls abort() (SIGABRT)
    "exit",  # doStep calls exit(3)
    "get_real",  # fmi2GetReal fails (and logs why, with printf arguments)
    "terminate",  # doStep returns fmi2Discard with fmi2Terminated true
    "get_state",  # fmi2GetFMUstate fails
    "instantiate",  # fmi2Instantiate returns NULL
    "hang",  # doStep never returns
    "stop",  # doStep raises SIGSTOP
    "warning",  # doStep logs a warning and returns fmi2Warning
    "log_warning",  # doStep logs in category logStatusWarning and returns fmi2OK
    "long_error",  # doStep logs 2000 lines, then 100000 characters, and returns fmi2Error
    "by_n_sub",  # n_sub 101, 102, 103: segfault, hang, stop; others: no fault
    "terminate_segfault",  # fmi2Terminate segfaults
    "terminate_after",  # doStep completes its step, then returns fmi2Discard, terminated
)


def build_torsion_body(
    dest: Path,
    can_get_set_state: bool = True,
    phi0_in_degrees: bool = False,
    fault: str | None = None,
    fault_time: float = 0.0,
    flags: bool = False,
    input_derivatives: bool = False,
) -> Path:
    """Compile TorsionBody and pack it as ``dest/TorsionBody[-nostate][-deg][-<fault>].fmu``;
    return its path.

    Every build gets a fresh GUID, compiled into the binary (which refuses to instantiate
    with any other) and written into the model description.  ``phi0_in_degrees``: the
    parameter ``body.phi0`` is declared (and taken) in ``deg``, not SI.  ``fault``: one of
    ``FAULTS``, from the first doStep that starts at ``fault_time`` [s] (doStep faults and
    ``get_real``) or at once (the others).  ``flags``: with a Boolean and a String output
    (``FLAG_VARIABLES``).  ``input_derivatives``: it takes the first derivative of
    ``flange.w`` through fmi2SetRealInputDerivatives (``canInterpolateInputs="true"``).
    """
    if fault is not None and fault not in FAULTS:
        raise ValueError(f"unknown fault {fault!r}; expected one of {FAULTS}")
    name = MODEL_IDENTIFIER + ("" if can_get_set_state else "-nostate")
    name += "-deg" if phi0_in_degrees else ""
    name += "-flags" if flags else ""
    name += "-deriv" if input_derivatives else ""
    defines = [
        *(["-DTORSION_BODY_FMU_STATE"] if can_get_set_state else []),
        *(["-DTORSION_BODY_PHI0_DEG"] if phi0_in_degrees else []),
        *(["-DTORSION_BODY_FLAGS"] if flags else []),
        *(["-DTORSION_BODY_INPUT_DERIVATIVES"] if input_derivatives else []),
        *(
            [
                f"-DTORSION_BODY_FAULT=FAULT_{fault.upper()}",
                f"-DTORSION_BODY_FAULT_TIME={fault_time!r}",
            ]
            if fault
            else []
        ),
    ]
    return _build_c_fmu(
        TORSION_BODY_SOURCE,
        MODEL_IDENTIFIER,
        "TORSION_BODY_GUID",
        defines,
        lambda guid: torsion_body_model_description(
            guid, can_get_set_state, phi0_in_degrees, flags, input_derivatives
        ),
        Path(dest) / (name + (f"-{fault}" if fault else "") + ".fmu"),
        with_source=True,
    )


def _build_c_fmu(
    source: Path,
    identifier: str,
    guid_macro: str,
    defines: list[str],
    model_description: Callable[[str], bytes | str],
    target: Path,
    with_source: bool = False,
) -> Path:
    """Compile one C source into an FMI 2.0 co-simulation binary (its GUID passed as the
    macro ``guid_macro``) and pack it with its modelDescription.xml as ``target``."""
    compiler = c_compiler()
    if compiler is None:
        raise ForeignFmuError("no C compiler (cc, gcc or $CC) on PATH")
    platform_dir, suffix = fmi2_platform()
    target.parent.mkdir(parents=True, exist_ok=True)
    guid = "{" + str(uuid.uuid4()) + "}"
    with tempfile.TemporaryDirectory(prefix=f"{identifier}_") as tmp:
        library = Path(tmp) / (identifier + suffix)
        command = [
            compiler,
            "-std=c99",
            "-O2",
            # no fused multiply-add: the Python references must see the same roundings
            "-ffp-contract=off",
            "-fPIC",
            "-shared",
            "-fvisibility=hidden",
            "-Wall",
            "-Wextra",
            f"-I{fmi_headers_dir()}",
            f'-D{guid_macro}="{guid}"',
            *defines,
            str(source),
            "-o",
            str(library),
            "-lm",
        ]
        result = subprocess.run(command, capture_output=True, text=True)
        if result.returncode != 0:
            raise ForeignFmuError(
                f"compiling {source.name} failed:\n{' '.join(command)}\n"
                f"{result.stdout}{result.stderr}"
            )
        partial = target.with_suffix(".fmu.part")
        with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as z:
            z.writestr("modelDescription.xml", model_description(guid))
            z.write(library, f"binaries/{platform_dir}/{library.name}")
            if with_source:
                z.write(source, f"sources/{source.name}")
        partial.replace(target)
    return target


def torsion_body_model_description(
    guid: str,
    can_get_set_state: bool,
    phi0_in_degrees: bool = False,
    flags: bool = False,
    input_derivatives: bool = False,
) -> bytes:
    """modelDescription.xml of TorsionBody (FMI 2.0, co-simulation)."""
    units = dict(UNITS)
    variables = TORSION_BODY_VARIABLES + (FLAG_VARIABLES if flags else ())
    if phi0_in_degrees:
        units["deg"] = {"rad": 1, "factor": math.pi / 180.0}
        variables = tuple((*v[:4], "deg", *v[5:]) if v[0] == "body.phi0" else v for v in variables)
    root = ET.Element(
        "fmiModelDescription",
        fmiVersion="2.0",
        modelName=MODEL_IDENTIFIER,
        guid=guid,
        description="Body on a torsional spring-damper tied to another body's flange",
        generationTool="hand-written C (tests/fmus/foreign/torsion_body.c)",
        variableNamingConvention="structured",
        numberOfEventIndicators="0",
    )
    ET.SubElement(
        root,
        "CoSimulation",
        modelIdentifier=MODEL_IDENTIFIER,
        canHandleVariableCommunicationStepSize="true",
        canGetAndSetFMUstate="true" if can_get_set_state else "false",
        canInterpolateInputs="true" if input_derivatives else "false",
        canSerializeFMUstate="false",
        providesDirectionalDerivative="false",
    )
    unit_defs = ET.SubElement(root, "UnitDefinitions")
    for name, exponents in units.items():
        unit = ET.SubElement(unit_defs, "Unit", name=name)
        ET.SubElement(unit, "BaseUnit", {k: str(v) for k, v in exponents.items()})
    categories = ET.SubElement(root, "LogCategories")
    ET.SubElement(categories, "Category", name="logStatusError", description="errors")
    ET.SubElement(root, "DefaultExperiment", DEFAULT_EXPERIMENT)

    model_vars = ET.SubElement(root, "ModelVariables")
    index: dict[str, int] = {}
    for i, (name, vr, type_, causality, unit, start, description) in enumerate(variables, start=1):
        index[name] = i
        attrs = {"name": name, "valueReference": str(vr), "description": description}
        attrs["causality"] = causality
        if causality == "parameter":
            attrs["variability"] = "fixed"
        elif type_ == "Real":
            attrs["variability"] = "continuous"
        else:
            attrs["variability"] = "discrete"
        sv = ET.SubElement(model_vars, "ScalarVariable", attrs)
        type_attrs = {}
        if unit is not None:
            type_attrs["unit"] = unit
        if start is not None:
            type_attrs["start"] = start
        ET.SubElement(sv, type_, type_attrs)

    structure = ET.SubElement(root, "ModelStructure")
    more = {"body.ahead": ("flange.phi",), "body.label": ()} if flags else {}
    for element, dependencies in (
        ("Outputs", OUTPUT_DEPENDENCIES | more),
        ("InitialUnknowns", INITIAL_DEPENDENCIES | more),
    ):
        unknowns = ET.SubElement(structure, element)
        for name in sorted(dependencies, key=index.__getitem__):
            deps = " ".join(str(j) for j in sorted(index[d] for d in dependencies[name]))
            ET.SubElement(unknowns, "Unknown", index=str(index[name]), dependencies=deps)
    return parseString(ET.tostring(root, "UTF-8")).toprettyxml(indent="  ", encoding="UTF-8")


def build_container(
    dest: Path,
    inner: Path,
    fixed_step: float = 1e-3,
    names: tuple[str, ...] | None = None,
) -> Path:
    """Wrap the TorsionBody FMU ``inner`` in FMPy's container FMU; return its path.

    The container exposes the inner variables ``names`` (default: all of them) under the
    same dotted names, units, causalities and dependencies, so it can stand where the
    TorsionBody stands.  It steps the inner FMU with ``fixed_step``; communication steps
    must be whole multiples of it.  It cannot get or set its FMU state.
    """
    inner = Path(inner)
    dest = Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    inner_md = read_model_description(inner)
    by_name = {v.name: v for v in inner_md.modelVariables}
    if names is None:
        names = tuple(v.name for v in inner_md.modelVariables)
    unknown = [n for n in names if n not in by_name]
    if unknown:
        raise KeyError(f"{inner.name} has no variables {unknown}")

    component = Component(name="torsion_body", filename=inner, modelDescription=inner_md)
    md = ModelDescription(
        fmiVersion="2.0",
        modelName=f"{inner_md.modelName}Container",
        description=f"FMPy container FMU around {inner.name}",
        generationTool="fmpy.container_fmu",
        variableNamingConvention="structured",
    )
    md.guid = "{" + str(uuid.uuid4()) + "}"
    md.coSimulation = CoSimulation(
        modelIdentifier="container_fmu",
        canHandleVariableCommunicationStepSize=True,
        canGetAndSetFMUstate=False,
        fixedInternalStepSize=fixed_step,
    )
    md.defaultExperiment = DefaultExperiment(
        startTime="0.0", stopTime="0.1", stepSize=str(fixed_step)
    )

    # The container binary numbers its variables from value reference 1 and answers vr 0
    # with the time, as in FMI 3.0, while create_container_fmu numbers modelVariables from
    # 0.  An independent "time" variable first (and outside the mappings) lines them up.
    md.modelVariables.append(
        ModelVariable(
            name="time",
            type="Real",
            causality="independent",
            variability="continuous",
            description="simulation time",
            unit="s",
        )
    )
    # Copies, not the inner objects: create_container_fmu renumbers the container's value
    # references in place, and the mappings must keep the inner ones.
    outer: dict[str, ModelVariable] = {}
    mappings = {}
    for name in names:
        variable = copy.copy(by_name[name])
        variable.valueReference = None
        variable.sourceline = None
        md.modelVariables.append(variable)
        outer[name] = variable
        mappings[variable] = [(component, by_name[name])]
    units_used = {v.unit for v in md.modelVariables if v.unit}
    md.unitDefinitions = [u for u in inner_md.unitDefinitions if u.name in units_used]
    if "s" not in {u.name for u in md.unitDefinitions}:
        md.unitDefinitions.append(Unit(name="s", baseUnit=BaseUnit(s=1)))

    exposed = set(names)
    for target, source in (
        (md.outputs, inner_md.outputs),
        (md.initialUnknowns, inner_md.initialUnknowns),
    ):
        for u in source:
            if u.variable.name not in exposed:
                continue
            deps = None
            if u.dependencies is not None:
                # a dependency that is not exposed is a constant of the container
                deps = [outer[d.name] for d in u.dependencies if d.name in exposed]
            target.append(Unknown(variable=outer[u.variable.name], dependencies=deps))

    config = Configuration(
        parallelDoStep=False,
        modelDescription=md,
        components=[component],
        connections=[],
        variableMappings=mappings,
    )
    target = dest / f"{inner.stem}-container.fmu"
    with tempfile.TemporaryDirectory(prefix="container_fmu_") as tmp:
        unzipped = Path(tmp) / "unzipped"
        unzipped.mkdir()  # create_container_fmu empties it with rmtree, so it must exist
        packed = Path(tmp) / "container.fmu"
        create_container_fmu(config, unzipped, packed)
        # create_container_fmu zips the folder it writes the archive into, so the FMU holds
        # a stray, truncated "Container.zip": copy everything else.
        partial = target.with_suffix(".fmu.part")
        with (
            zipfile.ZipFile(packed) as src,
            zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as z,
        ):
            for info in src.infolist():
                if info.filename != "Container.zip":
                    z.writestr(info, src.read(info))
        partial.replace(target)
    return target


def torsion_body_reference(
    J_a: float,
    phi0_a: float,
    w0_a: float,
    J: float,
    k: float,
    d: float,
    phi0: float,
    w0: float,
    n_sub: int,
    step: float,
    stop: float,
    start: float = 0.0,
) -> dict[str, np.ndarray]:
    """Fixed-step Jacobi co-simulation of ``Inertia`` (A) and TorsionBody, in plain floats.

    Coupling: Inertia ``tau`` <- ``flange.tau``; ``flange.phi`` <- Inertia ``phi``,
    ``flange.w`` <- Inertia ``w``.  In initialization mode the TorsionBody's flange inputs
    are set to A's start angle and speed.  Each macro step first reads every output, then
    sets every input, then steps both FMUs from the same time (so A is driven by the torque
    computed from the flange inputs as they stood at the end of the previous step).

    Returns arrays over the communication points ``t``: ``phi_a``, ``w_a`` (Inertia),
    ``phi``, ``w``, ``tau`` (TorsionBody outputs).
    """
    n = round((stop - start) / step)
    if n < 1 or not math.isclose(n * step, stop - start, rel_tol=1e-9):
        raise ValueError(f"stop - start = {stop - start} is not a whole number of steps {step}")
    if n_sub < 1:
        raise ValueError("n_sub must be at least 1")

    def accel(y: float, v: float) -> float:  # torsion_body.c: relative_acceleration
        return -(d * v + k * y) / J

    def torque(phi_in: float, w_in: float, phi: float, w: float) -> float:
        return -(k * (phi_in - phi) + d * (w_in - w))

    phi_a, w_a = float(phi0_a), float(w0_a)
    phi, w = float(phi0), float(w0)
    phi_in, w_in = phi_a, w_a
    tau = torque(phi_in, w_in, phi, w)
    hs = step / n_sub
    out = {key: np.empty(n + 1) for key in ("t", "phi_a", "w_a", "phi", "w", "tau")}

    def record(i: int) -> None:
        out["t"][i] = start + i * step
        out["phi_a"][i], out["w_a"][i] = phi_a, w_a
        out["phi"][i], out["w"][i], out["tau"][i] = phi, w, tau

    record(0)
    for i in range(n):
        # exchange (Jacobi): all outputs are read before any input is set
        tau_a = tau
        phi_in, w_in = phi_a, w_a
        # Inertia.step: exact parabola for the held torque
        alpha = tau_a / J_a
        dphi = w_a * step + 0.5 * alpha * step * step
        phi_a += dphi
        w_a += alpha * step
        # TorsionBody doStep: RK4 on the relative coordinate, flange at its held speed
        y = phi - phi_in
        v = w - w_in
        for _ in range(n_sub):
            k1y = v
            k1v = accel(y, v)
            k2y = v + 0.5 * hs * k1v
            k2v = accel(y + 0.5 * hs * k1y, v + 0.5 * hs * k1v)
            k3y = v + 0.5 * hs * k2v
            k3v = accel(y + 0.5 * hs * k2y, v + 0.5 * hs * k2v)
            k4y = v + hs * k3v
            k4v = accel(y + hs * k3y, v + hs * k3v)
            y = y + hs / 6.0 * (k1y + 2.0 * k2y + 2.0 * k3y + k4y)
            v = v + hs / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v)
        phi_in = phi_in + w_in * step
        phi = phi_in + y
        w = w_in + v
        tau = torque(phi_in, w_in, phi, w)
        record(i + 1)
    return out


PI_CONTROLLER_SOURCE = FOREIGN_DIR / "pi_controller.c"
# (name, value reference, causality, unit, start, min, max, description); all Real.
PI_CONTROLLER_VARIABLES = (
    ("kp", 0, "parameter", "N.m.s/rad", "2e-3", None, None, "proportional gain"),
    ("ki", 1, "parameter", "N.m/rad", "1e-2", None, None, "integral gain"),
    ("u_s", 2, "input", "rad/s", "0.0", "-100", "100", "set point (0 at initialization)"),
    ("u_m", 3, "input", "rad/s", "0.0", None, None, "measured speed"),
    ("y", 4, "output", "N.m", None, None, None, "drive torque kp*(u_s - u_m) + ki*x"),
    ("x", 5, "output", "rad", None, None, None, "integral of the error u_s - u_m"),
)


def build_pi_controller(
    dest: Path, forgets_integrator: bool = False, after_jump: bool = False
) -> Path:
    """Compile PiController (its initialization fails unless the set point u_s is 0) and
    pack it as ``dest/PiController.fmu``; return its path.  ``forgets_integrator``: its
    fmi2SetFMUstate restores everything but the integral x (``PiController-forgets.fmu``),
    a state restore that does not reproduce a step; with ``after_jump`` only once the set
    point has left its value at the first step (``PiController-forgets-after-jump.fmu``)."""
    suffix = ("-forgets" if forgets_integrator else "") + ("-after-jump" if after_jump else "")
    defines = ["-DPI_CONTROLLER_FORGETS_INTEGRATOR"] if forgets_integrator else []
    defines += ["-DPI_CONTROLLER_FORGETS_AFTER_JUMP"] if after_jump else []
    return _build_c_fmu(
        PI_CONTROLLER_SOURCE,
        "PiController",
        "PI_CONTROLLER_GUID",
        defines,
        _pi_controller_model_description,
        Path(dest) / f"PiController{suffix}.fmu",
    )


def _pi_controller_model_description(guid: str) -> bytes:
    root = ET.Element(
        "fmiModelDescription",
        fmiVersion="2.0",
        modelName="PiController",
        guid=guid,
        description="PI controller whose initial equations need a zero set point",
        generationTool="hand-written C (tests/fmus/foreign/pi_controller.c)",
        numberOfEventIndicators="0",
    )
    ET.SubElement(
        root,
        "CoSimulation",
        modelIdentifier="PiController",
        canHandleVariableCommunicationStepSize="true",
        canGetAndSetFMUstate="true",
    )
    unit_defs = ET.SubElement(root, "UnitDefinitions")
    for name in sorted({v[3] for v in PI_CONTROLLER_VARIABLES}):
        unit = ET.SubElement(unit_defs, "Unit", name=name)
        ET.SubElement(unit, "BaseUnit", {k: str(e) for k, e in UNITS[name].items()})
    ET.SubElement(root, "DefaultExperiment", DEFAULT_EXPERIMENT)
    model_vars = ET.SubElement(root, "ModelVariables")
    for name, vr, causality, unit, start, low, high, description in PI_CONTROLLER_VARIABLES:
        variability = "fixed" if causality == "parameter" else "continuous"
        attrs = {"name": name, "valueReference": str(vr), "causality": causality}
        attrs.update(variability=variability, description=description)
        if causality == "output":
            attrs["initial"] = "calculated"
        sv = ET.SubElement(model_vars, "ScalarVariable", attrs)
        real = {"unit": unit}
        real.update({k: v for k, v in (("start", start), ("min", low), ("max", high)) if v})
        ET.SubElement(sv, "Real", real)
    structure = ET.SubElement(root, "ModelStructure")
    outputs = ET.SubElement(structure, "Outputs")
    ET.SubElement(outputs, "Unknown", index="5", dependencies="3 4")
    ET.SubElement(outputs, "Unknown", index="6", dependencies="")
    initial = ET.SubElement(structure, "InitialUnknowns")
    ET.SubElement(initial, "Unknown", index="5", dependencies="1 2 3 4")
    ET.SubElement(initial, "Unknown", index="6", dependencies="")
    return parseString(ET.tostring(root, "UTF-8")).toprettyxml(indent="  ", encoding="UTF-8")


#: A scene of our Inertia driving the foreign TorsionBody (``{fmu}``: its file) through its
#: flange; its initial angle ``{phi0}`` in rad, for a parameter the FMU declares in degrees.
TORSION_BODY_SCENE = """
[scene]
name = "deg_parameter"
stop = "20 ms"

[fmus.a]
component = "Inertia"
parameters = {{ J = "2e-4 kg*m^2", w0 = "10 rad/s" }}

[fmus.c]
fmu = "{fmu}"
parameters = {{ "body.J" = "1e-4 kg*m^2", "spring.k" = "2 N*m/rad", "body.phi0" = "{phi0} rad" }}

[[connections]]
from = "c.flange.tau"
to = "a.tau"

[[connections]]
from = "a.phi"
to = "c.flange.phi"

[[connections]]
from = "a.w"
to = "c.flange.w"

[master]
algorithm = "jacobi"
step = "1 ms"

[output]
record = ["a.phi", "a.w", "c.body.phi", "c.body.w", "c.flange.tau"]
"""


@dataclass(frozen=True)
class ForeignFmus:
    directory: Path  # all three, under their file names
    torsion_body: Path  # TorsionBody.fmu, with fmi2Get/SetFMUstate
    stateless: Path  # TorsionBody-nostate.fmu, without
    container: Path  # TorsionBody-container.fmu: FMPy's container around the first, 1 ms step


def foreign_scene(fmu: str, algorithm: str = "jacobi", step: str = "1 ms") -> str:
    step_key = "first_step" if algorithm == "regime-aware" else "step"
    return f"""
[scene]
name = "foreign"
stop = "0.2 s"

[fmus.a]
component = "Inertia"
parameters = {{ J = "2e-4 kg*m^2", w0 = "10 rad/s" }}

[fmus.c]
fmu = "{fmu}"
parameters = {{ "body.J" = "1e-4 kg*m^2", "spring.k" = "2 N*m/rad", "spring.d" = 2e-3, n_sub = 10 }}
inputs = {{ "flange.phi" = 0.0, "flange.w" = "10 rad/s" }}

[[connections]]
from = "c.flange.tau"
to = "a.tau"

[[connections]]
from = "a.phi"
to = "c.flange.phi"

[[connections]]
from = "a.w"
to = "c.flange.w"

[master]
algorithm = "{algorithm}"
{step_key} = "{step}"

[output]
record = ["a.phi", "a.w", "c.body.phi", "c.body.w", "c.flange.tau"]
"""


def write_scene(directory: Path, text: str) -> Path:
    path = directory / "scene.toml"
    path.write_text(text)
    return path
