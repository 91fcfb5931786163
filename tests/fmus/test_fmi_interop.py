"""FMI both ways: foreign FMUs in our scenes, and our FMUs standing alone in one process.

Foreign FMUs are made here at test time: a C FMU compiled with the system compiler
(skipped where there is none) and FMPy's own container FMU around it.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import foreign_fmus
import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu
from foreign_fmus import foreign_scene, write_scene

import fmus.registry as registry
from fmus.build import build_fmu
from orchestrator.errors import RunError, ScenarioError
from orchestrator.fmu_instance import FmuInstance
from orchestrator.model_info import model_info
from orchestrator.run import run_scene
from orchestrator.scenario import load_scene
from orchestrator.scenes.two_inertias.report import two_inertias_exact

needs_cc = pytest.mark.skipif(foreign_fmus.c_compiler() is None, reason="no C compiler")

# Body A (our Inertia) and the foreign TorsionBody: the two-inertia scene, other tool.
A = {"J_a": 2e-4, "phi0_a": 0.0, "w0_a": 10.0}
B = {"J": 1e-4, "k": 2.0, "d": 2e-3, "phi0": 0.0, "w0": 0.0, "n_sub": 10}


def assert_matches_reference(result, step: float = 1e-3) -> None:
    ref = foreign_fmus.torsion_body_reference(**A, **B, step=step, stop=0.2)
    assert result.status == "completed", result.message
    assert np.array_equal(result.signal("time"), ref["t"])
    for ours, theirs in [
        ("a.phi", "phi_a"),
        ("a.w", "w_a"),
        ("c.body.phi", "phi"),
        ("c.body.w", "w"),
        ("c.flange.tau", "tau"),
    ]:
        scale = np.abs(ref[theirs]).max()
        assert np.abs(result.signal(ours) - ref[theirs]).max() <= 1e-12 * scale, ours


# -- foreign FMUs in scenes ---------------------------------------------------------------
@needs_cc
def test_c_fmu_in_a_scene_matches_the_hand_written_reference(tmp_path, foreign) -> None:
    scene = load_scene(write_scene(tmp_path, foreign_scene(str(foreign.torsion_body))))
    assert scene.fmus["c"].component is None and not scene.fmus["c"].model.annotated
    assert_matches_reference(
        run_scene(scene, output_dir=tmp_path / "run", show_progress=False, plots=False)
    )


@needs_cc
def test_container_fmu_in_a_scene_matches_the_same_reference(tmp_path, foreign) -> None:
    fmu = foreign.directory / "TorsionBody-container.fmu"
    scene = load_scene(write_scene(tmp_path, foreign_scene(str(fmu))))
    assert "FMPy" in scene.fmus["c"].model.generation_tool or scene.fmus["c"].model.variables
    assert_matches_reference(
        run_scene(scene, output_dir=tmp_path / "run", show_progress=False, plots=False)
    )


@needs_cc
def test_dotted_names_work_in_overrides(tmp_path, foreign) -> None:
    path = write_scene(tmp_path, foreign_scene(str(foreign.torsion_body)))
    scene = load_scene(path, {"fmus.c.parameters.spring.k": "3 N*m/rad"})
    assert scene.fmus["c"].parameters["spring.k"] == 3.0
    with pytest.raises(ScenarioError, match=r"fmus\.c\.parameters.*spring\.q"):
        load_scene(path, {"fmus.c.parameters.spring.q": 1.0})


@needs_cc
def test_regime_aware_master_steps_a_black_box_with_rollback(tmp_path, foreign) -> None:
    path = write_scene(tmp_path, foreign_scene(str(foreign.torsion_body), "regime-aware"))
    scene = load_scene(path, {"master.tolerance": 1e-2, "master.first_step": "0.1 ms"})
    r = run_scene(scene, output_dir=tmp_path / "run", show_progress=False, plots=False)
    assert r.status == "completed", r.message
    assert r.stats.rollbacks > 0
    # It cannot know which inputs are sampled states: it says so and holds them.
    (warning,) = r.stats.warnings
    assert "'c' declares no sampled inputs" in warning
    # Against the closed form of the two bodies (averaging the black box's inputs would
    # have missed it by 0.3 at this tolerance; held, the error is 2.5e-5).
    exact = two_inertias_exact(np.array([0.2]), 2e-4, 1e-4, 2.0, 2e-3, 0.0, 10.0, 0.0, 0.0)
    assert r.signal("a.phi")[-1] == pytest.approx(exact["phi_a"][-1], rel=1e-4)


@needs_cc
@pytest.mark.parametrize("fmu", ["TorsionBody-nostate.fmu", "TorsionBody-container.fmu"])
def test_regime_aware_master_says_what_it_gives_up_without_state(tmp_path, foreign, fmu) -> None:
    path = write_scene(tmp_path, foreign_scene(str(foreign.directory / fmu), "regime-aware"))
    r = run_scene(load_scene(path), output_dir=tmp_path / "run", show_progress=False, plots=False)
    (warning,) = r.stats.warnings
    assert "'c' cannot save and restore its state" in warning and "fixed-step Jacobi" in warning
    assert_matches_reference(r)


def fixed_step_only(fmu: Path, target: Path) -> Path:
    """A copy of ``fmu`` whose description says it cannot take steps of varying size."""
    with zipfile.ZipFile(fmu) as z:
        members = {n: z.read(n) for n in z.namelist()}
    xml = members["modelDescription.xml"].decode()
    flag = 'canHandleVariableCommunicationStepSize="true"'
    assert flag in xml
    members["modelDescription.xml"] = xml.replace(flag, flag.replace("true", "false")).encode()
    with zipfile.ZipFile(target, "w") as z:
        for name, data in members.items():
            z.writestr(name, data)
    return target


@needs_cc
def test_foreign_fmu_without_annotation_runs_under_the_plain_masters(tmp_path, foreign) -> None:
    info = model_info(foreign.torsion_body)
    assert not info.annotated and info.roles == {}
    for algorithm in ("jacobi", "gauss-seidel"):
        path = write_scene(tmp_path, foreign_scene(str(foreign.torsion_body), algorithm))
        r = run_scene(load_scene(path), output_dir=tmp_path / algorithm, show_progress=False)
        assert r.status == "completed", r.message
        exact = two_inertias_exact(np.array([0.2]), 2e-4, 1e-4, 2.0, 2e-3, 0.0, 10.0, 0.0, 0.0)
        # first order in the 1 ms step: Jacobi is 0.6 % off the closed form at 0.2 s
        assert r.signal("a.phi")[-1] == pytest.approx(exact["phi_a"][-1], rel=1e-2), algorithm


@needs_cc
def test_an_fmu_without_variable_steps_is_refused_where_a_master_varies_its_step(
    tmp_path, foreign
) -> None:
    fmu = fixed_step_only(foreign.torsion_body, tmp_path / "TorsionBody.fmu")
    # The regime-aware master sizes every step: it falls back to fixed-step Jacobi, on a grid.
    path = write_scene(tmp_path, foreign_scene(str(fmu), "regime-aware"))
    r = run_scene(load_scene(path), output_dir=tmp_path / "aware", show_progress=False)
    (warning,) = r.stats.warnings
    assert warning.startswith(
        "FMU 'c' cannot take communication steps of varying size "
        "(canHandleVariableCommunicationStepSize is false), which the regime-aware master needs"
    )
    assert "fixed-step Jacobi in steps of 0.001 s" in warning
    assert_matches_reference(r)
    # A fixed step of 3 ms does not divide the 0.2 s span: its last step would be shorter.
    path = write_scene(tmp_path, foreign_scene(str(fmu), "jacobi", "3 ms"))
    r = run_scene(load_scene(path), output_dir=tmp_path / "jacobi", show_progress=False)
    assert r.status == "failed"
    assert r.message == (
        "FMU 'c': cannot take communication steps of varying size "
        "(canHandleVariableCommunicationStepSize is false), which the fixed-step master needs "
        "with a step of 0.003 s that does not divide the span 0.2 s"
    )


@needs_cc
def test_foreign_connection_units_are_checked(tmp_path, foreign) -> None:
    text = foreign_scene(str(foreign.torsion_body)).replace(
        'from = "a.phi"\nto = "c.flange.phi"', 'from = "a.w"\nto = "c.flange.phi"'
    )
    text = text.replace('from = "a.w"\nto = "c.flange.w"', 'from = "a.phi"\nto = "c.flange.w"')
    with pytest.raises(ScenarioError, match=r"\[connections\[1\]\] a\.w -> c\.flange\.phi joins"):
        load_scene(write_scene(tmp_path, text))


# -- scene errors found from the model description ----------------------------------------
TWO = Path(__file__).resolve().parents[2] / "scenarios" / "two_inertias.toml"


def test_rad_output_to_torque_input_is_refused() -> None:
    # A rad output driving an N.m input used to run silently.
    text = TWO.read_text() + '\n[[connections]]\nfrom = "b.phi"\nto = "a.tau"\n'
    text = text.replace('ports = ["a.flange", "b.coupling"]', 'from = "a.w"\nto = "b.w_in"')
    path = TWO.parent / "_tmp_units.toml"
    try:
        path.write_text(text)
        with pytest.raises(ScenarioError, match=r"b\.phi -> a\.tau joins 'rad' to 'N\.m'"):
            load_scene(path)
    finally:
        path.unlink()


@pytest.mark.parametrize(
    ("key", "value", "message"),
    [
        ("fmus.a.parameters.J", "-1 kg*m^2", r"outside the valid range \[0"),
        ("fmus.a.parameters.w0", "nan", "finite"),
        ("fmus.a.fmu", "nowhere.fmu", "expected exactly one of 'component'"),
    ],
)
def test_bad_fmu_values_are_named(key, value, message) -> None:
    with pytest.raises(ScenarioError, match=message) as info:
        load_scene(TWO, {key: value})
    assert key.rsplit(".", 1)[0] in str(info.value) or key in str(info.value)


# -- our FMUs stand alone ------------------------------------------------------------------
def test_our_fmus_run_one_after_the_other_in_one_process() -> None:
    # This process has imported the project's own components package: each FMU must still
    # run the code packed in it (before, the second FMU failed to instantiate).
    for name in ("GearTrain", "VergeEscapement", "Inertia"):
        result = simulate_fmu(str(build_fmu(name)), stop_time=1e-3, output_interval=1e-4)
        assert len(result) == 11 and np.all(np.isfinite(result[result.dtype.names[1]]))


def test_two_builds_of_one_fmu_run_each_their_own_code(tmp_path, monkeypatch) -> None:
    plain = build_fmu("Inertia", tmp_path / "cache")
    changed = tmp_path / "components"
    shutil.copytree(registry.COMPONENTS_DIR, changed)
    source = (changed / "rotational.py").read_text()
    assert "alpha = self.tau / self.J" in source
    (changed / "rotational.py").write_text(
        source.replace("alpha = self.tau / self.J", "alpha = 2.0 * self.tau / self.J")
    )
    monkeypatch.setattr(registry, "COMPONENTS_DIR", changed)
    doubled = build_fmu("Inertia", tmp_path / "cache")
    assert doubled != plain
    instances = [FmuInstance(f"i{k}", path) for k, path in enumerate((plain, doubled))]
    try:
        for inst in instances:  # both alive at once, in one process
            inst.initialize(0.0, 1.0, {"J": 1.0})
            inst.set_real(inst.refs(["tau"]), [1.0])
        for inst in instances:
            inst.do_step(0.0, 1.0)
        speeds = [inst.get("w") for inst in instances]
    finally:
        for inst in instances:
            inst.close()
    assert speeds == [1.0, 2.0]


def test_each_fmu_carries_its_requirements_and_documentation() -> None:
    for name, needs in [("Inertia", []), ("GearMesh", ["numpy", "scipy"])]:
        with zipfile.ZipFile(build_fmu(name)) as z:
            lines = z.read("resources/requirements.txt").decode().split()
            assert [line.split(">")[0] for line in lines] == needs
            assert name in z.read("documentation/index.html").decode()
            modules = [n for n in z.namelist() if n.endswith(".py") and "/components/" in n]
        # Only the modules the component needs are packed, under a name unique to the build.
        assert all(f"mechcosim_{build_fmu(name).stem.split('-')[1]}/" in m for m in modules)


def test_missing_module_is_reported_in_the_log_at_normal_logging() -> None:
    # GearMesh needs scipy: a Python without it must say so, not just fail to instantiate.
    code = (
        "import sys; sys.modules['scipy'] = None\n"
        "from fmpy import simulate_fmu\n"
        f"simulate_fmu({str(build_fmu('GearMesh'))!r})\n"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert run.returncode != 0
    assert "GearMesh cannot load its Python code" in run.stdout + run.stderr
    assert "scipy" in run.stdout + run.stderr


def test_model_structure_lists_direct_dependencies() -> None:
    md = read_model_description(str(build_fmu("SpringDamperInertia")))
    deps = {u.variable.name: sorted(d.name for d in u.dependencies) for u in md.outputs}
    assert deps["tau"] == ["phi_in", "w_in"]
    assert deps["phi"] == [] and deps["w"] == []
    info = model_info(build_fmu("Inertia"))
    assert all(d == () for d in info.dependencies.values())


def test_declared_nominals_reach_the_model_description_and_the_master() -> None:
    load = model_info(build_fmu("BrakeLoad"))
    assert load.variables["speed"].nominal == 1.0 and load.variables["angle"].nominal == 1.0
    assert load.variables["torque"].nominal is None  # none declared: no floor
    md = read_model_description(str(build_fmu("BrakeLoad")))
    assert {v.name: v.nominal for v in md.modelVariables}["speed"] == "1.0"


def test_vendor_annotation_declares_ports_sampled_inputs_regimes() -> None:
    verge = model_info(build_fmu("VergeEscapement"))
    assert verge.annotated and "escape_wheel" in verge.ports
    assert verge.regime == "regime" and verge.variables["regime"].type == "Enumeration"
    assert set(verge.regime_names.values()) >= {"free", "coupled-entrance", "coupled-exit"}
    assert all(n.startswith("ind_") for n in verge.indicators) and verge.indicators
    damper = model_info(build_fmu("SpringDamperInertia"))
    assert damper.sampled == {"phi_in"}


@pytest.mark.parametrize("h", [0.0, -1.0, float("nan"), float("inf")])
def test_invalid_steps_are_refused_with_the_reason_logged(h) -> None:
    """fmi2Error, never a hang; the instance is in FMI's error state, from which an FMU
    state taken before brings it back."""
    fmu = FmuInstance("i", build_fmu("Inertia"))
    try:
        fmu.initialize(0.0, 1.0, {"J": 1.0})
        before = fmu.get_state()
        with pytest.raises(
            RunError, match=r"doStep failed: .*refused: .*(not positive|not finite)"
        ):
            fmu.do_step(0.0, h)
        with pytest.raises(RunError, match="fmi2SetReal: not allowed in state error"):
            fmu.set_real(fmu.refs(["tau"]), [1.0])
        fmu.set_state(before)
        with pytest.raises(RunError, match=r"fmi2SetReal: tau = nan is not finite"):
            fmu.set_real(fmu.refs(["tau"]), [float("nan")])
        fmu.set_state(before)
        fmu.set_real(fmu.refs(["tau"]), [1.0])
        fmu.do_step(0.0, 1.0)
        assert fmu.get("w") == 1.0
    finally:
        fmu.close()


def test_non_finite_parameter_fails_initialization() -> None:
    fmu = FmuInstance("i", build_fmu("Inertia"))
    try:
        with pytest.raises(RunError, match="fmi2SetReal: J = nan is not finite"):
            fmu.initialize(0.0, 1.0, {"J": float("nan")})
    finally:
        fmu.close()
