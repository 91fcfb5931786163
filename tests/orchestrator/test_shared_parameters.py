"""A parameter several FMUs share (a family declares it) is stated once, in [parameters]."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from orchestrator.errors import ScenarioError
from orchestrator.scenario import load_scene
from orchestrator.scenes import shared_parameters

PROJECT = Path(__file__).resolve().parents[2]
M739 = PROJECT / "scenarios" / "m739.toml"


def test_one_value_reaches_every_fmu_that_takes_it() -> None:
    scene = load_scene(M739)
    spin = 30000.0 * 2.0 * math.pi / 60.0
    for instance in ("train", "verge"):
        assert scene.fmus[instance].parameters["spin"] == pytest.approx(spin, rel=1e-15)
        assert scene.fmus[instance].parameters["mu"] == 0.1
    assert scene.fmus["verge"].parameters["mu1"] == 0.1  # the verge's own
    slower = load_scene(M739, {"parameters.spin": "20000 rpm"})
    assert {slower.fmus[i].parameters["spin"] for i in ("train", "verge")} == {spin * 2 / 3}


def test_the_families_declare_them() -> None:
    shared = shared_parameters(("m739", "clock_train"))
    assert shared["spin"].components == {"GearTrain", "ClockGearTrain", "VergeEscapement"}
    assert shared["mu"].components == {"GearTrain", "ClockGearTrain", "VergeEscapement"}
    assert shared_parameters(("m739",))["spin"].components == {"GearTrain", "VergeEscapement"}
    assert shared_parameters(("press_feed",)) == {}


def test_only_the_scene_families_share_their_parameters(tmp_path: Path) -> None:
    """Without the M739 family, the train and the verge share nothing: each FMU's own
    friction coefficient is its own (with the family, stating it per FMU is refused)."""
    text = M739.read_text()
    own = (
        text[: text.index("[report]")]
        .replace(text[text.index("[parameters]") : text.index("[fmus.train]")], "")
        .replace(
            'component = "GearTrain"\n', 'component = "GearTrain"\nparameters = { mu = 0.2 }\n'
        )
    )
    path = tmp_path / "m739_no_family.toml"
    path.write_text(own)
    scene = load_scene(path)
    assert scene.family is None and scene.fmus["train"].parameters["mu"] == 0.2
    assert "mu" not in scene.fmus["verge"].parameters
    path.write_text(own + '\n[report]\nfamily = "m739"\n')
    with pytest.raises(ScenarioError, match=r"\[fmus\.train\.parameters\.mu\].*state it once"):
        load_scene(path)


def test_a_scene_in_the_old_form_is_refused_with_the_new_key(tmp_path: Path) -> None:
    text = M739.read_text()
    shared = text[text.index("[parameters]") : text.index("[fmus.train]")]
    old = text.replace(shared, "").replace(
        'component = "GearTrain"\n',
        'component = "GearTrain"\nparameters = { mu = 0.1, spin = "30000 rpm" }\n',
    )
    path = tmp_path / "m739.toml"
    path.write_text(old)
    with pytest.raises(ScenarioError, match=r"\[fmus\.train\.parameters\.mu\].*as parameters\.mu"):
        load_scene(path)


def test_a_study_varies_a_shared_parameter_by_its_one_key() -> None:
    scene = load_scene(PROJECT / "scenarios" / "m739_study.toml")
    spin = next(i for i in scene.study.inputs if i.name == "spin")
    assert spin.keys == ("parameters.spin",) and spin.unit == "rad/s"
    # a range outside the FMUs' declared one is refused at load, for each FMU
    with pytest.raises(ScenarioError, match="below parameters.spin's minimum"):
        load_scene(
            PROJECT / "scenarios" / "m739_study.toml",
            {
                "study.inputs": [
                    {
                        "key": "parameters.spin",
                        "low": "-1 rpm",
                        "high": "1 rpm",
                        "distribution": "uniform",
                    }
                ]
            },  # fmt: skip
        )
