"""FMU: Rotor and two-pass involute gear train of the M739 S&A, driven by spin."""

from component_slave import ComponentSlave


class GearTrain(ComponentSlave):
    component = "gear_train.GearTrain"
    # Scenes coupling it with other FMUs (its documentation lists their connections).
    examples = ("scenarios/m739.toml",)
    description = "Rotor and two-pass involute gear train of the M739 S&A, driven by spin"
    default_run = (0.0, 0.01, 1.0e-5)
