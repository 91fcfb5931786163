"""The escape-wheel port between a spin-driven train and its escapement.

The train sends the wheel state and its affine response J_ref phi_dd = T_ref + c_load T_esc;
the escapement sends its moment T_esc, in affine form T_esc = T_esc_static - J_esc phi_dd
when its inertia rides on the wheel, and applies impacts as a new wheel speed.  A master
that steps the escapement first may give the train the escapement moment of that very step
as its mean and its rate (``T_esc_rate``): the train then takes the step's impulse and its
first moment, not a held torque.
"""

from __future__ import annotations

from .base import Role, Variable
from .early_return import EARLY_RETURN_VARIABLES

#: The escape-wheel port of a spin-driven train, and of the verge on the other side: the
#: train sends the wheel state and its affine response, the verge the escapement moment
#: and its affine form (T_esc = T_esc_static - J_esc phi_ddot).
ESCAPE_WHEEL_PORT = {
    "angle": "phi",
    "speed": "phi_dot",
    "torque": "T_esc",
    "inertia": "J_ref",
    "drive": "T_ref",
    "load_factor": "c_load",
    "impact_inertia": "J_stot",
    "static_torque": "T_esc_static",
    "load_inertia": "J_esc",
    "torque_rate": "T_esc_rate",
    "inertia_slope": "J_ref_phi",
    "drive_slope": "T_ref_phi",
    "drive_damping": "T_ref_phi_dot",
    "impact_inertia_slope": "J_stot_phi",
}

#: Direct feedthrough of a train: an impact sets the wheel speed at once, and at rest the
#: held escapement load decides start, direction or stick, so whatever follows the wheel's
#: speed, direction or acceleration depends on these inputs within one instant.
IMPACT_INPUTS = ("impact_count", "phi_dot_impact")
WHEEL_INPUTS = ("T_esc", "T_esc_static", "J_esc", *IMPACT_INPUTS)


def response_slope_outputs(speed_slope_inputs: tuple[str, ...]) -> tuple[Variable, ...]:
    """The response's slopes in the wheel state at the sent point, in the mode in force:
    with them the escapement follows J_ref, T_ref and J_stot along its own copy of the wheel
    over a step (a reduced model of the train), not their values held.  The slopes in the
    angle follow the mode as J_ref does; the one in the speed depends on the inputs
    ``speed_slope_inputs`` (a train whose speed slope vanishes at rest in either direction
    names only the impact inputs)."""
    return (
        Variable(
            "J_ref_phi",
            "output",
            "kg.m2/rad",
            0.0,
            "slope of J_ref in the wheel angle",
            depends_on=WHEEL_INPUTS,
        ),
        Variable(
            "T_ref_phi",
            "output",
            "N.m/rad",
            0.0,
            "slope of T_ref in the wheel angle",
            depends_on=WHEEL_INPUTS,
        ),
        Variable(
            "T_ref_phi_dot",
            "output",
            "N.m.s/rad",
            0.0,
            "slope of T_ref in the wheel speed",
            depends_on=speed_slope_inputs,
        ),
        Variable("J_stot_phi", "output", "kg.m2/rad", 0.0, "slope of J_stot in the wheel angle"),
    )


#: Mesh forces of both trains (involute and clock): they follow the load at once; their
#: peaks over every internal step are state.
MESH_FORCE_VARIABLES = (
    Variable("F12_peak", "output", "N", 0.0, "largest mesh-1 force so far, loaded"),
    Variable("F23_peak", "output", "N", 0.0, "largest mesh-2 force so far, loaded"),
    Variable("FF12_peak", "output", "N", 0.0, "largest mesh-1 force so far, unloaded"),
    Variable("FF23_peak", "output", "N", 0.0, "largest mesh-2 force so far, unloaded"),
    Variable(
        "F12", "output", "N", 0.0, "mesh-1 contact force (any regime)", depends_on=WHEEL_INPUTS
    ),
    Variable(
        "F23", "output", "N", 0.0, "mesh-2 contact force (any regime)", depends_on=WHEEL_INPUTS
    ),
    Variable(
        "FF12",
        "output",
        "N",
        0.0,
        "mesh-1 force when unloaded (T_esc = 0), else 0",
        depends_on=WHEEL_INPUTS,
    ),
    Variable(
        "FF23",
        "output",
        "N",
        0.0,
        "mesh-2 force when unloaded (T_esc = 0), else 0",
        depends_on=WHEEL_INPUTS,
    ),
)

#: The train side of that port.  Impact inputs are events taken once, not signals held
#: over the step.
ESCAPE_WHEEL_VARIABLES = (
    Variable("T_esc", "input", "N.m", 0.0, "escapement moment on the escape wheel"),
    Variable(
        "T_esc_static",
        "input",
        "N.m",
        0.0,
        "escapement moment at zero wheel acceleration (used when J_esc != 0)",
    ),
    Variable(
        "J_esc",
        "input",
        "kg.m2",
        0.0,
        "escapement inertia at the wheel: the load is T_esc_static - J_esc phi_ddot",
    ),
    Variable(
        "T_esc_rate",
        "input",
        "N.m/s",
        0.0,
        "the load's rate over the step, about its mean at the step's middle (0: held)",
        role=Role("rate_of", "T_esc"),
    ),
    Variable(
        "impact_count",
        "input",
        "1",
        0,
        "incremented by the master at an impact",
        "Integer",
        sampled=True,
    ),
    Variable(
        "phi_dot_impact", "input", "rad/s", 0.0, "escape-wheel speed after impact", sampled=True
    ),
    Variable("phi", "output", "rad", 0.0, "cumulative escape-wheel angle"),
    Variable("phi_dot", "output", "rad/s", 0.0, "escape-wheel speed", depends_on=IMPACT_INPUTS),
    Variable(
        "phi_ddot", "output", "rad/s2", 0.0, "escape-wheel acceleration", depends_on=WHEEL_INPUTS
    ),
    Variable(
        "J_ref",
        "output",
        "kg.m2",
        0.0,
        "effective inertia at the escape wheel",
        depends_on=WHEEL_INPUTS,
    ),
    Variable(
        "T_ref",
        "output",
        "N.m",
        0.0,
        "net train torque at the escape wheel",
        depends_on=WHEEL_INPUTS,
    ),
    Variable("c_load", "output", "1", 1.0, "factor of T_esc in J_ref phi_dd = T_ref + c T_esc"),
    Variable("J_stot", "output", "kg.m2", 0.0, "frictionless reflected inertia (impacts, B213)"),
    *EARLY_RETURN_VARIABLES,
)
