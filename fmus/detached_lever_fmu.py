"""FMU: Balance wheel and hairspring of a detached lever escapement (Monday 1965)."""

from component_slave import ComponentSlave


class DetachedLever(ComponentSlave):
    component = "detached_lever.DetachedLever"
    description = "Balance wheel and hairspring of a detached lever escapement (Monday 1965)"
    # Ten cycles of the worked example (period 0.3886 s), sampled 40 times a cycle.
    default_run = (0.0, 4.0, 1.0e-2)
