"""The clock-train S&A: the M739 verge driven through a clock (round-on-flank) gear train.

Lowen & Tepper (1982), ARLCD-TR-82013, with the two-pass clock train kinematics of the US Army
fuze report of about 1980 (Task 2).
"""

from orchestrator.scenes.family import SceneFamily
from orchestrator.scenes.m739 import escapement_needs, escapement_shared

FAMILY = SceneFamily(
    needs=escapement_needs("ClockGearTrain"),
    shared=escapement_shared("ClockGearTrain"),
    analysis="orchestrator.scenes.clock_train.report:analyse",
    plot="orchestrator.scenes.clock_train.report:plot",
    reference="orchestrator.scenes.clock_train.report:reference",
)
