"""The single-pass master's error estimate: which copies of a sampled input it judges
together (an angle with its speed) and how."""

from __future__ import annotations

from orchestrator.masters.copies import angles_with_speeds
from orchestrator.model_info import base_of_unit_name

RAD, RAD_S = base_of_unit_name("rad"), base_of_unit_name("rad/s")


def test_a_speed_copy_is_judged_with_its_angle() -> None:
    copies = [((0, 3), (1, 7)), ((0, 4), (1, 8))]  # train's phi, phi_dot -> verge's copies
    assert angles_with_speeds(copies, [RAD_S, RAD]) == [((0, 4), (1, 8), ((0, 3), (1, 7)))]


def test_copies_of_other_fmus_or_other_units_stay_alone() -> None:
    # Another receiver's speed, and a torque: neither is the angle's speed.
    copies = [((0, 3), (1, 7)), ((0, 4), (2, 8)), ((0, 5), (1, 9))]
    units = [RAD, RAD_S, base_of_unit_name("N.m")]
    assert angles_with_speeds(copies, units) == [(s, c, None) for s, c in copies]


def test_unknown_units_pair_nothing() -> None:
    copies = [((0, 3), (1, 7)), ((0, 4), (1, 8))]
    assert angles_with_speeds(copies, [None, None]) == [(s, c, None) for s, c in copies]
