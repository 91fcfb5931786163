"""FMU: Spin-driven M739 rotor behind a two-pass clock gear train (round-on-round/flank)."""

from component_slave import ComponentSlave

from components.clock_gear_train import ClockGearTrain as _Component


class ClockGearTrain(ComponentSlave):
    component_class = _Component
    description = "Spin-driven M739 rotor behind a two-pass clock gear train"
    default_run = (0.0, 0.01, 1.0e-5)
