"""One involute or clock gear mesh (Tepper 1981): point and cycle efficiency against closed form."""

from orchestrator.scenes.family import Needs, Role, SceneFamily

FAMILY = SceneFamily(
    needs=Needs(
        roles=(
            Role(
                "GearMesh",
                signals=(
                    "driver_angle",
                    "efficiency",
                    "regime",
                    "input_work",
                    "output_work",
                    "dissipated_work",
                ),  # fmt: skip
            ),
        )
    ),
    analysis="orchestrator.scenes.gear_mesh.report:analyse",
    plot="orchestrator.scenes.gear_mesh.report:plot",
    reference="orchestrator.scenes.gear_mesh.report:reference",
    drawing="orchestrator.scenes.gear_mesh.drawing:draw",
    design_check="orchestrator.scenes.gear_mesh.report:check",
)
