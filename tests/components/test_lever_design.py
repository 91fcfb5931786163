"""Monday's deck as the lever's design parameters, each rule of his model refused at FMU
initialization in one line, and an asymmetric deck against independent solutions."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from components.base import ComponentError
from components.design_rules import DesignError
from components.detached_lever import (
    ANGLE_SWITCHED,
    PHASE_SCHEDULED,
    DetachedLever,
    deck_amplitudes,
    phase_amplitudes,
)
from components.detached_lever_design import SEGMENTS, WINDOWS, LeverDesign, violations

INERTIA = DetachedLever().inertia
DRIVE = DetachedLever().drive_torque  # the worked example's impulse torque, 1245.8 I


def test_every_card_quantity_is_a_design_parameter_named_after_monday() -> None:
    params = {v.name: v for v in DetachedLever.variables("parameter")}
    for s in SEGMENTS:
        v = params[s.coulomb]
        assert v.design and v.unit == "N.m" and v.description.endswith(f"[Monday: R({s.n})]")
    for s in WINDOWS:
        v = params[s.ratio]
        assert v.design and v.unit == "1" and v.description.endswith(f"[Monday: X({s.n})]")
    for name, symbol in (("alpha", "ALPHA"), ("gamma", "GAMA"), ("mu", "AMU"), ("sigma", "SIGMA")):
        assert params[name].description.endswith(f"[Monday: {symbol}]")


def test_the_defaults_are_the_worked_example_cards() -> None:
    # Card deck of the Ch. IV example (Monday 1965, pp. 39-45): R(1..5) = 305.546,
    # R(6..10) = -305.546; X(2) X(3) X(4) X(7) X(8) X(9) = 143.41 -1245.8 -1245.8 -143.41
    # 1245.8 1245.8 (s^-2).
    lever = DetachedLever()
    for s in SEGMENTS:
        expected = 305.546 if s.n <= 5 else -305.546
        assert getattr(lever, s.coulomb) / INERTIA == pytest.approx(expected, rel=1e-14)
    card5 = {2: 143.41, 3: -1245.8, 4: -1245.8, 7: -143.41, 8: 1245.8, 9: 1245.8}
    for n, x in card5.items():
        ratio = getattr(lever, next(s.ratio for s in WINDOWS if s.n == n))
        assert ratio * DRIVE / INERTIA == pytest.approx(x, rel=1e-14)


def refused(**params: float) -> str:
    lever = DetachedLever(**params)
    with pytest.raises(DesignError) as info:
        lever.initialize(0.0)
    message = str(info.value)
    assert "\n" not in message
    return message


# -- one test per rule --------------------------------------------------------------------
def test_rule_balance_and_hairspring() -> None:
    m = refused(stiffness=0.0)
    assert m.startswith("design rule 'balance and hairspring' broken: ")
    assert "K0 = 0 N.m/rad; expected both > 0" in m


def test_rule_underdamped_balance() -> None:
    # C = 2 OMEGO = 32.348 1/s: omega1 = sqrt(4 OMEGO^2 - C^2) / 2 is zero (App. A)
    m = refused(viscous=INERTIA * 2 * 16.174)
    assert m.startswith("design rule 'underdamped balance' broken: C = 32.348 1/s")
    assert "expected C < 2 OMEGO" in m


def test_rule_windows_ordered() -> None:
    m = refused(gamma=0.7)
    assert m == (
        "design rule 'windows ordered' broken: moving positive: GAMA = 0.7 rad, "
        "SIGMA = 0.6338 rad; expected 0 <= GAMA <= SIGMA (the unlock ends where the impulse "
        "begins)"
    )


def test_rule_windows_within_a_quarter_cycle() -> None:
    m = refused(alpha=0.3, epsilon=1.6)
    assert m.startswith("design rule 'windows within a quarter cycle' broken: EPIL = 1.6 rad")
    assert "expected 0 <= EPIL <= pi/2" in m


def test_rule_release_at_a_positive_extreme() -> None:
    # the phase schedule starts at psi = 0: at rest at a positive extreme beyond the unlock
    m = refused(omega_start=1.0)
    assert m.startswith("design rule 'release at a positive extreme' broken: THETO = 6.28 rad, ")
    assert "omega_start = 1 rad/s" in m
    m = refused(theta_start=-3.0)
    assert "THETO = -3 rad" in m and "expected THETO > max(EPIL, SIGMA) = 0.6338 rad" in m


def test_rule_windows_inside_the_swing() -> None:
    m = refused(switching_mode=ANGLE_SWITCHED, theta_start=0.3, sigma=0.7)
    assert m.startswith(
        "design rule 'windows inside the swing' broken: start amplitude "
        "sqrt(theta_start^2 + (omega_start/OMEGO)^2) = 0.3 rad, max(EPIL, SIGMA) = 0.7 rad"
    )
    # a swing that passes the unlock from the dead point is fine
    DetachedLever(switching_mode=ANGLE_SWITCHED, theta_start=0.0, omega_start=20.0).initialize(0)


def test_rule_friction_opposes_the_motion() -> None:
    m = refused(coulomb_7=+1e-7)
    assert m.startswith("design rule 'friction opposes the motion' broken: R(7) = ")
    assert "in segment 7 (moving positive); expected <= 0" in m


def test_rule_unlock_resists_the_motion() -> None:
    m = refused(unlock_ratio_2=-0.1)
    assert m == (
        "design rule 'unlock resists the motion' broken: X(2) = -0.1 x drive_torque / I "
        "(unlock_ratio_2 = -0.1) in segment 2 (moving negative); expected unlock_ratio_2 >= 0"
    )


def test_rule_impulse_drives_the_motion() -> None:
    m = refused(impulse_ratio_9=-1.0)
    assert m.startswith("design rule 'impulse drives the motion' broken: X(9) = -1 x ")
    assert "expected impulse_ratio_9 >= 0" in m


def test_rule_lever_gives_net_work() -> None:
    # phase-scheduled: impulse |X3| sin(alpha) + |X4| sin(beta) against the unlock
    # |X2| (sin(epsilon) - sin(alpha)), per drive torque / INERTIA (theta = Theta cos psi)
    m = refused(impulse_ratio_3=-0.1, impulse_ratio_4=-0.1, unlock_ratio_2=0.9)
    impulse = 0.2 * math.sin(0.2787)
    unlock = 0.9 * (math.sin(0.6338) - math.sin(0.2787))
    assert m.startswith("design rule 'lever gives net work' broken: moving negative: ")
    assert f"= {impulse:.6g}, unlock |X(2)|" in m and f"= {unlock:.6g} (per" in m
    # angle-switched: the windows' widths, 0.2 alpha against 0.9 (epsilon - alpha)
    m = refused(switching_mode=ANGLE_SWITCHED, impulse_ratio_8=0.1, impulse_ratio_9=0.1,
                unlock_ratio_7=-0.9)  # fmt: skip
    assert f"= {0.2 * 0.2787:.6g}, unlock |X(7)| (SIGMA - GAMA) = {0.9 * 0.3551:.6g}" in m


def test_violations_lists_every_broken_rule() -> None:
    params = {v.name: v.start for v in DetachedLever.variables("parameter")}
    params.update(coulomb_1=-1.0, impulse_ratio_8=-1.0, gamma=0.7)
    rules = [v.rule for v in violations(LeverDesign.of(params))]
    assert rules == ["windows ordered", "friction opposes the motion", "impulse drives the motion"]


# -- asymmetric decks against independent solutions ----------------------------------------
ASYMMETRIC = {
    "beta": 0.25, "gamma": 0.30, "sigma": 0.66,
    "coulomb_2": INERTIA * 320.0, "coulomb_7": -INERTIA * 320.0,
    "impulse_ratio_4": -1100.0 / 1245.8, "unlock_ratio_7": -120.0 / 1245.8,
    "impulse_ratio_8": 1200.0 / 1245.8,
}  # fmt: skip


def _forcing(lever: DetachedLever, n: int) -> float:
    s = SEGMENTS[n - 1]
    x = getattr(lever, s.ratio) * lever.drive_torque if s.ratio else 0.0
    return (getattr(lever, s.coulomb) + x) / lever.inertia


def test_phase_scheduled_asymmetric_deck_against_ode_integration() -> None:
    # theta'' + C theta' + OMEGO^2 theta = F(n) with F switched on the phase psi = omega1 t
    # (Table III), integrated numerically over three cycles: theta at each cycle end.
    lever = DetachedLever(**ASYMMETRIC)
    lever.initialize(0.0)
    assert len(lever._schedule) == 10  # both impulses change at the dead point
    c = lever.viscous / INERTIA
    w0sq = lever.stiffness / INERTIA
    w1 = math.sqrt(w0sq - c * c / 4)
    p = math.pi / 2
    a, b, g, m, e, s = (lever.alpha, lever.beta, lever.gamma, lever.mu, lever.epsilon,
                        lever.sigma)  # fmt: skip
    bounds = [0, p - e, p - a, p, p + b, 2 * p, 3 * p - s, 3 * p - g, 3 * p, 3 * p + m, 4 * p]
    theta, omega, ends = 6.28, 0.0, []
    for _cycle in range(3):
        for n in range(1, 11):
            f = _forcing(lever, n)
            sol = solve_ivp(
                lambda t, y, f=f: [y[1], f - c * y[1] - w0sq * y[0]],
                (bounds[n - 1] / w1, bounds[n] / w1), [theta, omega],
                rtol=1e-12, atol=1e-13, method="DOP853",
            )  # fmt: skip
            theta, omega = sol.y[:, -1]
        ends.append(theta)
    lever.step(0.0, 3 * 2 * math.pi / w1 + 1e-9)
    assert lever.cycle_count == 3
    assert lever.cycle_end_angle == pytest.approx(ends[-1], abs=1e-8)
    # and the closed-form cycle map of the same deck (derived from Table III)
    forcing = tuple(_forcing(lever, n) for n in range(1, 11))
    amps = deck_amplitudes(6.28, 3, c=c, omega0=math.sqrt(w0sq), forcing=forcing, alpha=a,
                           epsilon=e, beta=b, gamma=g, mu=m, sigma=s)  # fmt: skip
    np.testing.assert_allclose(amps[1:], ends, atol=1e-8)


def test_a_symmetric_deck_keeps_the_thesis_map_exactly() -> None:
    lever = DetachedLever()
    lever.initialize(0.0)
    assert len(lever._schedule) == 8  # the impulse halves are alike: one step each side
    forcing = tuple(_forcing(lever, n) for n in range(1, 11))
    common = {"c": 0.833, "omega0": 16.174, "alpha": 0.2787, "epsilon": 0.6338}
    by_deck = deck_amplitudes(6.28, 5, forcing=forcing, **common)
    by_magnitudes = phase_amplitudes(6.28, 5, r=305.546, x_unlock=143.41, x_impulse=1245.8,
                                     **common)  # fmt: skip
    np.testing.assert_allclose(by_deck, by_magnitudes, rtol=1e-13)
    assert by_deck[1] == pytest.approx(5.548613, abs=1e-6)  # the worked example's cycle 1


def test_angle_switched_asymmetric_impulse_gives_its_exact_work() -> None:
    # Without damping and friction a half swing from rest at A ends at rest at A' with
    # k (A'^2 - A^2) / 2 = T (|r3| alpha + |r4| beta - |r2| (epsilon - alpha)): the work of
    # each window, its torque times its angle (the impulse switches at the dead point).
    params = {**ASYMMETRIC, "viscous": 0.0, "switching_mode": ANGLE_SWITCHED, "theta_start": 3.0}
    for s in SEGMENTS:
        params[s.coulomb] = 0.0
    lever = DetachedLever(**params)
    lever.initialize(0.0)
    assert lever._split == {3, 8}
    t = lever.advance_to_next_beat(0.0, 10.0)
    T, k = lever.drive_torque, lever.stiffness
    work = T * (1.0 * 0.2787 + 1100 / 1245.8 * 0.25 - 143.41 / 1245.8 * (0.6338 - 0.2787))
    assert lever.theta == pytest.approx(-math.sqrt(9.0 + 2 * work / k), rel=1e-12)
    assert lever.drive_work == pytest.approx(work, rel=1e-12)
    a1 = -lever.theta
    lever.advance_to_next_beat(t, 10.0)
    work = T * (1200 / 1245.8 * 0.30 + 1.0 * 0.2787 - 120 / 1245.8 * (0.66 - 0.30))
    assert lever.theta == pytest.approx(math.sqrt(a1 * a1 + 2 * work / k), rel=1e-12)


def test_an_unknown_switching_mode_is_refused() -> None:
    with pytest.raises(ComponentError, match="unknown switching_mode 2"):
        DetachedLever(switching_mode=PHASE_SCHEDULED + 2).initialize(0.0)
