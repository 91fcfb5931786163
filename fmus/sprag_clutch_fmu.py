"""FMU: Indexing sprag clutch: nonlinear spring-damper engaged only while wound up."""

from component_slave import ComponentSlave


class SpragClutch(ComponentSlave):
    component = "sprag_clutch.SpragClutch"
    examples = (
        "scenarios/press_feed_run1.toml",
    )  # scenes coupling it with other FMUs (documented)
    description = "Indexing sprag clutch: nonlinear spring-damper engaged only while wound up"
    default_run = (0.0, 0.01, 1.0e-5)
