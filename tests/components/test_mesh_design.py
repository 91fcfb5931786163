"""A user gear pair in GearMesh (Tepper 1981, ARLCD-TR-81020): the stored tables entered as
design parameters give the stored results bit for bit, and each consistency rule is refused in
one line naming it and its quantities."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from components.design_rules import DesignError
from components.gear_mesh import (
    REGIME_NAMES,
    ClockTableModel,
    GearMesh,
    InvoluteModel,
    build_mesh,
)
from components.mesh_design import (
    CLOCK_DESIGN,
    INVOLUTE_DESIGN,
    check_clock_design,
    check_involute_design,
    check_mesh_design,
    clock_design_values,
    involute_design_values,
)
from components.mesh_efficiency import (
    ClockMeshModel,
    clock_sweep,
    clock_table_cycle_summary,
    involute_cycle,
    involute_cycle_summary,
    involute_efficiency_curve,
)
from components.mesh_efficiency_data import (
    ALFIN_ANOMALY_TABLES,
    CLOCK_MESHES,
    INCH,
    INVOLUTE_MESHES,
)
from orchestrator.errors import ScenarioError
from orchestrator.run import run_scene
from orchestrator.scenario import load_scene
from orchestrator.scenes.gear_mesh.report import check

STORED = {table - 4: mesh for table, mesh in INVOLUTE_MESHES.items()}  # mesh = k: Table k + 4


def _user(mesh_values: dict, **params) -> GearMesh:
    c = GearMesh(mesh=0, **mesh_values, **params)
    c.load_torque = 0.1
    c.initialize(0.0)
    return c


def _run(c: GearMesh, n: int = 40, h: float = 7.3e-4) -> list[tuple[float, ...]]:
    out, t = [], 0.0
    names = [v.name for v in GearMesh.variables("output")]
    for _ in range(n):
        c.step(t, h)
        t += h
        out.append(tuple(getattr(c, name) for name in names))
    return out


# -- every ISAD input is a design parameter ---------------------------------------------------
def test_design_parameters_name_their_source_symbol() -> None:
    isad = "PSUBD NP CAPRP RP CAPRO RO THETAD RHOCAPN RHON CD HOBTIPR K RASFACT".split()
    found = [v.description.rsplit("[ISAD: ", 1)[1].rstrip("]") for v in INVOLUTE_DESIGN]
    assert set(isad) <= set(found) and "ISAD1/ISAD2" in found
    assert all(v.design and v.causality == "parameter" for v in INVOLUTE_DESIGN + CLOCK_DESIGN)
    names = {v.name for v in GearMesh.variables("parameter")}
    assert {v.name for v in INVOLUTE_DESIGN + CLOCK_DESIGN} <= names


# -- the stored tables entered as a user pair -------------------------------------------------
@pytest.mark.parametrize("printed_run", [0, 1])
@pytest.mark.parametrize("k", sorted(STORED))
def test_table_entered_gives_the_stored_mesh(k: int, printed_run: int) -> None:
    table = k + 4
    if printed_run and table in ALFIN_ANOMALY_TABLES:
        pytest.skip("printed ALFIN of Tables 15, 16, 18, 21: a quirk of the 1981 run, no input")
    values = involute_design_values(STORED[k])
    stored = build_mesh(1, k, 1, 0.1, printed_run)
    user = build_mesh(1, 0, 1, 0.1, printed_run, values)
    assert isinstance(user, InvoluteModel) and user.geometry == stored.geometry
    for a, b in zip(involute_efficiency_curve(user.geometry, 0.2),
                    involute_efficiency_curve(stored.geometry, 0.2), strict=True):  # fmt: skip
        assert np.array_equal(a, b)
    assert involute_cycle_summary(user.geometry, 0.2) == involute_cycle_summary(
        stored.geometry, 0.2
    )
    # the component: every output of every step bit-identical
    assert _run(_user(values, mu=0.1, printed_run=printed_run)) == _run(_stored(k, printed_run))


def _stored(k: int, printed_run: int) -> GearMesh:
    c = GearMesh(mesh=k, mu=0.1, printed_run=printed_run)
    c.load_torque = 0.1
    c.initialize(0.0)
    return c


@pytest.mark.parametrize("table", sorted(ALFIN_ANOMALY_TABLES))
def test_printed_run_of_a_user_pair_uses_the_physical_end_of_dual_contact(table: int) -> None:
    """Table 15's ALFIN 13.948 deg (Appendix E) is what the 1981 run printed, not what its
    inputs give (15.215 deg); a user pair gets the physics with the 1981 arithmetic."""
    user = build_mesh(1, 0, 1, 0.1, 1, involute_design_values(INVOLUTE_MESHES[table]))
    stored = build_mesh(1, table - 4, 1, 0.1, 1)
    assert user.geometry == replace(stored.geometry, alpha_fin=stored.geometry.alpha_fin_physical)


def test_the_default_user_pair_is_table_6_as_published() -> None:
    user = build_mesh(1, 0, 1, 0.1, 0, {})
    assert user.geometry == build_mesh(1, 2, 1, 0.1, 0).geometry
    assert user.geometry.pinion_drives  # ISAD1, as Table 15 / Appendix E ran it


def test_gear_drives_selects_isad2() -> None:
    """Table 6 marks the gear as driver: run with ISAD2 the mesh enters at 17.501 deg and leaves
    dual contact at 19.964 deg (Tepper 1981 Table 6; the digest's recomputation)."""
    values = involute_design_values(INVOLUTE_MESHES[6], driver="gear")
    g = build_mesh(1, 0, 1, 0.1, 1, values).geometry
    assert not g.pinion_drives
    z = 3.14159 / 180.0
    assert g.alpha_in / z == pytest.approx(17.501, abs=5e-3)
    assert g.alpha_fin / z == pytest.approx(19.964, abs=5e-3)


def test_points_per_cycle_sets_the_report_cycle() -> None:
    m = build_mesh(1, 0, 1, 0.1, 1, {"points_per_cycle": 25})
    assert m.points == 25
    # Table 15 run with ISAD1 and the physical ALFIN: CYCLEFF .8734 at mu = 0.1 (K = 25)
    assert involute_cycle(m.geometry, 0.1, m.points)[2] == pytest.approx(0.8734, abs=1e-4)


# -- the clock meshes of Tables 1-4 -----------------------------------------------------------
@pytest.mark.parametrize("table", sorted(CLOCK_MESHES))
def test_clock_table_entered_gives_the_library_results(table: int) -> None:
    mesh = CLOCK_MESHES[table]
    m = build_mesh(2, 2, 0, 0.1, 0, clock_design_values(mesh))
    assert isinstance(m, ClockTableModel)
    library = ClockMeshModel(mesh)
    phis = library.pitch_g * (np.arange(200) / 200 - 0.5)
    ours = [m.efficiency(float(p)) for p in phis]
    assert ours == [library.point_efficiency(0.1, float(p))[0] for p in phis]
    assert min(ours) == clock_sweep(mesh, (0.1,), n=200)[1][0]
    # one gear pitch turns the pinion one leaf, forwards
    assert m.driven(m.cycle_start + m.cycle) - m.driven(m.cycle_start) == pytest.approx(
        2 * math.pi / mesh.n_pinion, rel=1e-9
    )
    c = GearMesh(model=2, clock_mesh=0, mu=0.1, **clock_design_values(mesh))
    c.load_torque = 0.01
    c.initialize(0.0)
    _run(c, n=20, h=2.0 * m.cycle / c.speed / 20)  # two gear pitches
    assert c.mesh_cycles == pytest.approx(2.0, rel=1e-9)
    assert c.driven_angle == pytest.approx(4 * math.pi / mesh.n_pinion, rel=1e-9)
    # two whole pitches at constant load: the work ratio of the closed form's quadrature
    summary = clock_table_cycle_summary(library, 0.1)
    assert c.cycle_efficiency == pytest.approx(summary.work_efficiency, rel=1e-9)
    assert {REGIME_NAMES[r] for r in m.regimes} >= {"round-on-flank-recess"}


# -- every stored mesh passes every rule ------------------------------------------------------
def test_stored_meshes_pass_the_rules() -> None:
    for mesh in INVOLUTE_MESHES.values():
        assert check_involute_design(mesh) == [], mesh.name
        assert check_mesh_design({"mesh": 0, **involute_design_values(mesh)}) == []
    for mesh in CLOCK_MESHES.values():
        b = mesh.gear_pitch_radius + mesh.pinion_pitch_radius
        assert check_clock_design(mesh, b) == [], mesh.name


# -- one test per rule ------------------------------------------------------------------------
T6, T5 = INVOLUTE_MESHES[6], INVOLUTE_MESHES[5]


def _one(violations, rule: str) -> str:
    assert [v.rule for v in violations] == [rule]
    text = str(violations[0])
    assert text.startswith(f"design rule '{rule}' broken: ") and "\n" not in text
    return text


def test_rule_involute_base_radius() -> None:
    text = _one(
        check_involute_design(replace(T6, pinion_pitch_radius=0.1010 * INCH)),
        "involute base radius",
    )
    # 0.1010 cos 20 = 0.09491 in against 16 cos 20 / 160 = 0.09397 in
    assert "RP cos(THETAD) = 0.09491 in" in text and "= 0.09397 in" in text
    assert "NP = 16" in text and "PSUBD = 80 /in" in text


def test_rule_equal_base_pitch() -> None:
    text = _one(
        check_involute_design(
            replace(T6, gear_pitch_radius=0.4531 * INCH, center_distance=0.5541 * INCH)
        ),
        "equal base pitch",
    )
    # 0.4531 in at 80 / in: NG = 72 (72.496); pi cos 20 / 80 = 0.03690 in
    assert "(NG = 72)" in text and "PB = pi cos(THETAD) / PSUBD = 0.03690 in" in text
    assert "PB gear = 2 pi CAPRP cos(THETAD) / NG = 0.03716 in" in text


def test_rule_outside_radius_above_base_radius() -> None:
    text = _one(
        check_involute_design(replace(T6, pinion_outside_radius=0.0930 * INCH)),
        "outside radius above base radius",
    )
    assert "pinion: RO = 0.09300 in against RB = 0.09397 in" in text


def test_rule_centre_distance() -> None:
    text = _one(
        check_involute_design(replace(T6, center_distance=0.5400 * INCH)), "centre distance"
    )
    assert "CD = 0.54000 in against CAPRP + RP = 0.55000 in" in text


def test_rule_undercut() -> None:
    pinion = 5 / 160 * INCH  # a 5-tooth pinion at 80 / in
    mesh = replace(T6, n_pinion=5, pinion_pitch_radius=pinion, pinion_outside_radius=7 / 160 * INCH,
                   center_distance=T6.gear_pitch_radius + pinion)  # fmt: skip
    text = _one(check_involute_design(mesh), "undercut")
    # b = 1.2 / 80 + 0.002 = 0.017 in: U = 1 - 0.017 / 0.03125 = 0.456 <= 0.883
    assert "U = 1 - B / RP = 0.456 <= RASFACT = 0.883" in text and "B = 0.01700 in" in text


@pytest.mark.parametrize(
    "changes, cr",
    [
        ({"gear_outside_radius": 0.452 * INCH, "pinion_outside_radius": 0.104 * INCH}, "0.358"),
        ({"pressure_angle": math.radians(14.5), "gear_outside_radius": 0.640625 * INCH,
          "pinion_outside_radius": 0.515625 * INCH, "center_distance": 1.125 * INCH}, "2.237"),
    ],
)  # fmt: skip
def test_rule_contact_ratio(changes: dict, cr: str) -> None:
    base = T6 if "pressure_angle" not in changes else T5
    text = _one(check_involute_design(replace(base, **changes)), "contact ratio")
    assert f"CR = {cr} " in text and "expected 1 < CR < 2" in text


CLOCK_T1 = CLOCK_MESHES[1]
B1 = CLOCK_T1.gear_pitch_radius + CLOCK_T1.pinion_pitch_radius


def test_rule_clock_circular_pitch() -> None:
    text = _one(check_clock_design(replace(CLOCK_T1, n_pinion=17), B1), "clock circular pitch")
    # 2 pi 0.360 / 72 = 0.03142 in against 2 pi 0.090 / 17 = 0.03326 in
    assert "2 pi R_G / N_G = 0.03142 in (N_G = 72)" in text
    assert "2 pi R_P / N_P = 0.03326 in (N_P = 17)" in text


def test_rule_clock_tooth_thickness() -> None:
    mesh = replace(CLOCK_T1, pinion_tooth_thickness=0.017 * INCH)  # more than 2 rho_P = 0.016
    text = _one(check_clock_design(mesh, B1), "clock tooth thickness")
    assert "pinion: t_P = 0.01700 in against rho_P = 0.00800 in" in text


def test_rule_clock_centre_of_curvature() -> None:
    mesh = replace(CLOCK_T1, pinion_center_distance=0.0015 * INCH)  # C_x = 0.002 in
    text = _one(check_clock_design(mesh, B1), "clock centre of curvature")
    assert "a_P = 0.00150 in against C_x = rho - t/2 = 0.00200 in" in text


def test_rule_clock_tooth_tip() -> None:
    mesh = replace(CLOCK_T1, gear_center_distance=0.340 * INCH)
    text = _one(check_clock_design(mesh, B1), "clock tooth tip")
    # sqrt(0.340^2 - 0.0153^2) + sqrt(0.0223^2 - 0.0153^2) = 0.33966 + 0.01622 in
    assert "r_om = sqrt(a^2 - C_x^2) + h = 0.35588 in against R_G = 0.36000 in" in text


def test_rule_clock_contact() -> None:
    text = _one(check_clock_design(CLOCK_T1, 0.470 * INCH), "clock contact")
    assert "b = 0.47000 in (R_G + R_P = 0.45000 in)" in text


# -- the rules refuse a pair before it runs -----------------------------------------------------
def test_initialization_refuses_a_broken_pair() -> None:
    with pytest.raises(DesignError, match=r"^design rule 'centre distance' broken: CD = 0\.54000"):
        _user({"center_distance": 0.54 * INCH})
    with pytest.raises(DesignError, match=r"^design rule 'clock contact' broken"):
        c = GearMesh(model=2, clock_mesh=0, clock_center_distance=0.47 * INCH)
        c.initialize(0.0)
    # a stored mesh ignores the design parameters
    GearMesh(mesh=2, center_distance=0.54 * INCH).initialize(0.0)


# -- scenes: the user pair entered in inches and degrees, and the drawing ---------------------
SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"


def test_user_pair_scene_runs_as_the_stored_mesh(tmp_path: Path, fmu_cache: Path) -> None:
    """Table 15's inputs typed as the report prints them give the stored mesh 2 (physical end
    of dual contact) bit for bit: every recorded sample and event."""
    user = run_scene(load_scene(SCENARIOS / "mesh_user_pair.toml"), output_dir=tmp_path / "u",
                     cache_dir=fmu_cache, show_progress=False)  # fmt: skip
    stored_scene = load_scene(
        SCENARIOS / "mesh_efficiency.toml", {"fmus.mesh.parameters.printed_run": 0}
    )
    stored = run_scene(stored_scene, output_dir=tmp_path / "s", cache_dir=fmu_cache,
                       show_progress=False)  # fmt: skip
    assert user.status == stored.status == "completed"
    for name in ("timeseries.csv", "events.csv"):
        assert (tmp_path / "u" / name).read_bytes() == (tmp_path / "s" / name).read_bytes()
    assert user.accuracy["headline_error"] < user.scene.error_bound
    # Table 15 run with the physical ALFIN 15.215 deg: minimum .8666 at mu = 0.1 (the dual
    # plateau of Appendix E), the continuous cycle mean .8735 (K = 25 gives .8734)
    assert user.value("min_efficiency") == pytest.approx(0.8666, abs=1e-4)
    assert user.value("mean_efficiency") == pytest.approx(0.8734, abs=2e-4)


def test_a_broken_user_pair_is_refused_in_one_line() -> None:
    # Refused when the scene loads, before any FMU is made.
    with pytest.raises(ScenarioError) as err:
        load_scene(
            SCENARIOS / "mesh_user_pair.toml", {"fmus.mesh.parameters.center_distance": "0.54 in"}
        )
    text = str(err.value)
    assert "[parameters] design rule 'centre distance' broken: CD = 0.54000 in" in text
    assert "\n" not in text
    assert check(load_scene(SCENARIOS / "mesh_user_pair.toml")) == []


def _radii(fig) -> set[float]:
    return {
        round(p.get_radius(), 9) for ax in fig.axes for p in ax.patches if hasattr(p, "get_radius")
    }


@pytest.mark.parametrize(
    "name", ["mesh_efficiency.toml", "mesh_user_pair.toml", "mesh_efficiency_clock.toml"]
)
def test_drawing_is_written_to_scale(name: str, tmp_path: Path) -> None:
    import matplotlib.pyplot as plt

    from orchestrator.scenes import DRAWINGS
    from orchestrator.scenes.gear_mesh.drawing import figure

    scene = load_scene(SCENARIOS / name)
    DRAWINGS["gear_mesh"](scene, tmp_path / "pair.png")
    assert (tmp_path / "pair.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (tmp_path / "pair.png").stat().st_size > 20_000
    fig = figure(scene)
    radii = _radii(fig)
    plt.close(fig)
    if name == "mesh_efficiency_clock.toml":
        # M739-like mesh 1: 64 : 9 on centre distance 0.4701 in (11.941 mm)
        b = 0.4701 * 25.4
        assert round(b * 64 / 73, 9) in radii and round(b * 9 / 73, 9) in radii
        return
    # Table 15 (p. 31): base radii .4229 / .0940 in, outside .4625 / .1125 in, operating pitch
    # radii .45082 / .10018 in, drawn in mm
    mm = [r / 25.4 for r in radii]
    for printed, digits in ((0.4229, 4), (0.0940, 4), (0.4625, 4), (0.1125, 4), (0.45082, 5),
                            (0.10018, 5)):  # fmt: skip
        assert any(round(r, digits) == printed for r in mm), printed


def test_drawing_of_a_tables_1_4_clock_mesh(tmp_path: Path) -> None:
    import matplotlib.pyplot as plt

    from orchestrator.scenes.gear_mesh.drawing import figure

    scene = load_scene(SCENARIOS / "mesh_efficiency_clock.toml", {
        "fmus.mesh.parameters.clock_mesh": 0})  # fmt: skip
    fig = figure(scene)
    radii = _radii(fig)
    plt.close(fig)
    assert {round(0.360 * 25.4, 9), round(0.090 * 25.4, 9)} <= radii  # Table 1 pitch radii
