"""Coupling roles: declared on the components' variables, carried by the model description
(our vendor annotation), read back by ModelInfo; masters read them, never name suffixes."""

from __future__ import annotations

import ast
import zipfile
from pathlib import Path

import pytest

from components.base import Role, role_problem
from fmus.build import build_fmu
from fmus.host_loader import loader_plan
from fmus.registry import FMU_RECORDS
from orchestrator.model_info import ModelInfoError, model_info

PROJECT_DIR = Path(__file__).resolve().parents[2]
#: The names and suffixes the masters once read the coupling from.
SUFFIXES = ("_rate", "_own", "_mean")
NAMES = ("early_return", "t_reached")


@pytest.mark.parametrize("name", sorted(FMU_RECORDS))
def test_every_declared_role_names_a_variable_of_the_right_causality(name: str) -> None:
    variables = FMU_RECORDS[name].component_class.VARIABLES
    by_name = {v.name: v for v in variables}
    assert [role_problem(v, by_name) for v in variables if v.role] == [
        None for v in variables if v.role
    ]


def test_a_role_on_the_wrong_variable_is_said_in_one_line() -> None:
    verge = FMU_RECORDS["VergeEscapement"].component_class
    by_name = {v.name: v for v in verge.VARIABLES}
    wrong = by_name["phi_own"].__class__(
        "phi_own", "output", "rad", 0.0, role=Role("own_copy_of", "T_esc")
    )
    assert role_problem(wrong, by_name) == (
        "phi_own has the role own_copy_of T_esc, but 'T_esc' is not an input of it"
    )
    rate = by_name["T_esc_mean"].__class__("x", "output", "1", 0.0, role=Role("rate_of", "phi"))
    assert (
        role_problem(rate, by_name)
        == "x has the role rate_of phi but is an output; expected an input"
    )


def test_roles_are_read_from_a_built_fmu() -> None:
    verge = model_info(build_fmu("VergeEscapement"))
    assert verge.annotated
    assert verge.roles == {
        "T_esc_mean": Role("step_mean_of", "T_esc"),
        "T_esc_static_mean": Role("step_mean_of", "T_esc_static"),
        "J_esc_mean": Role("step_mean_of", "J_esc"),
        "T_esc_rate_mean": Role("step_mean_of", "T_esc_rate"),
        "phi_own": Role("own_copy_of", "phi"),
        "phi_dot_own": Role("own_copy_of", "phi_dot"),
        "early_return": Role("early_return"),
        "t_reached": Role("reached_time"),
    }
    assert verge.with_role("own_copy_of", "phi_dot").name == "phi_dot_own"
    assert verge.with_role("rate_of", "T_esc") is None
    brake = model_info(build_fmu("BrakeLoad"))
    assert brake.with_role("rate_of", "torque").name == "torque_rate"
    assert brake.with_role("early_return") is None
    # FMI 2.0's own capabilities, as the description states them
    assert brake.can_handle_variable_step and brake.can_get_set_state
    assert brake.max_output_derivative_order == 0
    # its loader serves input derivatives through torque_rate (test_loader_input_derivatives)
    assert brake.can_interpolate_inputs == loader_plan().packs_loader


def _with_description(source: Path, target: Path, old: str, new: str) -> Path:
    with zipfile.ZipFile(source) as z:
        members = {n: z.read(n) for n in z.namelist()}
    xml = members["modelDescription.xml"].decode()
    assert old in xml
    members["modelDescription.xml"] = xml.replace(old, new).encode()
    with zipfile.ZipFile(target, "w") as z:
        for n, data in members.items():
            z.writestr(n, data)
    return target


def test_an_annotation_role_of_an_unknown_variable_is_refused(tmp_path: Path) -> None:
    fmu = _with_description(
        build_fmu("BrakeLoad"),
        tmp_path / "BrakeLoad.fmu",
        'role="rate_of" of="torque"',
        'role="rate_of" of="torque_typo"',
    )
    with pytest.raises(ModelInfoError) as error:
        model_info(fmu)
    assert str(error.value) == (
        "BrakeLoad: the annotation's role of 'torque_rate', rate_of torque_typo: expected "
        "'torque_typo' to be an input"
    )


def _string_constants(path: Path) -> set[str]:
    """The string constants of a module but the role kinds it asks ``with_role`` for (the
    kinds early_return and reached_time share a variable's name)."""
    tree = ast.parse(path.read_text())
    kinds = {
        id(n.args[0])
        for n in ast.walk(tree)
        if isinstance(n, ast.Call)
        and isinstance(n.func, ast.Attribute)
        and n.func.attr == "with_role"
        and n.args
    }
    return {
        n.value
        for n in ast.walk(tree)
        if isinstance(n, ast.Constant) and isinstance(n.value, str) and id(n) not in kinds
    }


@pytest.mark.parametrize(
    "module",
    sorted(
        str(p.relative_to(PROJECT_DIR))
        for p in [
            *(PROJECT_DIR / "orchestrator" / "masters").glob("*.py"),
            PROJECT_DIR / "orchestrator" / "system.py",
            PROJECT_DIR / "orchestrator" / "execution.py",
        ]
    ),
)
def test_no_master_reads_the_coupling_from_names(module: str) -> None:
    found = _string_constants(PROJECT_DIR / module)
    assert sorted(s for s in found if s in NAMES or s in SUFFIXES) == []
    assert sorted(s for s in found if s.endswith(SUFFIXES) and " " not in s) == []
