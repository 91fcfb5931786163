"""FMU of a free rigid body driven by a torque."""

from component_slave import ComponentSlave


class Inertia(ComponentSlave):
    component = "rotational.Inertia"
    # Scenes coupling it with other FMUs (its documentation lists their connections).
    examples = ("scenarios/two_inertias.toml",)
    description = "Rigid body on a frictionless pivot driven by an input torque"
    default_run = (0.0, 1.0, 1.0e-3)
