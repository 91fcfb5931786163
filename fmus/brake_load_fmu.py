"""FMU: Feed-roller shaft with strip inertia and a dry-friction brake."""

from component_slave import ComponentSlave


class BrakeLoad(ComponentSlave):
    component = "brake_load.BrakeLoad"
    examples = (
        "scenarios/press_feed_run1.toml",
    )  # scenes coupling it with other FMUs (documented)
    description = "Feed-roller shaft with strip inertia and a dry-friction brake"
    default_run = (0.0, 0.01, 1.0e-5)
