"""FMU: one gear pair driven at a set speed against a load, with mesh friction losses."""

from component_slave import ComponentSlave

from components.gear_mesh import GearMesh as _Component


class GearMesh(ComponentSlave):
    component_class = _Component
    description = "Gear pair driven at a set speed against a load torque, mesh friction losses"
    default_run = (0.0, 0.1, 1.0e-3)
