"""FMU: Straight-sided verge runaway escapement of the M739 S&A."""

from component_slave import ComponentSlave


class VergeEscapement(ComponentSlave):
    component = "verge_escapement.VergeEscapement"
    examples = (
        "scenarios/m739.toml",
        "scenarios/clock_train_sa.toml",
    )  # scenes coupling it with other FMUs (documented)
    description = "Straight-sided verge runaway escapement of the M739 S&A"
    default_run = (0.0, 0.01, 1.0e-5)
