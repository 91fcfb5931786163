"""FMU: Indexing sprag clutch: nonlinear spring-damper engaged only while wound up."""

from component_slave import ComponentSlave


class SpragClutch(ComponentSlave):
    component = "sprag_clutch.SpragClutch"
    description = "Indexing sprag clutch: nonlinear spring-damper engaged only while wound up"
    default_run = (0.0, 0.01, 1.0e-5)
