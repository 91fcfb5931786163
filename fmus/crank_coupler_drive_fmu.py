"""FMU: Press-feed crank drive: RSSR linkage with an elastic bent coupler."""

from component_slave import ComponentSlave


class CrankCouplerDrive(ComponentSlave):
    component = "crank_coupler_drive.CrankCouplerDrive"
    examples = (
        "scenarios/press_feed_run1.toml",
    )  # scenes coupling it with other FMUs (documented)
    description = "Press-feed crank drive: RSSR linkage with an elastic bent coupler"
    default_run = (0.0, 0.01, 1.0e-5)
