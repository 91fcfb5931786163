"""Mesh efficiency against Tepper (1981), ARLCD-TR-81020: Tables 14-22, Appendix E, Conclusions."""

from __future__ import annotations

import math

import numpy as np
import pytest

from components.mesh_efficiency import (
    LEGACY_PI,
    MU_SWEEP,
    ClockMeshModel,
    clock_sweep,
    contact_efficiency,
    involute_cycle,
    involute_efficiency_at,
    involute_efficiency_curve,
    involute_geometry,
    involute_point_efficiency,
    involute_sweep,
)
from components.mesh_efficiency_data import (
    ALFIN_ANOMALY_TABLES,
    APPENDIX_E_ALFIN_DEG,
    APPENDIX_E_CYCLE,
    APPENDIX_E_DUAL,
    APPENDIX_E_MIN,
    APPENDIX_E_MU,
    APPENDIX_E_SINGLE,
    CLOCK_MESHES,
    INCH,
    INVOLUTE_MESHES,
    PRINTED_RUNS,
)

Z = LEGACY_PI / 180.0  # the programs' degree factor


def appendix_e_geometry(legacy: bool = True):
    return involute_geometry(INVOLUTE_MESHES[6], alpha_fin=APPENDIX_E_ALFIN_DEG * Z, legacy=legacy)


# -- geometry of all nine involute meshes (Tables 14–22) ------------------------------------
@pytest.mark.parametrize("table", sorted(INVOLUTE_MESHES))
def test_involute_geometry_printed(table: int) -> None:
    g = involute_geometry(INVOLUTE_MESHES[table], legacy=True)
    pr = PRINTED_RUNS[table]
    assert g.form_radius / INCH == pytest.approx(pr.rf_in, abs=1e-4)
    assert g.undercut == pr.undercut
    tol = 0.02 if table == 8 else 0.01  # T18 printed 20.71 needs CD ~ .34533 (derived)
    assert math.degrees(g.op_pressure_angle) == pytest.approx(pr.op_pressure_deg, abs=tol)
    assert g.contact_ratio == pytest.approx(pr.contact_ratio, abs=0.01)
    assert g.alpha_in / Z == pytest.approx(pr.alin_deg, abs=0.005)
    if table not in ALFIN_ANOMALY_TABLES:
        assert g.alpha_fin / Z == pytest.approx(pr.alfin_deg, abs=0.005)


def test_alfin_anomaly_physical_values() -> None:
    """The four ISAD1 form-radius runs printed an ALFIN that the physics does not give."""
    correct = {6: 15.215, 7: 13.946, 8: 14.631, 12: 12.156}
    for table, value in correct.items():
        g = involute_geometry(INVOLUTE_MESHES[table], legacy=True)
        assert g.alpha_fin / Z == pytest.approx(value, abs=0.005)
        assert abs(g.alpha_fin / Z - PRINTED_RUNS[table].alfin_deg) > 0.1
        rb, ro = g.pinion_base_radius, INVOLUTE_MESHES[table].pinion_outside_radius
        assert g.alpha_fin == pytest.approx((math.sqrt(ro**2 - rb**2) - g.base_pitch) / rb)


# -- Appendix E, point by point -------------------------------------------------------------
def _appendix_e_points():
    for j, mu in enumerate(APPENDIX_E_MU):
        for deg, row in APPENDIX_E_SINGLE.items():
            if row[j] is not None:
                yield mu, deg, row[j]


# The single printed value that the equations miss by slightly more than the print precision.
_OFF_BY_1E4 = {(0.275, 20.33)}


@pytest.mark.parametrize("j", range(len(APPENDIX_E_MU)))
def test_appendix_e_table(j: int) -> None:
    mu = APPENDIX_E_MU[j]
    alphas, eff, cycle, minimum = involute_cycle(appendix_e_geometry(), mu, k=25)
    degs = np.round(alphas / Z, 2)
    assert len(degs) == 25 and degs[0] == 4.13 and degs[-1] == 25.73
    for deg, e in zip(degs, eff, strict=True):
        deg = float(deg)
        printed = APPENDIX_E_SINGLE[deg][j] if deg in APPENDIX_E_SINGLE else APPENDIX_E_DUAL[j]
        if printed is None or (mu, deg) in _OFF_BY_1E4:
            continue
        assert e == pytest.approx(printed, abs=1e-4), (mu, deg)
    if APPENDIX_E_CYCLE[j] is not None:
        assert cycle == pytest.approx(APPENDIX_E_CYCLE[j], abs=1e-4)
    if APPENDIX_E_MIN[j] is not None:
        assert minimum == pytest.approx(APPENDIX_E_MIN[j], abs=1e-4)


@pytest.mark.xfail(strict=True, reason="computed .70010 vs printed .7002 (1.04e-4 off)")
def test_appendix_e_worst_point() -> None:
    mu, deg = next(iter(_OFF_BY_1E4))
    j = APPENDIX_E_MU.index(mu)
    alphas, eff, _, _ = involute_cycle(appendix_e_geometry(), mu)
    e = eff[int(np.argmin(abs(alphas / Z - deg)))]
    assert e == pytest.approx(APPENDIX_E_SINGLE[deg][j], abs=1e-4)


def test_appendix_e_worked_points() -> None:
    g = appendix_e_geometry()
    # App. E, p. 83: single contact at 14.03 deg and dual plateau, mu = 0.025
    assert involute_point_efficiency(g, 0.025, 14.03 * Z) == pytest.approx(0.9655, abs=5e-5)
    assert involute_point_efficiency(g, 0.025, 8.0 * Z) == pytest.approx(1.98304 / 2.05769, 1e-5)


def test_end_of_dual_contact_error_effect() -> None:
    """With the physical ALFIN (15.215 deg) the rows at 14.03 and 14.93 become dual contact."""
    printed = appendix_e_geometry()
    physical = involute_geometry(INVOLUTE_MESHES[6], legacy=True)
    a, e_printed, cyc_p, min_p = involute_cycle(printed, 0.3)
    _, e_phys, cyc_c, min_c = involute_cycle(physical, 0.3)
    assert (min_p, cyc_p) == pytest.approx((0.6526, 0.6837), abs=1e-4)
    assert (min_c, cyc_c) == pytest.approx((0.6594, 0.6854), abs=1e-4)
    for deg in (14.03, 14.93):
        k = int(np.argmin(abs(a / Z - deg)))
        assert e_phys[k] == pytest.approx(APPENDIX_E_DUAL[-1], abs=1e-4)
        assert e_printed[k] == pytest.approx(APPENDIX_E_SINGLE[deg][-1], abs=1e-4)
    assert np.array_equal(e_printed[a > 15.3 * Z], e_phys[a > 15.3 * Z])


# -- invariants (derived from eqs. 46, 47 and A-26) ------------------------------------------
def test_invariants() -> None:
    g = involute_geometry(INVOLUTE_MESHES[6])
    _, eff0, cyc0, _ = involute_cycle(g, 0.0)
    assert np.all(eff0 == 1.0) and cyc0 == 1.0
    alphas, eff = involute_efficiency_curve(g, 0.2, n=500)
    tan_op = math.tan(g.op_pressure_angle)
    dual = alphas <= g.alpha_fin
    assert np.ptp(eff[dual]) < 1e-14  # S = 0 plateau
    approach = ~dual & (alphas < tan_op)
    recess = alphas > tan_op
    assert np.all(np.diff(eff[approach]) > 0) and np.all(np.diff(eff[recess]) < 0)
    assert eff[recess][0] > eff[approach][-1]  # upward jump at the pitch point
    _, pts, cyc, _ = involute_cycle(g, 0.2)
    assert cyc == pytest.approx(pts.mean(), rel=1e-15)
    for a in alphas[::50]:  # periodic in the base pitch
        shifted = involute_efficiency_at(g, 0.2, a + 3 * g.cycle_angle)
        assert shifted == pytest.approx(involute_point_efficiency(g, 0.2, a), abs=1e-12)


def test_general_statics_reproduces_a26() -> None:
    """The vector single-contact statics gives ref. 1 eq. A-26 for an involute contact."""
    g = involute_geometry(INVOLUTE_MESHES[6], alpha_fin=0.0)  # single contact everywhere
    rb, big_rb, op = g.pinion_base_radius, g.gear_base_radius, g.op_pressure_angle
    cd = INVOLUTE_MESHES[6].center_distance
    o1, o2 = np.zeros(2), np.array([cd, 0.0])
    t1 = rb * np.array([math.cos(op), math.sin(op)])  # base-tangent point T' of the pinion
    line = np.array([math.sin(op), -math.cos(op)])  # line of action, from T' towards T
    for alpha in (0.1, 0.3, 0.45):
        contact = t1 + rb * alpha * line
        for mu in (0.05, 0.3):
            eff, ratio = contact_efficiency(o1, o2, contact, line, mu, 0.090 * INCH, 0.125 * INCH,
                                            omega1=-1.0)  # fmt: skip
            assert ratio == pytest.approx(-rb / big_rb)  # external mesh
            assert eff == pytest.approx(involute_point_efficiency(g, mu, alpha), rel=1e-12)


# -- all nine meshes: cross-check with an independent recomputation of eqs. 1-52 (K = 25,
# physical ALFIN; not printed in the report) -----------------------------------------------
SECTION_9 = {  # table: (min mu=.1, min mu=.3, cycle mu=.1, cycle mu=.3), physical ALFIN
    5: (.9680, .9091, .9704, .9147), 6: (.8666, .6594, .8734, .6854),
    7: (.8801, .6913, .8915, .7228), 9: (.9166, .7729, .9318, .8090),
    8: (.9256, .7984, .9361, .8219), 10: (.8794, .6753, .8926, .7164),
    11: (.9238, .7913, .9303, .8083), 12: (.8645, .6485, .8783, .6911),
    13: (.8698, .6058, .8883, .6769),
}  # fmt: skip


@pytest.mark.parametrize("table", sorted(SECTION_9))
def test_nine_meshes_cycle_and_minimum(table: int) -> None:
    g = involute_geometry(INVOLUTE_MESHES[table])
    cyc, mins = involute_sweep(g, (0.1, 0.3))
    m1, m3, c1, c3 = SECTION_9[table]
    np.testing.assert_allclose([mins[0], mins[1], cyc[0], cyc[1]], [m1, m3, c1, c3], atol=1e-4)


def test_involute_conclusions() -> None:
    """Conclusions, p. 13: involute minimum ~0.9 at mu = 0.1; its '~0.7 at 0.3' is optimistic
    (.606)."""
    mins_01, mins_03 = [], []
    for mesh in INVOLUTE_MESHES.values():
        _, mins = involute_sweep(involute_geometry(mesh), (0.1, 0.3))
        mins_01.append(mins[0])
        mins_03.append(mins[1])
    assert min(mins_01) == pytest.approx(0.9, abs=0.05)
    assert min(mins_03) == pytest.approx(0.606, abs=1e-3)


def test_sweep_shape() -> None:
    cyc, mins = involute_sweep(involute_geometry(INVOLUTE_MESHES[6]))
    assert len(cyc) == len(MU_SWEEP) == 13
    assert cyc[0] == mins[0] == 1.0
    assert np.all(np.diff(cyc) < 0) and np.all(mins <= cyc)


# -- clock meshes (derived model) -----------------------------------------------------------
@pytest.mark.parametrize("table", sorted(CLOCK_MESHES))
def test_clock_kinematics_consistent(table: int) -> None:
    model = ClockMeshModel(CLOCK_MESHES[table])
    n = 400
    phis = model.pitch_g * (np.arange(n + 1) / n - 0.5)
    contacts = [model.contact(p) for p in phis]
    psi = np.array([c.pinion_angle for c in contacts])
    # one gear pitch turns the pinion by one leaf pitch: mean ratio -N_G/N_P
    assert psi[-1] - psi[0] == pytest.approx(-model.pitch_p, rel=1e-6)
    # continuous (no drop): the pinion never jumps
    ratios = np.array([model.point_efficiency(0.0, p)[1] for p in phis])
    assert np.max(np.abs(np.diff(psi))) < 1.01 * np.max(np.abs(ratios)) * model.pitch_g / n
    # the statics' speed ratio agrees with the position solution (central differences)
    fd = (psi[2:] - psi[:-2]) / (phis[2:] - phis[:-2])
    tags = [(c.pair, c.phase) for c in contacts]
    same = np.array([tags[k - 1] == tags[k] == tags[k + 1] for k in range(1, n)])
    np.testing.assert_allclose(ratios[1:-1][same], fd[same], rtol=1e-4)
    assert {"ror", "rof"} & {c.phase for c in contacts}
    eff0 = [model.point_efficiency(0.0, p)[0] for p in phis]
    np.testing.assert_allclose(eff0, 1.0, atol=1e-12)


def test_clock_conclusions_18_leaf_meshes() -> None:
    """Conclusions, p. 13: clock minimum efficiency ~0.8 at mu = 0.3 and ~0.9 at mu = 0.1 (graph
    readings, +-0.05), for the two meshes with 18-leaf pinions (Tables 1 and 4)."""
    mins = np.array([clock_sweep(CLOCK_MESHES[t], (0.1, 0.3), n=200)[1] for t in (1, 4)])
    assert mins[:, 1].min() == pytest.approx(0.8, abs=0.05)
    assert mins[:, 0].min() == pytest.approx(0.9, abs=0.05)


@pytest.mark.xfail(
    strict=True,
    reason="derived model: 7- and 8-leaf meshes (Tables 3, 2) reach 0.640/0.676 at mu = 0.3 "
    "and 0.847 at mu = 0.1, late in recess on the pinion flank (centre distance assumed)",
)
def test_clock_conclusions_all_four() -> None:
    """Conclusions, p. 13: the lowest clock minimum efficiency of the four meshes is ~0.8 at 0.3."""
    mins = np.array([clock_sweep(mesh, (0.1, 0.3), n=200)[1] for mesh in CLOCK_MESHES.values()])
    assert mins[:, 1].min() == pytest.approx(0.8, abs=0.05)
    assert mins[:, 0].min() == pytest.approx(0.9, abs=0.05)
