"""The M739 rotor behind the two-pass clock train (ClockGearTrain), the verge's escapement
centre distance, and the clock-train S&A scenes (kinematics of the US Army fuze report of about
1980, Task 2; M739 data of Lowen & Tepper 1982, ARLCD-TR-82013)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from components.base import ComponentError
from components.clock_gear_train import (
    LOSS_NONE,
    LOSS_POINT,
    STUCK,
    ClockGearTrain,
    ClockTrainPhysics,
)
from components.clock_train_kinematics import INCH, M739_CD_SWEEP, M739_ESCAPEMENT_CD, M739_TRAIN
from components.m739_data import M739
from components.mesh_efficiency import contact_efficiency
from components.verge_escapement import VergeEscapement, escapement_data
from components.verge_geometry import kinem
from orchestrator.run import run_scene
from orchestrator.scenario import load_scene
from orchestrator.scenes.clock_train.monolithic import (
    ARMING_ROTOR_ANGLE,
    arming_phi,
    run_clock_train,
)
from orchestrator.scenes.m739.monolithic import run_m739

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
SCENE = SCENARIOS / "clock_train_sa.toml"
SWEEP_SCENE = SCENARIOS / "clock_train_cd_sweep.toml"
# Positions over two escape-wheel turns, off the piece bounds (generic points).
PHIS = [float(x) for x in 0.0137 + np.linspace(0.0, 4.0 * math.pi, 53)]


def _positions(psi: float) -> tuple[float, float]:
    """Rotor and cluster angles from the train's own auto-phase inverse kinematics."""
    m1, m2 = M739_TRAIN.mesh1, M739_TRAIN.mesh2
    theta2 = m2.driver_angle(psi) - M739_TRAIN.kappa2
    return m1.driver_angle(theta2), theta2


def _train(t_esc: float, **parameters: float) -> ClockGearTrain:
    """A standalone train under a held escapement torque, from rest."""
    c = ClockGearTrain(**parameters)
    c.T_esc = t_esc
    c.initialize(0.0)
    return c


def _at(phys: ClockTrainPhysics, phi: float, direction: int = 1) -> tuple[float, ...]:
    phys.set_mode(phi, direction)
    return phys.evaluate(phi)


# ---------------------------------------------------------------------------------------
# Component physics
# ---------------------------------------------------------------------------------------
def test_reflected_inertia_is_twice_the_kinetic_energy_per_speed_squared() -> None:
    """J_ref (mu = 0) = I3 + I2 r2^2 + I1 r1^2 with r_i central differences of the positions."""
    phys = ClockTrainPhysics(mu=0.0)
    h = 1e-6
    for phi in PHIS:
        ev = _at(phys, phi)
        up, down = _positions(phi + h), _positions(phi - h)
        r1 = (up[0] - down[0]) / (2 * h)
        r2 = (up[1] - down[1]) / (2 * h)
        kinetic = 0.5 * (M739.i3 + M739.i2 * r2 * r2 + M739.i1 * r1 * r1)  # per phi_dot^2
        j_ref = phys.response(phi, 0.0)[0]
        assert j_ref == pytest.approx(2.0 * kinetic, rel=1e-7)
        assert phys.j_stot(phi) == pytest.approx(j_ref, rel=1e-14)
        assert ev[0] == pytest.approx(_positions(phi)[0], abs=1e-12)


def test_speed_squared_terms_are_half_the_inertia_gradient() -> None:
    """Lagrange: T_ref(phi_dot) - T_ref(0) = -1/2 dJ/dphi phi_dot^2 (mu = 0)."""
    phys = ClockTrainPhysics(mu=0.0)
    h = 1e-6
    for phi in PHIS:
        _at(phys, phi)
        w = 700.0
        quad = (phys.response(phi, w)[1] - phys.response(phi, 0.0)[1]) / (w * w)
        grad = (phys.j_stot(phi + h) - phys.j_stot(phi - h)) / (2 * h)  # same piece
        assert quad == pytest.approx(-0.5 * grad, rel=1e-6, abs=1e-16)


def test_spin_moment_mapped_through_the_ratio() -> None:
    """At rest and mu = 0, T_ref = -A35 sin(Phi) d(theta1)/d(phi) (virtual work)."""
    phys = ClockTrainPhysics(mu=0.0)
    a35 = M739.m1 * M739.r1 * M739.rc1 * M739.omega**2
    h = 1e-6
    for phi in PHIS:
        _at(phys, phi)
        r1 = (_positions(phi + h)[0] - _positions(phi - h)[0]) / (2 * h)
        drive = -a35 * math.sin(phys.rotor_angle(phi))
        assert phys.response(phi, 0.0)[1] == pytest.approx(drive * r1, rel=1e-7)
    _at(phys, 0.0)
    assert phys.rotor_angle(0.0) == M739.phi1c


def test_point_efficiency_is_the_clock_mesh_contact_statics() -> None:
    """loss_model 1 uses mesh_efficiency.contact_efficiency on this train's contacts."""
    phys = ClockTrainPhysics(mu=0.1, loss_model=LOSS_POINT)
    for phi in PHIS:
        ev = _at(phys, phi)
        for i, mesh in enumerate(phys.meshes):
            k, phase, _ = phys.pieces[i]
            x = ev[6 + i]
            v = mesh._pair_inverse(x, phase)[0]
            cx, cy, nx, ny = mesh.contact(x, v, phase)
            eta, ratio = contact_efficiency(
                np.zeros(2),
                np.array(phys.pinion_pivot[i]),
                np.array([cx, cy]),
                np.array([nx, ny]),
                0.1,
                *phys.rho[i],
            )
            assert ratio * ev[8 + i][5] == pytest.approx(1.0, abs=1e-12)  # normal = kinematics
            assert phys.point_efficiency(i, ev[8 + i]) == pytest.approx(eta, abs=1e-12)
            assert 0.5 < eta < 1.0


def test_speed_ratio_and_rotor_angle_follow_the_clock_train() -> None:
    """A standalone run over many tooth handovers: the outputs equal ClockTrain's kinematics
    at every step (speed_ratio = ClockTrain.speed_ratio, rotor angle by the auto phases)."""
    c = _train(-0.006, mu=0.1)
    phys = c._phys
    t, checked = 0.0, 0
    while c.handovers < 6 and t < 0.01:
        c.step(t, 5e-6)
        t += 5e-6
        theta1 = phys.theta1_0 + c.rotor_angle - M739.phi1c
        assert c.speed_ratio == pytest.approx(M739_TRAIN.speed_ratio(theta1), rel=1e-9)
        assert theta1 == pytest.approx(M739_TRAIN.rotor_angle(phys.psi0 + c.phi), abs=1e-9)
        checked += 1
    assert c.handovers == 6 and checked > 50


def test_energy_is_conserved_without_friction() -> None:
    """mu = 0: stored + dissipated - external - W_esc stays constant (to 1e-9 of the spin
    work, integrated at 1e-11); dissipation only at tooth handovers (inelastic impacts)."""
    t_esc = -0.0125
    c = _train(t_esc, mu=0.0, tolerance=1e-11)

    def balance() -> float:
        return c.stored_energy + c.dissipated_work - c.external_work - t_esc * c.phi

    t, e0, worst, handover_steps = 0.0, balance(), 0.0, 0
    while t < 4e-3:
        before = (c.handovers, c.dissipated_work)
        c.step(t, 1e-5)
        t += 1e-5
        worst = max(worst, abs(balance() - e0))
        if c.handovers == before[0]:
            assert c.dissipated_work == pytest.approx(before[1], abs=1e-15)
        else:
            handover_steps += 1
            assert c.dissipated_work > before[1]
    assert handover_steps >= 5
    assert worst < 1e-9 * c.external_work


def test_energy_balance_closes_with_friction() -> None:
    t_esc = -0.006
    for model in (1, 2):
        c = _train(t_esc, mu=0.1, loss_model=model, tolerance=1e-11)
        t = 0.0
        while t < 4e-3:
            c.step(t, 1e-5)
            t += 1e-5
        residual = c.stored_energy + c.dissipated_work - c.external_work - t_esc * c.phi
        assert abs(residual) < 1e-9 * c.external_work
        assert c.dissipated_work > 0.02 * c.external_work  # mesh and pivot losses


@pytest.mark.parametrize("mesh", [0, 1])
def test_handover_is_continuous_in_position_and_an_inelastic_impact(mesh: int) -> None:
    phys = ClockTrainPhysics(mu=0.0)
    m = phys.meshes[mesh]
    k = phys.pieces[mesh][0]
    if mesh == 1:  # mesh 2 is mirrored: x2 = -psi - k q
        phi_h = -(m.window_end + k * m.pinion_pitch) - phys.psi0
    else:  # x1 = theta2 - k q: the escape-wheel angle by forward kinematics
        theta2 = m.window_end + k * m.pinion_pitch
        phi_h = M739_TRAIN.mesh2.driven_angle(theta2 + M739_TRAIN.kappa2) - phys.psi0
    assert phi_h > 0.0
    before = _at(phys, phi_h - 1e-7)
    assert phys.pieces[mesh][1] == "rof"
    old = phys.evaluate(phi_h)  # old pair, at the handover
    w, j_load = 650.0, 3.0e-9
    w_new, loss = phys.cross(phi_h + 1e-12, w, j_load)
    assert phys.handovers == 1 and phys.pieces[mesh][:2] == (k - 1, "ror")
    new = phys.evaluate(phi_h)
    assert new[0] == pytest.approx(old[0], abs=1e-11)  # rotor
    assert new[1] == pytest.approx(old[1], abs=1e-11)  # cluster
    jump = new[2 if mesh == 0 else 4] / old[2 if mesh == 0 else 4] - 1.0
    assert abs(jump) > 0.01, "the ratio jumps at the handover"
    # The momentum conjugate to the new constraint is kept, and the loss is the kinetic
    # energy of the velocity change (M-norm), both for rotor, cluster and wheel + load.
    inertias = (M739.i1, M739.i2, M739.i3 + j_load)
    v_old = (old[2] * w, old[4] * w, w)
    v_new = (new[2] * w_new, new[4] * w_new, w_new)
    dirs = (new[2], new[4], 1.0)
    assert sum(i * d * v for i, d, v in zip(inertias, dirs, v_old, strict=True)) == pytest.approx(
        sum(i * d * v for i, d, v in zip(inertias, dirs, v_new, strict=True)), rel=1e-12
    )
    kinetic = 0.5 * sum(i * (a - b) ** 2 for i, a, b in zip(inertias, v_old, v_new, strict=True))
    assert loss == pytest.approx(kinetic, rel=1e-9) and loss > 0.0
    assert before[0] < new[0]


def test_handovers_are_one_pinion_pitch_apart_over_a_whole_run(monkeypatch) -> None:
    """Every handover of a whole arming run: mesh 2 hands over each escape-pinion pitch of
    the wheel angle, mesh 1 each pinion-2 pitch of the cluster angle (the pieces are cut per
    tooth, not per contact range, so the phase cannot drift)."""
    seen: list[tuple[float, int, int, float]] = []
    cross = ClockTrainPhysics.cross

    def record(self, phi, phi_dot, j_load=0.0):
        out = cross(self, phi, phi_dot, j_load)
        seen.append((phi, self.pieces[0][0], self.pieces[1][0], self.evaluate(phi)[1]))
        return out

    monkeypatch.setattr(ClockTrainPhysics, "cross", record)
    result = run_clock_train(mu=0.0, mu1=0.0)
    assert result.armed, result.reason
    m1, m2 = M739_TRAIN.mesh1, M739_TRAIN.mesh2
    for mesh, pitch, position in ((1, m1.pinion_pitch, 3), (2, m2.pinion_pitch, 0)):
        at = [
            row[position] for k, row in enumerate(seen) if k > 0 and row[mesh] != seen[k - 1][mesh]
        ]
        assert len(at) >= 4, mesh
        gaps = np.abs(np.diff(at))
        assert gaps == pytest.approx(pitch, abs=1e-9), mesh


def test_sticks_between_the_friction_limits_and_backdrives_beyond() -> None:
    phys = ClockTrainPhysics(mu=0.1)
    _at(phys, 0.0, 1)
    t_forward = phys.response(0.0, 0.0)[1]
    _at(phys, 0.0, -1)
    t_backward = phys.response(0.0, 0.0)[1]
    assert t_backward > t_forward > 0.0  # friction opposes either motion
    held = _train(-0.5 * (t_forward + t_backward), mu=0.1)
    held.step(0.0, 1e-4)
    assert held.regime == STUCK and held.phi == 0.0 and held.phi_dot == 0.0
    pushed = _train(-1.2 * t_backward, mu=0.1)
    pushed.step(0.0, 1e-4)
    assert pushed.regime != STUCK and pushed.phi < 0.0 and pushed.phi_dot < 0.0


def test_bad_parameters_are_refused() -> None:
    for bad in ({"loss_model": 5}, {"h_max": 0.0}, {"tolerance": 0.0}, {"pivot_loads": 0.5}):
        with pytest.raises(ComponentError):
            ClockGearTrain(**bad).initialize(0.0)
    for cd in (0.001 * INCH, 0.3 * INCH):  # pivot off R4 / tip never reaches the corner
        with pytest.raises(ComponentError, match="center_distance"):
            VergeEscapement(center_distance=cd).initialize(0.0)


def test_lossless_model_ignores_the_friction_signs() -> None:
    a = ClockTrainPhysics(mu=0.0)
    b = ClockTrainPhysics(mu=0.2, loss_model=LOSS_NONE, pivot_loads=False)
    for phi in PHIS[:10]:
        _at(a, phi)
        _at(b, phi)
        assert a.response(phi, 300.0) == b.response(phi, 300.0)


# ---------------------------------------------------------------------------------------
# Verge centre distance
# ---------------------------------------------------------------------------------------
def test_verge_center_distance_default_is_the_m739() -> None:
    assert VergeEscapement.variable("center_distance").start == M739_ESCAPEMENT_CD == M739.a
    assert escapement_data(M739_ESCAPEMENT_CD) is M739
    assert M739_CD_SWEEP[4] == M739_ESCAPEMENT_CD
    default, explicit = VergeEscapement(), VergeEscapement(center_distance=M739_ESCAPEMENT_CD)
    for v in (default, explicit):
        v.J_ref, v.T_ref = 2.8e-9, 1.0e-2
        v.initialize(0.0)
        for k in range(20):
            v.step(k * 1e-5, 1e-5)
    names = [x.name for x in VergeEscapement.variables("output")]
    assert default.values(names) == explicit.values(names)


def test_verge_geometry_follows_the_center_distance() -> None:
    cd = float(M739_CD_SWEEP[-1])
    v = VergeEscapement(center_distance=cd)
    v.initialize(0.0)
    d = escapement_data(cd)
    assert d.a == cd and d.b == M739.b and d.c == M739.c
    psi = kinem(M739.phi_start, M739.alpha_en, cd, M739.b, M739.c)[0]
    assert v.psi_local == psi
    nominal = VergeEscapement()
    nominal.initialize(0.0)
    assert nominal.psi_local != psi
    # The pallet pivot stays at R4 from the spin axis: its fuze-body angles follow a.
    assert v._core.k.beta3 != nominal._core.k.beta3


# ---------------------------------------------------------------------------------------
# Coupled scenes
# ---------------------------------------------------------------------------------------
def test_arming_angle_by_forward_kinematics() -> None:
    phys = ClockTrainPhysics()
    phi = arming_phi(phys)
    phys.set_mode(phi, 1)
    assert phys.rotor_angle(phi) == pytest.approx(ARMING_ROTOR_ANGLE, abs=1e-12)
    assert math.degrees(phi) == pytest.approx(1485.0, abs=3.0)  # the 32:1 mean, rippled


#: Energy residual of the first 2.5 ms under either scheme of the regime-aware master
#: (measured: midpoint hold 4.3e-5; single pass 3.0e-5 with the train's reduced model in
#: the verge, 2.5e-4 before it).
RESIDUAL = 1e-4


@pytest.mark.parametrize("hold", ["extrapolated", "midpoint"])
def test_short_coupled_run_through_the_orchestrator(
    tmp_path: Path, fmu_cache: Path, hold: str
) -> None:
    scene = load_scene(SCENE, {"scene.stop": "2.5 ms", "master.input_hold": hold})
    r = run_scene(scene, output_dir=tmp_path, cache_dir=fmu_cache, show_progress=False)
    assert r.status == "completed", r.message
    assert r.value("armed") == 0.0
    assert r.value("impacts") >= 4 and r.value("handovers") >= 1
    acc = r.accuracy
    assert acc["headline_error.impacts"] == 0.0
    # The reference is sampled every 10 us and interpolated linearly across the impact speed
    # jumps (~500 rad/s): about 1e-3 rad of phi, relative to the 2.5 ms travel here.
    assert acc["trajectory_error"] < 3e-3
    assert acc["event_time_error"] < 1e-5
    assert r.value("energy_residual") < RESIDUAL
    assert (tmp_path / "clock_train_sa.png").stat().st_size > 10_000
    ratio = r.signal("train.speed_ratio")
    assert 0.8 * 32 < ratio.min() < 32 < ratio.max() < 1.2 * 32


def test_sweep_scene_is_the_same_scene_over_the_tolerance_band() -> None:
    base, sweep = load_scene(SCENE), load_scene(SWEEP_SCENE)
    assert sweep.sweep is not None and base.sweep is None
    assert sweep.sweep.parameter == "fmus.verge.parameters.center_distance"
    assert np.allclose(sweep.sweep.si_values, M739_CD_SWEEP, rtol=0, atol=1e-12)
    assert "turns_to_arm" in sweep.sweep.quantities
    assert sweep.fmus == base.fmus and sweep.connections == base.connections
    assert sweep.stop_when == base.stop_when


@pytest.mark.slow
@pytest.mark.parametrize("hold", ["auto", "midpoint"])  # auto: the single pass here
def test_full_arming_run_matches_the_monolithic_reference(tmp_path, fmu_cache, hold) -> None:
    scene = load_scene(SCENE, {"master.input_hold": hold})
    r = run_scene(scene, output_dir=tmp_path, cache_dir=fmu_cache, show_progress=False)
    assert r.status == "completed" and r.value("armed") == 1.0
    acc = r.accuracy
    assert acc["headline_error.turns_to_arm"] < 1e-3
    assert acc["headline_error.impacts"] == 0.0
    assert r.value("energy_residual") < 1e-4
    # Same rotor travel, drive and escapement as the M739 (25.92 turns): the clock train's
    # ratio ripple, handover impacts and friction model move it by a few per cent only.
    assert r.value("turns_to_arm") == pytest.approx(25.92, rel=0.1)


@pytest.mark.slow
def test_turns_to_arm_fall_as_the_escapement_center_distance_grows() -> None:
    """The test plans' response (turns to arm, Test Plan 2) over the assumed band, monolithic
    models: turns fall monotonically with the centre distance, with the relative sensitivity of
    the M739's involute train (same escapement, same rotor travel) within 20 %."""
    turns = [run_clock_train(center_distance=float(cd)).turns for cd in M739_CD_SWEEP]
    assert all(t is not None for t in turns)
    assert all(b < a for a, b in zip(turns, turns[1:], strict=False)), turns
    involute = [run_m739(data=escapement_data(float(M739_CD_SWEEP[i]))).turns for i in (0, -1)]
    clock_rel = (turns[-1] - turns[0]) / turns[4]
    involute_rel = (involute[1] - involute[0]) / run_m739().turns
    assert clock_rel < 0.0 and involute_rel < 0.0
    assert clock_rel / involute_rel == pytest.approx(1.0, abs=0.2), (clock_rel, involute_rel)


def test_a_crossing_exactly_on_a_piece_bound_moves_on(monkeypatch) -> None:
    """An event that fires at a step start with its indicator exactly zero (the step began
    on the bound) moves to the piece beyond; staying would fire it again without end."""
    phys = ClockTrainPhysics(mu=0.1, loss_model=LOSS_POINT)
    phys.set_mode(PHIS[0], 1)
    pieces = phys.pieces
    ahead = lambda phi: phys.piece_distances(phi)[2]  # noqa: E731  mesh 2, forward
    lo, hi = PHIS[0], PHIS[0]
    while ahead(hi) >= 0.0:
        lo, hi = hi, hi + 1e-3
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if ahead(mid) >= 0.0 else (lo, mid)
    offset = ahead(lo)  # >= 0, within rounding of the bound: shift it to exactly zero
    real = phys.piece_distances

    def on_the_bound(phi: float) -> tuple[float, float, float, float]:
        a1, b1, a2, b2 = real(phi)
        return a1, b1, a2 - offset, b2 + offset

    monkeypatch.setattr(phys, "piece_distances", on_the_bound)
    assert phys.piece_distances(lo)[2] == 0.0
    phys.cross(lo, 700.0)
    assert phys.pieces[1] != pieces[1]
    assert phys.piece_distances(lo)[2] > 0.0
