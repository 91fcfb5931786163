"""FMU: Indexing sprag clutch: nonlinear spring-damper engaged only while wound up."""

from component_slave import ComponentSlave

from components.sprag_clutch import SpragClutch as _Component


class SpragClutch(ComponentSlave):
    component_class = _Component
    description = "Indexing sprag clutch: nonlinear spring-damper engaged only while wound up"
    default_run = (0.0, 0.01, 1.0e-5)
