"""The M739 S&A: involute gear train and straight-sided verge runaway escapement (Lowen &
Tepper 1982, *Computer Simulation of Artillery S&A Mechanism*)."""

from orchestrator.scenes.family import Needs, Option, Role, SceneFamily, SharedParameter

_ESCAPEMENT_FORCES = ("phi", "phi_dot", "regime", "F12", "F23", "FF12", "FF23")
_VERGE = ("regime", "PN", "impact_count")


def escapement_needs(train_component: str) -> Needs:
    """What a spin-driven train + verge escapement family reads: the train's angle, speed,
    regime and mesh forces, the verge's regime, normal force and impact count."""
    return Needs(
        options=(Option("train"), Option("verge")),
        roles=(
            Role(train_component, "train", "train", _ESCAPEMENT_FORCES),
            Role("VergeEscapement", "verge", "verge", _VERGE),
        ),
    )


def escapement_shared(train_component: str) -> tuple[SharedParameter, ...]:
    """What a spin-driven train and its verge escapement share: the spin, and the train's
    friction coefficient, which also acts at the escape-wheel pivot (the verge's ``mu``)."""
    pair = frozenset({train_component, "VergeEscapement"})
    return (
        SharedParameter("spin", pair, "the fuze spin rate"),
        SharedParameter("mu", pair, "the train's friction coefficient (escape-wheel pivot too)"),
    )


FAMILY = SceneFamily(
    needs=escapement_needs("GearTrain"),
    shared=escapement_shared("GearTrain"),
    analysis="orchestrator.scenes.m739.report:analyse",
    plot="orchestrator.scenes.m739.report:plot",
    reference="orchestrator.scenes.m739.report:reference",
)
