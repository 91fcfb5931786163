"""FMU: Press-feed crank drive: RSSR linkage with an elastic bent coupler."""

from component_slave import ComponentSlave


class CrankCouplerDrive(ComponentSlave):
    component = "crank_coupler_drive.CrankCouplerDrive"
    description = "Press-feed crank drive: RSSR linkage with an elastic bent coupler"
    default_run = (0.0, 0.01, 1.0e-5)
