"""The M739 S&A: involute gear train and straight-sided verge runaway escapement (Lowen &
Tepper 1982, *Computer Simulation of Artillery S&A Mechanism*)."""

from orchestrator.scenes.family import Needs, Option, Role, SceneFamily

_ESCAPEMENT_FORCES = ("phi", "phi_dot", "regime", "F12", "F23", "FF12", "FF23")
_VERGE = ("regime", "PN", "impact_count")

FAMILY = SceneFamily(
    needs=Needs(
        options=(Option("train"), Option("verge")),
        roles=(
            Role("GearTrain", "train", "train", _ESCAPEMENT_FORCES),
            Role("VergeEscapement", "verge", "verge", _VERGE),
        ),
    ),
    analysis="orchestrator.scenes.m739.report:analyse",
    plot="orchestrator.scenes.m739.report:plot",
    reference="orchestrator.scenes.m739.report:reference",
)
