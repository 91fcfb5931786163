"""FMI 2.0 input derivatives of our FMUs: which inputs the loader ramps, written at build time.

A component that takes the rate of a held input over a step has a Real input with the role
``rate_of`` it (``components.base.rate_input``).  pythonfmu's runtime does not serve
fmi2SetRealInputDerivatives, so the FMU's loader (``fmus/loader/python_loader.c``) does:
it reads the value references of each such input and its rate input from
``resources/input_derivatives.txt`` and passes a derivative set by the host on through the
rate input (the loader's comment says how).  An FMU declares ``canInterpolateInputs="true"``
only where that covers every Real input it holds over a step (every one it does not sample
has a rate input), as FMI 2.0 cannot say which inputs an FMU interpolates; and only with the
loader packed.
"""

from __future__ import annotations

from xml.etree import ElementTree as ET

from components.base import Component

#: where the loader reads the table (the loader's RAMPS_FILE)
RAMPS_FILE = "resources/input_derivatives.txt"


def ramped_inputs(component_class: type[Component]) -> list[tuple[str, str]]:
    """(input, its rate input) of every Real input the component holds over a step, where
    each has a rate input; [] where one has none (the FMU then interpolates no input)."""
    inputs = [v for v in component_class.variables("input") if v.type == "Real" and not v.sampled]
    rates = {v.role.of: v.name for v in inputs if v.role is not None and v.role.kind == "rate_of"}
    held = [v.name for v in inputs if v.name not in rates.values()]
    if not rates or any(name not in rates for name in held):
        return []
    return [(name, rates[name]) for name in held]


def ramps_table(pairs: list[tuple[str, str]], value_references: dict[str, int]) -> str:
    """The text of RAMPS_FILE: a line "<input vr> <rate input vr>" per pair."""
    lines = ["# value reference of an input the FMU ramps, then of its input with its rate"]
    lines += [f"{value_references[u]} {value_references[rate]}" for u, rate in pairs]
    return "\n".join(lines) + "\n"


def declare_input_derivatives(
    root: ET.Element, members: dict[str, bytes], component_class: type[Component]
) -> None:
    """Where the component ramps all its held inputs: canInterpolateInputs="true" in the
    model description ``root`` and RAMPS_FILE among the FMU's ``members``."""
    pairs = ramped_inputs(component_class)
    if not pairs:
        return
    root.find("CoSimulation").set("canInterpolateInputs", "true")
    value_references = {
        sv.get("name"): int(sv.get("valueReference"))
        for sv in root.find("ModelVariables").findall("ScalarVariable")
    }
    members[RAMPS_FILE] = ramps_table(pairs, value_references).encode()
