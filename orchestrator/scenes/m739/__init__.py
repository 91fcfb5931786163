"""The M739 S&A: involute gear train and straight-sided verge runaway escapement (Lowen &
Tepper 1982, *Computer Simulation of Artillery S&A Mechanism*)."""

from components.sanda2v_deck import DECK, SHARED
from orchestrator.scenes.family import (
    Headline,
    Needs,
    Option,
    Role,
    SceneFamily,
    SharedParameter,
)

#: What an S&A is judged by: the projectile turns until the rotor arms.
TURNS = Headline("turns_to_arm", "turns_error", "turns")

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


def deck_shared() -> tuple[SharedParameter, ...]:
    """The rest of what the M739 train and verge both take: the train geometry that places
    the pallet pivot in the fuze body, and the escape-wheel pivot radius."""
    pair = frozenset({"GearTrain", "VergeEscapement"})
    return tuple(
        SharedParameter(e.name, pair, f"the design's {e.meaning} [{e.source}]")
        for e in DECK
        if e.name in SHARED and e.name not in ("spin", "mu")
    )


FAMILY = SceneFamily(
    needs=escapement_needs("GearTrain"),
    shared=escapement_shared("GearTrain") + deck_shared(),
    design_check="orchestrator.scenes.m739.design:check",
    drawing="orchestrator.scenes.m739.drawing:draw",
    analysis="orchestrator.scenes.m739.report:analyse",
    plot="orchestrator.scenes.m739.report:plot",
    reference="orchestrator.scenes.m739.report:reference",
    monolithic="orchestrator.scenes.m739.report:monolithic_model",
    headline=TURNS,
)
