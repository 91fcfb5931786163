"""The M739 S&A: involute gear train and straight-sided verge runaway escapement (Lowen &
Tepper 1982, *Computer Simulation of Artillery S&A Mechanism*)."""

from orchestrator.scenes.family import SceneFamily, escapement_needs

FAMILY = SceneFamily(
    needs=escapement_needs("GearTrain"),
    analysis="orchestrator.scenes.m739.report:analyse",
    plot="orchestrator.scenes.m739.report:plot",
    reference="orchestrator.scenes.m739.report:reference",
)
