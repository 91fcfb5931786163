"""The press feed as a design: P1, F1 and the lumped-mass factor from the geometry (Xu 1993,
App. B, G, H), each consistency rule refused at FMU initialization in one named line, the
brake note."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from components.coupler_inertia import computed_inertia, coupler_frame, inertia_functions
from components.crank_coupler_drive import CrankCouplerDrive
from components.design_rules import DesignError
from components.press_feed_data import (
    APP_H_FOURIER,
    COUPLER_STANDARD,
    IN,
    LINKAGE_APP_H,
    LINKAGE_TABLE1,
    TABLE4,
)
from components.press_feed_rules import brake_note, engagement_minimum, sprag_violations
from components.sprag_clutch import MODEL_HERTZ, SpragClutch, two_point_hertz
from components.units import LBF_IN, RPM

C = COUPLER_STANDARD


def test_default_drive_keeps_the_printed_run1_constants() -> None:
    drive = CrankCouplerDrive(crank_speed=200 * RPM)
    drive.initialize(0.0)
    assert drive._m.f1 == APP_H_FOURIER.f1  # a10, a11, b11 of App. H to the bit
    assert drive.coupler().p1 == 2.65 * IN


def test_computed_f1_and_p1_of_run1_against_app_h() -> None:
    # App. H was computed with a1 = 0.955 in (press_feed_data); printed a10 = -0.03798,
    # a11 = 7.2439, b11 = -12.2350 in^2, P1 = 2.65 in (regime-2 mean), "near 0.05" per inch.
    ci = computed_inertia(LINKAGE_APP_H, C.alpha, C.length)
    a10, a11, b11 = (f / IN**2 for f in ci.f1)
    assert a11 == pytest.approx(7.2439, rel=6e-3)  # measured 0.48 %
    assert b11 == pytest.approx(-12.2350, rel=3e-3)  # measured 0.22 %
    assert a10 == pytest.approx(-0.03798, rel=4e-2)  # measured 3.3 %
    assert ci.p1 / IN == pytest.approx(2.65, rel=5.5e-2)  # measured 2.776 in (4.8 %)
    assert 0.045 < ci.lumped_factor * IN < 0.0566  # App. G: near 0.05, below 1/17.67
    assert ci.damping_factor == 3.0 - 8.0 / math.pi  # (B.7), printed rounded to 0.45
    # Table 1's a1 = 0.965 in brackets the printed a11 and b11 with a1 = 0.955 in.
    t1 = computed_inertia(LINKAGE_TABLE1, C.alpha, C.length)
    assert ci.f1[1] < 7.2439 * IN**2 < t1.f1[1]
    assert t1.f1[2] < -12.2350 * IN**2 < ci.f1[2]


def test_p1_is_the_printed_b17_with_the_a18_rotations() -> None:
    """The numerical P1 against (B.17) evaluated with eta2, eta32 of (A.16-A.18)."""
    lk, a, L = LINKAGE_TABLE1, C.alpha, C.length
    fn = inertia_functions(lk, a, L, n=64)
    phi1 = fn["phi1"]
    s, s2a, c2a, ca = math.sin(a), math.sin(2 * a), math.cos(2 * a), math.cos(a)
    big_a = 2 * lk.s1 * lk.a4
    big_b = 2 * lk.a4 * (lk.s3 + lk.a1 * np.sin(phi1))
    big_c = (lk.a4**2 + lk.s1**2 + lk.s2**2 + lk.s3**2 + lk.a1**2 - lk.a3**2) + 2 * lk.a1 * (
        lk.s2 * np.cos(phi1) + lk.s3 * np.sin(phi1)
    )
    p4 = 2 * np.arctan((big_a + np.sqrt(big_a**2 + big_b**2 - big_c**2)) / (big_b + big_c))
    p32 = np.arccos((lk.a4 * np.sin(p4) - lk.s1) / (lk.a3 * ca))  # (A.10)
    _, i1, j1 = coupler_frame(lk, a, phi1, 0.0)
    p2 = np.arctan2(j1[1], -j1[2])
    eta4 = -2 * lk.a3 / (big_a * np.cos(p4) - big_b * np.sin(p4))  # (A.16)
    eta32 = (ca * np.cos(p32) - lk.a4 * np.cos(p4) * eta4) / (lk.a3 * ca * np.sin(p32))
    eta2 = (ca * np.cos(p2) * (lk.a3 * np.cos(p32) * eta32 + np.sin(p32)) - s * np.sin(p2)) / (
        lk.a3 * (s * np.cos(p2) + ca * np.sin(p2) * np.sin(p32))
    )
    vs1x, vs2 = (2 / math.pi) ** 2, c2a - 1 + 2 / math.pi
    vs2x = 0.5 * (c2a - 1) - 4 / math.pi**2 + 2 / math.pi
    b17 = (
        4 * L**2 * s * np.sin(p32) * (vs1x + vs2x + s2a**2 + vs2 * c2a) * eta2
        + L**3 * (2 * s * np.sin(p32)) ** 2 * (5 / 3 + c2a) * eta2**2
        + (2 * s) ** 2 * L**3 * (4 / 3 + c2a + c2a**2 / 3) * eta32**2
        - s * s2a * np.cos(p32) * L**3 * (1 + 2 / 3 * c2a) * eta2 * eta32
    )
    assert np.max(np.abs(fn["p1"] - b17)) < 1e-3 * np.max(np.abs(b17))


def test_a_new_crank_gets_its_own_consistent_inertia() -> None:
    lk = replace(LINKAGE_TABLE1, a1=1.2 * IN)
    ci = computed_inertia(lk, C.alpha, C.length)
    base = computed_inertia(LINKAGE_TABLE1, C.alpha, C.length)
    # F1 is the coupler's inertia forcing: its first harmonic grows with the crank radius.
    assert math.hypot(*ci.f1[1:]) > 1.15 * math.hypot(*base.f1[1:])
    drive = CrankCouplerDrive(crank_speed=200 * RPM, a1=1.2 * IN, coupler_inertia=1)
    drive.initialize(0.0)
    assert drive._m.f1 == ci.f1 and drive.coupler().p1 == 2.65 * IN  # given p1 not used


def _refusal(**parameters: float) -> str:
    drive = CrankCouplerDrive(crank_speed=200 * RPM, **parameters)
    with pytest.raises(DesignError) as exc:
        drive.initialize(0.0)
    text = str(exc.value)
    assert "\n" not in text and "math domain" not in text
    return text


def test_rssr_that_does_not_assemble_is_refused() -> None:
    text = _refusal(a1=0.5)
    assert text.startswith("design rule 'RSSR assembly' broken: a1 = 19.685 in")
    assert "expected A^2 + B^2 - C^2 > 0 at every crank angle" in text


def test_chord_other_than_2_l_cos_alpha_is_refused() -> None:
    text = _refusal(a3=33.0 * IN)
    assert "'coupler chord'" in text and "a3 = 33.00000 in" in text
    assert "2 L cos(alpha) = 32.52341 in" in text  # 2 * 16.625 cos 12 deg (Table 1: 32.523)
    CrankCouplerDrive(crank_speed=72 * RPM, a3=33.0 * IN, rigid=1).initialize(0.0)  # no coupler


def test_tube_without_wall_is_refused() -> None:
    text = _refusal(d_inner=1.1 * IN)
    assert "'coupler tube'" in text and "D_i = 1.10000 in against D_o = 1.00000 in" in text


def test_sprag_without_real_hertz_stiffness_is_refused() -> None:
    assert sprag_violations(TABLE4) == []
    assert two_point_hertz(TABLE4).k > 0.0
    # |R_o - R_i - 2 R_s| = 0.0001 in: an offset below it cannot reach both races.
    clutch = SpragClutch(model=MODEL_HERTZ, sprag_offset=0.00005 * IN)
    with pytest.raises(DesignError) as exc:
        clutch.initialize(0.0)
    assert "'sprag geometry'" in str(exc.value) and "a = 0.00005 in" in str(exc.value)
    with pytest.raises(DesignError, match="R_i < R_o"):
        SpragClutch(model=MODEL_HERTZ, r_inner=1.4 * IN).initialize(0.0)
    SpragClutch(sprag_offset=0.00005 * IN).initialize(0.0)  # the lumped clutch: not used


def test_brake_below_the_engagement_minimum_is_a_note() -> None:
    omega, j5 = 200 * RPM, 0.412 * LBF_IN
    t_min = engagement_minimum(LINKAGE_TABLE1, C.alpha, omega, j5)
    # Below J_o5 w^2 max|phi4r''| with Xu's recomputed max |phi4r''| = 0.237 (both strokes).
    assert 0.0 < t_min < j5 * omega**2 * 0.237
    assert brake_note(LINKAGE_TABLE1, C.alpha, omega, j5, 160 * LBF_IN) is None  # Run 1
    note = brake_note(LINKAGE_TABLE1, C.alpha, omega, j5, 20 * LBF_IN)
    assert note.startswith("design note 'brake engagement minimum': T_b = 20.0 lbf*in")
