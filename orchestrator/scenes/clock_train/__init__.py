"""The clock-train S&A: the M739 verge driven through a clock (round-on-flank) gear train.

Lowen & Tepper (1982), ARLCD-TR-82013, with the two-pass clock train kinematics of the US Army
fuze report of about 1980 (Task 2).
"""

from components.clock_train_design import BODY_NAMES
from components.sanda2v_deck import BY_NAME, SHARED
from orchestrator.scenes.family import SceneFamily, SharedParameter
from orchestrator.scenes.m739 import TURNS, escapement_needs, escapement_shared


def deck_shared() -> tuple[SharedParameter, ...]:
    """The rest of what the clock train and the verge both take from the SANDA2V deck: the
    pivot distances that place the pallet pivot, and the escape-wheel pivot radius."""
    pair = frozenset({"ClockGearTrain", "VergeEscapement"})
    return tuple(
        SharedParameter(n, pair, f"the design's {BY_NAME[n].meaning} [{BY_NAME[n].source}]")
        for n in BODY_NAMES
        if n in SHARED and n not in ("spin", "mu")
    )


FAMILY = SceneFamily(
    needs=escapement_needs("ClockGearTrain"),
    shared=escapement_shared("ClockGearTrain") + deck_shared(),
    design_check="orchestrator.scenes.clock_train.design:check",
    drawing="orchestrator.scenes.clock_train.drawing:draw",
    analysis="orchestrator.scenes.clock_train.report:analyse",
    plot="orchestrator.scenes.clock_train.report:plot",
    reference="orchestrator.scenes.clock_train.report:reference",
    monolithic="orchestrator.scenes.clock_train.report:monolithic_model",
    headline=TURNS,
)
