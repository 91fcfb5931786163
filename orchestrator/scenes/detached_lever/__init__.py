"""The detached-lever escapement (Monday 1965): beat amplitude, period and rate against drive."""

from orchestrator.scenes.family import Needs, Option, Role, SceneFamily

FAMILY = SceneFamily(
    needs=Needs(
        options=(
            Option("lever"),
            Option("nominal_period", "quantity", "s"),
            Option("load_step", "quantity", "N.m"),
        ),
        roles=(
            Role(
                "DetachedLever",
                option="lever",
                signals=("theta", "amplitude", "beat_count", "period", "regime"),
            ),
        ),
    ),
    design_check="orchestrator.scenes.detached_lever.design:check",
    drawing="orchestrator.scenes.detached_lever.drawing:draw",
    analysis="orchestrator.scenes.detached_lever.report:analyse",
    plot="orchestrator.scenes.detached_lever.report:plot",
    reference="orchestrator.scenes.detached_lever.report:reference",
)
