"""FMU: one gear pair driven at a set speed against a load, with mesh friction losses."""

from component_slave import ComponentSlave


class GearMesh(ComponentSlave):
    component = "gear_mesh.GearMesh"
    description = "Gear pair driven at a set speed against a load torque, mesh friction losses"
    default_run = (0.0, 0.1, 1.0e-3)
