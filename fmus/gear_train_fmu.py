"""FMU: Rotor and two-pass involute gear train of the M739 S&A, driven by spin."""

from component_slave import ComponentSlave

from components.gear_train import GearTrain as _Component


class GearTrain(ComponentSlave):
    component_class = _Component
    description = "Rotor and two-pass involute gear train of the M739 S&A, driven by spin"
    default_run = (0.0, 0.01, 1.0e-5)
