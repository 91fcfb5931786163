"""FMU: Spin-driven M739 rotor behind a two-pass clock gear train (round-on-round/flank)."""

from component_slave import ComponentSlave


class ClockGearTrain(ComponentSlave):
    component = "clock_gear_train.ClockGearTrain"
    # Scenes coupling it with other FMUs (its documentation lists their connections).
    examples = ("scenarios/clock_train_sa.toml",)
    description = "Spin-driven M739 rotor behind a two-pass clock gear train"
    default_run = (0.0, 0.01, 1.0e-5)
