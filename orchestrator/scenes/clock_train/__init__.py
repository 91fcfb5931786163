"""The clock-train S&A: the M739 verge driven through a clock (round-on-flank) gear train.

Lowen & Tepper (1982), ARLCD-TR-82013, with the two-pass clock train kinematics of the US Army
fuze report of about 1980 (Task 2).
"""

from orchestrator.scenes.family import Needs, Option, Role, SceneFamily

_ESCAPEMENT_FORCES = ("phi", "phi_dot", "regime", "F12", "F23", "FF12", "FF23")
_VERGE = ("regime", "PN", "impact_count")

FAMILY = SceneFamily(
    needs=Needs(
        options=(Option("train"), Option("verge")),
        roles=(
            Role("ClockGearTrain", "train", "train", _ESCAPEMENT_FORCES),
            Role("VergeEscapement", "verge", "verge", _VERGE),
        ),
    ),
    analysis="orchestrator.scenes.clock_train.report:analyse",
    plot="orchestrator.scenes.clock_train.report:plot",
    reference="orchestrator.scenes.clock_train.report:reference",
)
