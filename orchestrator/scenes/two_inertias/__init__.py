"""Two inertias on a spring-damper: the plumbing scene with a closed-form solution."""

from orchestrator.scenes.family import Needs, SceneFamily

FAMILY = SceneFamily(
    needs=Needs(),
    plot="orchestrator.scenes.two_inertias.report:plot",
    reference="orchestrator.scenes.two_inertias.report:two_inertias_reference",
)
