"""FMU of a free rigid body driven by a torque."""

from component_slave import ComponentSlave

from components.rotational import Inertia as _Component


class Inertia(ComponentSlave):
    component_class = _Component
    description = "Rigid body on a frictionless pivot driven by an input torque"
    default_run = (0.0, 1.0, 1.0e-3)
