"""``mechcosim bench overhead``'s timed run reaches every layer, counts each call once and
leaves nothing patched behind (orchestrator/studies/layer_costs.py)."""

from __future__ import annotations

import json
from pathlib import Path

from orchestrator.fmu_instance import FmuInstance
from orchestrator.scenario import load_scene
from orchestrator.studies.layer_costs import measure
from orchestrator.system import CoupledSystem

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"


def test_every_layer_is_timed_once_per_call(tmp_path: Path) -> None:
    do_step, initialize = FmuInstance.do_step, CoupledSystem.initialize
    scene = load_scene(SCENARIOS / "two_inertias.toml", {"scene.stop": "2 ms"})
    costs = measure(scene, tmp_path / "run")
    stats = json.loads((tmp_path / "run" / "summary.json").read_text())["stats"]
    # 2 ms of 0.1 ms steps (the scene's), two FMUs: 20 macro steps, 40 doSteps
    assert stats["steps"] == costs.macro_steps == 20
    for layer in ("fmi doStep", "slave do_step", "component step"):
        assert costs.clocks[layer].calls == stats["do_steps"] == 40, layer
    assert costs.clocks["recording"].calls == 4 * 20  # four observers per macro step
    own = sum(seconds for _, _, seconds in costs.layers())
    assert abs(own - costs.run_seconds) <= 1e-9 * costs.run_seconds + 1e-12
    assert FmuInstance.do_step is do_step and CoupledSystem.initialize is initialize
