"""FMU: Feed-roller shaft with strip inertia and a dry-friction brake."""

from component_slave import ComponentSlave

from components.brake_load import BrakeLoad as _Component


class BrakeLoad(ComponentSlave):
    component_class = _Component
    description = "Feed-roller shaft with strip inertia and a dry-friction brake"
    default_run = (0.0, 0.01, 1.0e-5)
