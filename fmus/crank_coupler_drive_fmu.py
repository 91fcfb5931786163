"""FMU: Press-feed crank drive: RSSR linkage with an elastic bent coupler."""

from component_slave import ComponentSlave

from components.rssr_coupler import CrankCouplerDrive as _Component


class CrankCouplerDrive(ComponentSlave):
    component_class = _Component
    description = "Press-feed crank drive: RSSR linkage with an elastic bent coupler"
    default_run = (0.0, 0.01, 1.0e-5)
