"""Clock train kinematics of the US Army fuze report of about 1980 (Task 2, eqs. 1-126): checks."""

from __future__ import annotations

import math

import numpy as np
import pytest

from components.clock_train_kinematics import (
    M739_CD_SWEEP,
    M739_MESH1,
    M739_MESH2,
    M739_TRAIN,
    TEST_PLANS,
    ClockMesh,
    escapement_cd_sweep,
)

# A synthetic check geometry (the report has no numbers; the values below are derived from an
# independent implementation of its equations): mesh 1 and a mirrored mesh 2 with beta2 = -0.3.
CHECK_M1 = ClockMesh(1.0, 0.2, 0.8, 0.1, 0.03, 0.3, 0.2, 0.03, 16, 4)
CHECK_M2 = ClockMesh(1.0, -0.3, 0.8, 0.1, 0.03, 0.3, 0.2, 0.03, 16, 4, mirrored=True)
MESHES = {"mesh1": M739_MESH1, "mesh2": M739_MESH2}


def test_check_geometry_transition_values() -> None:
    phi1t, phi2pt = CHECK_M1.transition()
    assert phi1t == pytest.approx(0.266457, abs=1e-6)
    assert phi2pt == pytest.approx(3.025756, abs=1e-6)
    for phase in ("ror", "rof"):
        assert CHECK_M1.speed_ratio(phi1t, phase) == pytest.approx(-3.999373, abs=1e-6)
        assert CHECK_M1.driven_angle(phi1t, phase) == pytest.approx(phi2pt, abs=1e-12)
    # mesh 2 (gear turning CW): phi2GT = -0.366457, psiT = -3.125756
    assert CHECK_M2.driven_angle(-0.366457, "ror") == pytest.approx(-3.125756, abs=5e-6)
    assert CHECK_M2.driven_angle(-0.366457, "rof") == pytest.approx(-3.125756, abs=5e-6)


def test_check_geometry_second_derivatives() -> None:
    """Derived: d2phi2P/dphi1^2 jumps at the transition (-1.537 RoR, -3.037 RoF); X Z of the
    mesh-1 RoR inverse at phi1 = 0.27 is -0.021089."""
    t = CHECK_M1.transition()[0]
    assert CHECK_M1.ratio_derivative(t, "ror") == pytest.approx(-1.537, abs=1e-3)
    assert CHECK_M1.ratio_derivative(t, "rof") == pytest.approx(-3.037, abs=1e-3)
    y = CHECK_M1.driven_angle(0.27, "ror")
    assert CHECK_M1.inverse_ratio_derivative(y, "ror") == pytest.approx(-0.021089, abs=1e-6)


def _inputs(mesh: ClockMesh, n: int = 40) -> np.ndarray:
    s = -1.0 if mesh.mirrored else 1.0
    p = 2 * math.pi / mesh.n_gear
    # three tooth cycles, avoiding the handover instants themselves
    return s * (mesh.handover() - p + 3 * p * (np.arange(n) + 0.37) / n)


@pytest.mark.parametrize("name", sorted(MESHES))
def test_round_trip_and_inverse_ratio(name: str) -> None:
    mesh = MESHES[name]
    for x in _inputs(mesh):
        y = mesh.driven_angle(x)
        assert mesh.driver_angle(y) == pytest.approx(x, abs=1e-12)
        assert mesh.speed_ratio(x) * mesh.inverse_speed_ratio(y) == pytest.approx(1.0, abs=1e-12)
    # and with each phase model forced, near the transition
    s = -1.0 if mesh.mirrored else 1.0
    t = mesh.transition()[0]
    for phase in ("ror", "rof"):
        for x in s * (t + np.linspace(-0.02, 0.02, 7)):
            y = mesh.driven_angle(x, phase)
            assert mesh.driver_angle(y, phase) == pytest.approx(x, abs=1e-12)
            ratio = mesh.speed_ratio(x, phase) * mesh.inverse_speed_ratio(y, phase)
            assert ratio == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("name", sorted(MESHES))
def test_speed_ratio_finite_differences(name: str) -> None:
    mesh = MESHES[name]
    h = 1e-6
    for x in _inputs(mesh, 25):
        fd = (mesh.driven_angle(x + h) - mesh.driven_angle(x - h)) / (2 * h)
        assert mesh.speed_ratio(x) == pytest.approx(fd, rel=1e-6, abs=1e-7)
        y = mesh.driven_angle(x)
        fdi = (mesh.driver_angle(y + h) - mesh.driver_angle(y - h)) / (2 * h)
        assert mesh.inverse_speed_ratio(y) == pytest.approx(fdi, rel=1e-6, abs=1e-7)
        fd2 = (mesh.speed_ratio(x + h) - mesh.speed_ratio(x - h)) / (2 * h)
        assert mesh.ratio_derivative(x) == pytest.approx(fd2, rel=1e-4, abs=1e-4)
        fdi2 = (mesh.inverse_speed_ratio(y + h) - mesh.inverse_speed_ratio(y - h)) / (2 * h)
        assert mesh.inverse_ratio_derivative(y) == pytest.approx(fdi2, rel=1e-4, abs=1e-5)


@pytest.mark.parametrize("name", sorted(MESHES))
def test_continuity_at_phase_change(name: str) -> None:
    mesh = MESHES[name]
    s = -1.0 if mesh.mirrored else 1.0
    t = s * mesh.transition()[0]
    for eps in (1e-7, 1e-9):
        before, after = t - s * eps, t + s * eps
        jump = mesh.driven_angle(after) - mesh.driven_angle(before)
        assert jump == pytest.approx(2 * s * eps * mesh.speed_ratio(t), rel=1e-3, abs=1e-13)
        assert mesh.speed_ratio(before) == pytest.approx(mesh.speed_ratio(after), abs=1e-5)
    assert mesh.driven_angle(t, "ror") == pytest.approx(mesh.driven_angle(t, "rof"), abs=1e-12)
    assert mesh.speed_ratio(t, "ror") == pytest.approx(mesh.speed_ratio(t, "rof"), abs=1e-9)


@pytest.mark.parametrize("name", sorted(MESHES))
def test_handover_and_mean_ratio(name: str) -> None:
    mesh = MESHES[name]
    s = -1.0 if mesh.mirrored else 1.0
    h = s * mesh.handover()
    # the next pair is sensed while the current pair is on the flank (derived check)
    assert mesh.handover() > mesh.transition()[0]
    # angle continuous across the handover (the speed ratio may jump there)
    assert mesh.driven_angle(h - s * 1e-10) == pytest.approx(mesh.driven_angle(h), abs=1e-8)
    # one gear tooth turns the pinion by one leaf: mean ratio -N_G/N_P
    p = s * 2 * math.pi / mesh.n_gear
    x0 = h - 0.3 * p
    travel = mesh.driven_angle(x0 + p) - mesh.driven_angle(x0)
    assert travel / p == pytest.approx(-mesh.n_gear / mesh.n_pinion, rel=1e-12)
    # a new pair first touches in round-on-round
    assert mesh._phase_fwd(mesh.handover() - 2 * math.pi / mesh.n_gear, "auto") == "ror"


def test_train_round_trip_and_ratio() -> None:
    h = 1e-6
    for phi1 in np.linspace(-0.4, 0.4, 13):  # a few teeth of mesh 1, many of mesh 2
        psi = M739_TRAIN.escape_angle(phi1)
        assert M739_TRAIN.rotor_angle(psi) == pytest.approx(phi1, abs=1e-12)
        fd = (M739_TRAIN.escape_angle(phi1 + h) - M739_TRAIN.escape_angle(phi1 - h)) / (2 * h)
        assert M739_TRAIN.speed_ratio(phi1) == pytest.approx(fd, rel=1e-5)
        fd2 = (M739_TRAIN.speed_ratio(phi1 + h) - M739_TRAIN.speed_ratio(phi1 - h)) / (2 * h)
        assert M739_TRAIN.ratio_derivative(phi1) == pytest.approx(fd2, rel=1e-3, abs=1e-3)
    turn = M739_TRAIN.escape_angle(2 * math.pi) - M739_TRAIN.escape_angle(0.0)
    assert turn / (2 * math.pi) == pytest.approx(32.0, rel=1e-12)  # (-64/9) x (-36/8)


def test_no_contact_raises() -> None:
    with pytest.raises(ValueError):
        M739_MESH1.driven_angle(M739_MESH1.transition()[0] - 1.0, "ror")


def test_test_plan_data() -> None:
    assert set(TEST_PLANS) == {"M577", "M739"}
    pallet = TEST_PLANS["M739"]["pallet"]
    assert pallet["angle_rad"] == pytest.approx(0.299615, abs=1e-6)
    assert pallet["corner_dimension_m"] == pytest.approx(4.8387e-3, abs=1e-7)
    sweep = escapement_cd_sweep(4.0e-3, 0.05e-3, 5)
    np.testing.assert_allclose(sweep, [3.95e-3, 3.975e-3, 4.0e-3, 4.025e-3, 4.05e-3])
    assert M739_CD_SWEEP[len(M739_CD_SWEEP) // 2] == pytest.approx(5.7404e-3, abs=1e-7)
    assert np.ptp(M739_CD_SWEEP) == pytest.approx(2 * 0.001 * 0.0254)
