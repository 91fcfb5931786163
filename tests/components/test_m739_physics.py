"""M739 S&A physics (Lowen & Tepper 1982): geometry, algebra, split exactness, reference.

Targets come from the report (ARLCD-TR-82013): Output Data (pp. 11-13), the App. A sample output
and Conclusions; forces are compared in lb, the report's unit.
"""

from __future__ import annotations

import math

import pytest

from components.gear_train import (
    INDEXING_AS_RUN,
    GearTrain,
    TrainPhysics,
)
from components.m739_data import DEG, INCH, LBF, M739, TORQUE_US
from components.verge_escapement import (
    COUPLED_ENTRANCE,
    COUPLED_EXIT,
    ENTRANCE,
    EXIT,
    FREE,
    HeldTrain,
    VergeConstants,
    VergeCore,
    VergeEscapement,
    contact_coefficients,
    coupled_phi_ddot_b176,
)
from components.verge_geometry import (
    contact_sensing,
    face_arms,
    fuze_angles,
    impact_map,
    kinem,
    normal_velocities,
)
from orchestrator.scenes.m739.monolithic import REFERENCE_TOLERANCE, run_m739


def rel(a: float, b: float) -> float:
    return abs(a - b) / abs(b)


# -- geometry and data ----------------------------------------------------------------
def test_fuze_angles():
    ang = fuze_angles(M739)
    assert ang.beta1 / DEG == pytest.approx(218.87, abs=0.01)
    assert ang.beta2 / DEG == pytest.approx(134.90, abs=0.01)
    assert ang.beta3 / DEG == pytest.approx(92.11, abs=0.01)
    # Printed without minus signs (OCR); configuration 2 measures clockwise.
    assert ang.gamma2 / DEG == pytest.approx(-111.47, abs=0.01)
    assert ang.gamma3 / DEG == pytest.approx(-155.09, abs=0.01)
    assert ang.gamma_pp / DEG == pytest.approx(249.549, abs=0.001)


def test_derived_data():
    assert M739.n31 == pytest.approx(1.0 / 32.0)
    assert M739.n32 == pytest.approx(-2.0 / 9.0)
    assert M739.i_stot / TORQUE_US == pytest.approx(2.5159e-8, rel=1e-4)  # in.lb.s^2
    tp = TrainPhysics(M739)
    assert tp.t2 / LBF == pytest.approx(10.246, rel=1e-4)
    assert tp.t3 / LBF == pytest.approx(8.0238, rel=1e-4)
    assert tp.a35 / TORQUE_US == pytest.approx(4.4982, rel=1e-4)
    # Unity contact ratio meshes (Input Data, pp. 7-11; subroutine ALFA, App. A).
    assert tp.al1_in == pytest.approx(0.36512, abs=2e-5)
    assert tp.al1_fin == pytest.approx(0.46323, abs=2e-5)
    assert tp.al2_in == pytest.approx(0.38774, abs=2e-5)
    assert tp.al2_fin == pytest.approx(0.56209, abs=2e-5)


def test_start_kinematics_and_v_is_du_dphi():
    d = M739
    psi, g, u, v, a1p, b1p, d1p = kinem(d.phi_start, d.alpha_en, d.a, d.b, d.c)
    assert psi / DEG == pytest.approx(42.081, abs=0.001)
    assert g / INCH == pytest.approx(0.022234, rel=1e-4)
    assert u == pytest.approx(0.8530, abs=1e-4)
    assert v == pytest.approx(1.371, abs=1e-3)
    assert (a1p / INCH, b1p / INCH, d1p / INCH) == pytest.approx(
        (0.10020, 0.13484, 0.11748), abs=1e-5
    )
    # C26 with the corrected sign: V = dU/dphi (both faces).
    for phi, alpha in ((d.phi_start, d.alpha_en), (212.5 * DEG, d.alpha_ex)):
        eps = 1e-6
        up = kinem(phi + eps, alpha, d.a, d.b, d.c)[2]
        um = kinem(phi - eps, alpha, d.a, d.b, d.c)[2]
        assert kinem(phi, alpha, d.a, d.b, d.c)[3] == pytest.approx((up - um) / (2 * eps), rel=1e-6)
    # On the face the gap f (E4) vanishes and g' (E5) equals g.
    f, gp = contact_sensing(d.phi_start, psi, d.alpha_en, d.a, d.b, d.c)
    assert f == pytest.approx(0.0, abs=1e-15)
    assert gp == pytest.approx(g, rel=1e-12)


# -- t = 0 algebra --------------------------------------------------------------------
def _core_at(phi_t: float, phi_dot: float, phi_local: float, face: int, train: TrainPhysics):
    k = VergeConstants(M739, M739.mu1, M739.mu, M739.omega, 0.0)
    held = HeldTrain(*train.response(phi_t, phi_dot), M739.i_stot)
    held.direction = train.direction
    core = VergeCore(k, held, phi_local - phi_t, face=face)
    if face == EXIT:
        core.psic = M739.psic + M739.lam
    y = core._sync_kinematics([phi_t, phi_dot, 0.0, 0.0, 0.0])
    return core, y


def test_t0_algebra():
    """The report's first printed row (App. A sample output): s1 = s2 = s4 = s5 = +1."""
    train = TrainPhysics(M739)
    core, y = _core_at(0.0, 0.0, M739.phi_start, ENTRANCE, train)
    acc, _, _, _, pn, *_ = core.coupled_terms(y)
    f12, f23 = train.forces(0.0, 0.0, acc)
    assert rel(acc, 1.568e6) < 1e-3
    assert rel(f23 / LBF, 2.4663) < 1e-3
    assert rel(f12 / LBF, 9.6322) < 1e-3
    assert rel(pn / LBF, 0.3312) < 1e-3
    # Second row (phi_dot = 6.35, sliding: s4 = -1): .1212E+07, 2.5031, 9.6925, .3305.
    core.s4 = -1
    y = core._sync_kinematics([0.0, 6.35, 0.0, 0.0, 0.0])
    acc, _, _, _, pn, *_ = core.coupled_terms(y)
    f12, f23 = train.forces(0.0, 6.35, acc)
    assert rel(acc, 1.212e6) < 2e-3
    assert rel(f12 / LBF, 9.6925) < 1e-3
    assert rel(pn / LBF, 0.3305) < 3e-3


def test_t0_through_components():
    train = GearTrain()
    train.initialize(0.0)
    verge = VergeEscapement(phi_local_start=M739.phi_start)
    for n in ("phi", "phi_dot", "J_ref", "T_ref", "c_load", "J_stot"):
        setattr(verge, n, getattr(train, n))
    verge.initialize(0.0)
    assert verge.regime == COUPLED_ENTRANCE
    assert rel(verge.phi_ddot, 1.568e6) < 1e-3
    assert rel(verge.PN / LBF, 0.3312) < 1e-3
    train.T_esc = verge.T_esc
    train.step(0.0, 0.0)  # refresh outputs with the escapement load
    assert rel(train.phi_ddot, verge.phi_ddot) < 1e-12
    assert rel(train.F23 / LBF, 2.4663) < 1e-3
    assert rel(train.F12 / LBF, 9.6322) < 1e-3


# -- split exactness ------------------------------------------------------------------
STATES = [
    # (phi_T [deg], phi_dot, phi_local [deg], face)
    (0.0, 0.0, 139.0, ENTRANCE),
    (3.7, 250.0, 141.2, ENTRANCE),
    (412.0, 610.0, 144.1, ENTRANCE),
    (7.4, 120.0, 211.9, EXIT),
    (801.3, 380.0, 213.4, EXIT),
    (1300.0, 455.0, 215.0, EXIT),
]


@pytest.mark.parametrize("phi_t_deg, phi_dot, phi_loc_deg, face", STATES)
def test_split_equals_b176(phi_t_deg, phi_dot, phi_loc_deg, face):
    """Verge with the train's affine response == monolithic B176 (A45-A50), 1e-12."""
    phi_t = phi_t_deg * DEG
    train = TrainPhysics(M739)
    train.set_mode(phi_t, 1)
    train.i1r_sign = -1 if phi_t_deg > 1000 else 1  # both I1R branches
    core, y = _core_at(phi_t, phi_dot, phi_loc_deg * DEG, face, train)
    k = core.k
    phi_l = phi_t + core.phi_off
    psi, g, u, v, a1p, b1p, d1p = kinem(phi_l, core.alpha, k.a, k.b, k.c)
    vst = -(phi_dot * b1p + u * phi_dot * k.c * math.sin(core.alpha))
    core.s4 = -1 if vst < 0 else 1
    core.s5 = -1 if u * phi_dot < 0 else 1
    acc_split, _, _, _, pn, t_esc, *_ = core.coupled_terms(y)
    a17, a18 = contact_coefficients(k, face, psi, core.s4, core.s5, 1, a1p, b1p, d1p)
    a19, a20, a22 = k.pivot(core.s5, psi + core.psic)
    ipr = k.ip + a22
    acc_b176 = coupled_phi_ddot_b176(
        train.coefficients(phi_t),
        a17,
        a18,
        ipr,
        a20,
        core.s5 * a20,
        a19,
        u,
        v,
        phi_dot,
        psi,
        core.psic,
        k,
        train.t2,
        train.t3,
        M739.i2,
        M739.i3,
        M739.n31,
        M739.n32,
    )
    assert abs(acc_split - acc_b176) <= 1e-12 * abs(acc_b176)
    # The train's own equation, driven by T_esc, reproduces the same acceleration ...
    j_ref, t_ref, c_load = train.response(phi_t, phi_dot)
    assert (t_ref + c_load * t_esc) / j_ref == pytest.approx(acc_split, rel=1e-12)
    # ... and Pn from the wheel side (B96 / B185) equals Pn from the verge side (B76).
    c = train.coefficients(phi_t)
    f23 = train.forces(phi_t, phi_dot, acc_split)[1]
    pn_wheel = (-M739.i3 * acc_split + f23 * c["A15"] - train.t3 * c["A16"]) / a17
    assert pn_wheel == pytest.approx(pn, rel=1e-10)
    assert pn > 0.0


def test_free_train_matches_b193_b199():
    """phi_dd = T_ref/J_ref equals B193 (A55-A59) and F23 equals FF23 of B199."""
    train = TrainPhysics(M739)
    for phi_t, w in ((0.0, 0.0), (5.8 * DEG, 473.0), (1483.5 * DEG, 461.9)):
        train.set_mode(phi_t, 1)
        c = train.coefficients(phi_t)
        r = c["A15"] * c["A42"] / (c["A31"] * c["A44"])
        a55 = M739.i3 - c["A15"] * M739.n32 * M739.i2 / c["A44"] + r * M739.n31 * c["I1R"]
        a56 = r * c["A34"] * M739.n31**2
        a57 = r * c["A33"] * M739.n31
        a58 = -c["A16"] * train.t3 - c["A15"] * c["A43"] * train.t2 / c["A44"] - r * c["A32"]
        a59 = r * c["A35"]
        acc_b193 = (-a56 * w * w - a57 * w + a58 - a59 * c["sinPhi"]) / a55
        j, t, _ = train.response(phi_t, w)
        assert t / j == pytest.approx(acc_b193, rel=1e-12)
        f12, f23 = train.forces(phi_t, w, acc_b193)
        ff23 = (M739.i3 * acc_b193 + train.t3 * c["A16"]) / c["A15"]
        assert f23 == pytest.approx(ff23, rel=1e-12)


def test_free_verge_deceleration():
    """B187 with r_cp = 0: constant pivot-friction deceleration (App. B)."""
    k = VergeConstants(M739, 0.1, 0.1, M739.omega, 0.0)
    core = VergeCore(k, HeldTrain(2.8e-9, 0.0, 1.0, M739.i_stot), 0.0, coupled=False)
    for s5, psi_d, target in ((1, 400.0, -7.63e5), (-1, -400.0, 6.96e5)):
        core.s5 = s5
        assert rel(core.free_terms([0.0, 0.0, 5.5, psi_d, 0.0])[1], target) < 2e-3


# -- impact ---------------------------------------------------------------------------
def test_impact_map_report_state():
    """Exit impact of the sample output: (620.77, 456.64) -> (113.856, -127.482)."""
    phi, psi = 211.782 * DEG, 315.922 * DEG
    _, a1p, d1p = face_arms(phi, psi, M739.alpha_ex, M739.b, M739.c)
    vtn, vsn = normal_velocities(phi, psi, 620.77, 456.64, M739.alpha_ex, M739.b, M739.c)
    assert vtn / INCH == pytest.approx(47.109, rel=2e-3)
    assert vsn / INCH == pytest.approx(-71.706, rel=2e-3)
    phi_f, psi_f = impact_map(620.77, 456.64, a1p, d1p, M739.ip, M739.i_stot, 0.0)
    assert rel(phi_f, 113.86) < 2e-3
    assert rel(psi_f, -127.48) < 2e-3
    vtn_f, vsn_f = normal_velocities(phi, psi, phi_f, psi_f, M739.alpha_ex, M739.b, M739.c)
    assert vtn_f / INCH == pytest.approx(-13.15, rel=2e-3)
    assert vsn_f == pytest.approx(vtn_f, rel=1e-12)


def test_impact_map_restitution_and_momentum():
    phi, psi = 211.782 * DEG, 315.922 * DEG
    _, a1p, d1p = face_arms(phi, psi, M739.alpha_ex, M739.b, M739.c)
    for e in (0.0, 0.4, 1.0):
        phi_f, psi_f = impact_map(620.77, 456.64, a1p, d1p, M739.ip, M739.i_stot, e)
        # B205: angular momentum balance; B210: V_TNf - V_SNf = -e (V_TNi - V_SNi).
        lhs = M739.ip * a1p * psi_f + M739.i_stot * d1p * phi_f
        rhs = M739.ip * a1p * 456.64 + M739.i_stot * d1p * 620.77
        assert lhs == pytest.approx(rhs, rel=1e-12)
        assert d1p * psi_f - a1p * phi_f == pytest.approx(
            -e * (d1p * 456.64 - a1p * 620.77), rel=1e-9, abs=1e-12
        )


# -- reference runs -------------------------------------------------------------------
@pytest.fixture(scope="module")
def nominal():
    return run_m739()


def test_turns_to_arm(nominal):
    assert nominal.armed, nominal.reason
    assert rel(nominal.turns, 25.78) < 0.01
    assert nominal.series["phi"][-1] == pytest.approx(M739.phi_cut, abs=1e-6)


def test_force_maxima(nominal):
    assert rel(nominal.f23_max / LBF, 3.24) < 0.02
    assert rel(nominal.f12_max / LBF, 11.41) < 0.02
    assert rel(nominal.ff23_max / LBF, 2.93) < 0.02
    assert rel(nominal.ff12_max / LBF, 10.94) < 0.02
    assert rel(nominal.pn_max / LBF, 0.66) < 0.05


def test_impacts_and_regime_log(nominal):
    assert abs(nominal.impacts - 181) <= 1
    log = nominal.regime_log
    exit_contacts = sum(1 for _, a, b in log if (a, b) == (FREE, COUPLED_EXIT))
    entrance_contacts = sum(1 for _, a, b in log if (a, b) == (FREE, COUPLED_ENTRANCE))
    assert (exit_contacts, entrance_contacts) == (91, 90)
    assert log[0][1:] == (COUPLED_ENTRANCE, FREE)
    assert log[0][0] == pytest.approx(0.41e-3, rel=0.05)
    assert log[1][1:] == (FREE, COUPLED_EXIT)
    times = [t for t, _, _ in log]
    assert times == sorted(times)
    # Every coupled phase ends by the tooth leaving the face end (derived; OUTP's g test, App. A).
    whys = {why for _, a, b, why in nominal.events if a != FREE and b == FREE}
    assert whys == {"tooth left the face end (g = 0)"}


# Turns to arm of the converged monolithic model at 30,000 rpm, mu1 = 0.1 (measured).  With
# per-pitch hand-over they differ from the former range-per-cycle rule by 1.8e-4 (train
# mu = 0.1) and 1.6e-4 (mu1 = 0); without train friction the hand-over carries no load
# difference and the value is the former one to 1e-9 (20.651031036 before the change).
TURNS_NOMINAL = 25.914572675
TURNS_MU1_ZERO = 24.693435351
TURNS_TRAIN_FRICTIONLESS = 20.651031036


def test_turns_to_arm_with_per_pitch_hand_over(nominal):
    assert nominal.turns == pytest.approx(TURNS_NOMINAL, rel=1e-8)
    r = run_m739(mu1=0.0)
    assert r.armed, r.reason
    assert r.turns == pytest.approx(TURNS_MU1_ZERO, rel=1e-8)


def test_frictionless_train_does_not_depend_on_the_hand_over():
    physical = run_m739(mu=0.0)
    assert physical.turns == pytest.approx(TURNS_TRAIN_FRICTIONLESS, rel=1e-9)
    as_run = run_m739(mu=0.0, indexing=INDEXING_AS_RUN)
    assert as_run.turns == pytest.approx(physical.turns, rel=1e-8)


@pytest.fixture(scope="module")
def hand_overs(monkeypatch_module):
    """The nominal run with every mesh event recorded: (phi, n1, n2) after each one, and
    the train physics at the end."""
    seen: list[tuple[float, int, int]] = []
    trains: list[TrainPhysics] = []
    on_event, init = TrainPhysics.on_mesh_event, TrainPhysics.__init__

    def record(self, phi):
        on_event(self, phi)
        seen.append((phi, self.n1, self.n2))

    def keep(self, *args, **kwargs):
        init(self, *args, **kwargs)
        trains.append(self)

    monkeypatch_module.setattr(TrainPhysics, "on_mesh_event", record)
    monkeypatch_module.setattr(TrainPhysics, "__init__", keep)
    result = run_m739()
    return result, seen, trains[-1]


@pytest.fixture(scope="module")
def monkeypatch_module():
    with pytest.MonkeyPatch.context() as mp:
        yield mp


def test_hand_over_once_per_tooth_pitch(hand_overs):
    """Mesh 2 hands over every 2 pi/N_P3 = 45 deg of phi, mesh 1 every 2 pi/(N_P2 |N32|) =
    180 deg (Tepper 1981, eq. 24: one base pitch per cycle), over the whole run."""
    result, seen, train = hand_overs
    assert result.armed, result.reason
    pitch2 = 2.0 * math.pi / M739.np3
    pitch1 = 2.0 * math.pi / (M739.np2 * abs(M739.n32))
    assert pitch2 / DEG == pytest.approx(45.0, rel=1e-15)
    assert pitch1 / DEG == pytest.approx(180.0, rel=1e-15)
    for mesh, pitch, count in ((1, pitch1, 8), (2, pitch2, 33)):
        changes = [
            phi for k, (phi, *n) in enumerate(seen) if k > 0 and n[mesh - 1] != seen[k - 1][mesh]
        ]
        assert len(changes) == count, mesh
        for j, phi in enumerate(changes, start=1):
            assert phi == pytest.approx(j * pitch, abs=1e-9), (mesh, j)


def test_mesh_phase_at_arming_is_phi_modulo_the_pitch(hand_overs):
    """Arming (1485 deg = 33 x 45 deg) falls on a mesh-2 hand-over: both events fire, the
    run arms, and each roll angle is alpha_in + |N3i| (phi mod pitch) on the new pair."""
    result, _, train = hand_overs
    assert result.armed, result.reason
    phi = result.phi_end
    assert phi == pytest.approx(M739.phi_cut, abs=1e-9)
    assert (train.n1, train.n2) == (8, 33)
    al1, al2 = train.mesh_alphas(phi)
    pitch1 = 2.0 * math.pi / (M739.np2 * abs(M739.n32))
    pitch2 = 2.0 * math.pi / M739.np3
    assert al2 == pytest.approx(train.al2_in + abs(M739.n32) * (phi - 33 * pitch2), abs=1e-12)
    assert al1 == pytest.approx(train.al1_in + M739.n31 * (phi - 8 * pitch1), abs=1e-12)
    assert abs(phi - 33 * pitch2) < 1e-9  # on the hand-over itself


@pytest.mark.parametrize("mu, turns", [(0.05, 22.0), (0.15, 31.0)])
def test_friction_sensitivity(mu, turns):
    r = run_m739(mu=mu, mu1=mu)
    assert r.armed, r.reason
    assert abs(r.turns - turns) <= 0.5


def test_as_run_indexing_first_cycle():
    """The report's sample rows need the as-run mesh indexing rate (derived from App. A output)."""
    r = run_m739(indexing=INDEXING_AS_RUN, t_stop=0.6e-3)
    t_end_coupled, t_impact = r.regime_log[0][0], r.regime_log[1][0]
    assert t_end_coupled == pytest.approx(0.41e-3, rel=0.01)
    assert t_impact == pytest.approx(0.46e-3, rel=0.02)
    i = int(abs(r.series["t"] - 0.41e-3).argmin())
    assert r.series["phi_dot"][i] == pytest.approx(473.0, rel=0.02)


@pytest.mark.parametrize(
    "kwargs, reason",
    [
        (dict(t_stop=2e-3), "stop time reached"),
        (dict(mu=0.5, mu1=0.5), "stall"),
        (dict(mu1=0.8), "stall"),
        (dict(rpm=0.0), "no spin"),
    ],
)
def test_did_not_arm(kwargs, reason):
    r = run_m739(**kwargs)
    assert not r.armed
    assert r.turns is None
    assert reason in r.reason


@pytest.mark.slow
def test_turns_independent_of_spin_forces_scale():
    a = run_m739()
    b = run_m739(rpm=15000.0, t_stop=0.3)
    assert b.turns == pytest.approx(a.turns, rel=1e-6)
    assert b.f23_max == pytest.approx(a.f23_max / 4.0, rel=1e-6)
    assert b.impacts == a.impacts


def test_reference_converged_in_tolerance(nominal):
    """The monolithic model at its default tolerance and tenfold tighter: turns to arm
    agree to 1e-7 relative, the force maxima to 1e-6."""
    a = nominal
    b = run_m739(tolerance=REFERENCE_TOLERANCE / 10.0)
    assert b.turns == pytest.approx(a.turns, rel=1e-7)
    assert b.impacts == a.impacts
    for name in ("pn_max", "f23_max", "f12_max", "ff23_max", "ff12_max"):
        assert getattr(b, name) == pytest.approx(getattr(a, name), rel=1e-6), name


def test_mesh_event_moves_past_a_rounding_tie():
    """A crossing located just past a piece boundary in phi whose mesh phase rounds to the
    old side still moves the piece (else the next pitch point would never be seen)."""
    p = TrainPhysics(M739)
    p.set_mode(0.3, 1)
    edge = p.phi_hi
    p.on_mesh_event(edge)  # exactly on the boundary: phase ties are possible
    assert p.phi_lo <= edge < p.phi_hi
    assert p.mesh_indicators(edge)[0] > 0.0


# -- components -----------------------------------------------------------------------
def test_train_step_independent_of_communication_step():
    """Mesh events (tooth change, pitch point) are located inside the step: 1000 steps of
    1 us and 4 of 250 us agree to 1e-9 (the internal tolerance is set below that)."""
    fine, coarse = GearTrain(tolerance=1e-12), GearTrain(tolerance=1e-12)
    fine.initialize(0.0)
    coarse.initialize(0.0)
    flips = 0
    s2 = fine.s2
    for i in range(1000):
        fine.step(i * 1e-6, 1e-6)
        flips += fine.s2 != s2
        s2 = fine.s2
    for i in range(4):
        coarse.step(i * 2.5e-4, 2.5e-4)
    assert flips >= 2  # several pitch-point / tooth changes were crossed
    assert coarse.phi == pytest.approx(fine.phi, rel=1e-9)
    assert coarse.phi_dot == pytest.approx(fine.phi_dot, rel=1e-9)
    # Energy: friction only dissipates; without load the spin's work is stored or lost.
    assert 0.0 < coarse.dissipated_work < coarse.external_work
    total = coarse.stored_energy + coarse.dissipated_work
    assert total == pytest.approx(coarse.external_work, rel=1e-6)


def test_train_sticks_when_held_back():
    train = GearTrain()
    train.initialize(0.0)
    # An escapement moment half-way between the forward and backward break-away
    # moments: static friction holds the train.
    tp = TrainPhysics(M739)
    t_fwd = tp.response(0.0, 0.0)[1]
    tp.set_direction(-1, 0.0)
    t_bwd = tp.response(0.0, 0.0)[1]
    assert t_bwd > t_fwd  # friction opposes the motion in both directions
    train.T_esc = -0.5 * (t_fwd + t_bwd)
    train.step(0.0, 1e-5)
    assert train.regime == 0
    assert train.phi_dot == 0.0
    train.T_esc = 0.0
    train.step(1e-5, 1e-5)
    assert train.regime == 1 and train.phi_dot > 0.0


class _Master:
    """Minimal master for the two components: step to the verge's events, pass impacts."""

    def __init__(self, h: float) -> None:
        self.h = h
        self.train = GearTrain()
        self.train.initialize(0.0)
        self.verge = VergeEscapement()
        self.feed()
        self.verge.initialize(0.0)
        self.train.T_esc = self.verge.T_esc
        self.train.update_outputs()
        self.t = 0.0
        self.impacts = 0
        self.pn_max = 0.0

    def feed(self) -> None:
        tr, vg = self.train, self.verge
        for n in ("phi", "phi_dot", "J_ref", "T_ref", "c_load", "J_stot"):
            setattr(vg, n, getattr(tr, n))

    def impact(self) -> None:
        """Give a new impact to the train at once (feedthrough), as an event iteration."""
        tr, vg = self.train, self.verge
        if vg.impact_count != self.impacts:
            self.impacts = vg.impact_count
            tr.impact_count += 1
            tr.phi_dot_impact = vg.phi_dot_post
            tr.update_outputs()

    def step(self) -> None:
        tr, vg, t = self.train, self.verge, self.t
        self.feed()
        saved = vg.get_state()
        vg.step(t, self.h)
        h = self.h
        # Step both to the verge's first event inside the step.
        if t < vg.t_event < t + self.h * (1 - 1e-9):
            h = vg.t_event - t
            vg.set_state(saved)
            self.feed()
            vg.step(t, h)
        if vg.t_event == t:
            self.impact()  # fired at the step start: the train takes it before its step
        tr.step(t, h)
        self.t = t + h
        tr.T_esc = vg.T_esc
        tr.update_outputs()
        self.impact()
        self.pn_max = max(self.pn_max, vg.PN)

    def outputs(self) -> tuple[float, ...]:
        tr, vg = self.train, self.verge
        return (
            tr.phi,
            tr.phi_dot,
            tr.F23,
            vg.psi,
            vg.psi_dot,
            vg.PN,
            vg.T_esc,
            vg.regime,
            vg.dissipated_work,
            tr.dissipated_work,
        )


def test_components_state_roundtrip_bit_identical():
    m = _Master(5e-6)
    while m.t < 0.5e-3:
        m.step()
    snap = (m.train.get_state(), m.verge.get_state(), m.t, m.impacts)
    out1 = []
    for _ in range(60):
        m.step()
        out1.append(m.outputs())
    m.train.set_state(snap[0])
    m.verge.set_state(snap[1])
    m.t, m.impacts = snap[2], snap[3]
    out2 = []
    for _ in range(60):
        m.step()
        out2.append(m.outputs())
    assert out1 == out2
    assert len({o[7] for o in out1}) >= 2  # the window covers a regime change


def test_the_normal_force_peak_between_accepted_points_is_the_parabolas_vertex() -> None:
    """A peak between internal points is not missed by the square of the step."""
    from components.verge_escapement import _vertex

    def force(t: float) -> float:
        return 3.0 - 2.0 * (t - 0.4) ** 2

    points = [(t, force(t)) for t in (0.0, 0.5, 1.2)]
    assert max(p for _, p in points) < 2.99  # the accepted points alone
    assert _vertex(*points) == pytest.approx(3.0, rel=1e-14)
    # Rising or falling through the middle point, or not spanning time: no vertex.
    assert _vertex((0.0, 1.0), (0.5, 2.0), (1.0, 3.0)) == -math.inf
    assert _vertex((0.0, 1.0), (0.0, 2.0), (1.0, 1.0)) == -math.inf
