"""The press roll feed (Xu 1993): crank-coupler drive, sprag clutch and strip/brake load."""

from orchestrator.scenes.family import Needs, Option, Role, SceneFamily

FAMILY = SceneFamily(
    needs=Needs(
        options=(Option("startup_cycles", "count"), Option("decay_ratios", "flag")),
        roles=(
            Role("CrankCouplerDrive", signals=("regime",)),
            Role("SpragClutch", signals=("regime", "windup")),
            Role("BrakeLoad", signals=("regime", "feed_length")),
        ),
    ),
    design_check="orchestrator.scenes.press_feed.design:check",
    drawing="orchestrator.scenes.press_feed.drawing:draw",
    analysis="orchestrator.scenes.press_feed.report:analyse",
    plot="orchestrator.scenes.press_feed.report:plot",
    reference="orchestrator.scenes.press_feed.report:reference",
)
