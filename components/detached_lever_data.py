"""Data of Monday (1965), *Detached Lever Clock Mechanism Dynamics*, PhD thesis, Oklahoma State.

The thesis works in inch, pound-force and second and states most quantities per unit balance
inertia (torque / I, in s^-2), which are unit-free apart from the second.  Only the balance inertia
of the worked example carries a length unit; it is converted here, once.
"""

from __future__ import annotations

from dataclasses import dataclass

from .units import LBF_IN

#: Balance inertia of the worked example, 1.10e-7 lb.in.s^2 (Monday 1965, Ch. IV, pp. 39-45),
#: in kg.m^2.
BALANCE_INERTIA = 1.10e-7 * LBF_IN

#: Power (lift) half-angle and start of unlock used by every program deck (Monday 1965, p. 37;
#: App. B, Tables II-IV data cards, pp. 109-115).
LIFT_ANGLE = 0.2786896  # rad
UNLOCK_START = 0.6337686  # rad

#: Release amplitude of every unit curve: overbank, 6.28 rad (Monday 1965, Ch. IV, p. 30).
OVERBANK = 6.28


@dataclass(frozen=True)
class WorkedExample:
    """Card deck of the Ch. IV estimation example (Monday 1965, pp. 39-45), per unit inertia."""

    alpha: float = 0.2787  # rad, power angle before the line of centres (all four equal)
    epsilon: float = 0.6338  # rad, start of unlock (epsilon = sigma)
    c: float = 0.833  # 1/s, viscous coefficient / I
    omega0: float = 16.174  # rad/s
    theta0: float = 6.28  # rad
    r: float = 305.546  # 1/s^2, Coulomb torque / I
    x_unlock: float = 143.41  # 1/s^2, unlock torque / I (per 100 gm fixture load)
    x_impulse: float = 1245.8  # 1/s^2, impulse torque / I


WORKED_EXAMPLE = WorkedExample()


@dataclass(frozen=True)
class TableIRow:
    load_multiple: int  # fixture load in multiples of an unknown unit load (from Table I X2, X3)
    r: float  # 1/s^2, Coulomb torque / I (chart-derived, numerically fragile)
    x_unlock: float  # 1/s^2
    x_impulse: float  # 1/s^2
    k: float  # 1, impulse-only drive parameter X3/omega0^2 of the matched CUC


@dataclass(frozen=True)
class TableIUnit:
    unit: int
    omega1: float  # rad/s, damped frequency as printed
    c_over_omega0: float  # 1
    omega0: float  # rad/s
    c: float  # 1/s
    epsilon: float  # rad, start of unlock
    alpha: float  # rad, power half-angle
    rows: tuple[TableIRow, ...]


# Table I, "Unit Curve Comparisons" (thesis p. 56).  Unit 4, row 1: X2 printed 232.530 is
# taken as 236.530 (derived here: every other X2 is an integer multiple of ~236.535).
TABLE_I: dict[int, TableIUnit] = {
    1: TableIUnit(
        1, 15.707, 0.090, 15.90, 1.431, 0.633, 0.278,
        (
            TableIRow(2, 965.482, 473.070, 4119.339, 0.720),
            TableIRow(4, 1981.859, 946.140, 8238.678, 1.070),
            TableIRow(6, 3022.290, 1419.210, 12358.017, 1.400),
        ),
    ),
    2: TableIUnit(
        2, 15.457, 0.110, 15.48, 1.703, 0.576, 0.262,
        (
            TableIRow(2, 932.640, 473.070, 4119.339, 0.485),
            TableIRow(4, 1875.584, 946.140, 8238.678, 0.815),
            TableIRow(6, 2817.809, 1419.210, 12358.017, 1.150),
        ),
    ),
    3: TableIUnit(
        3, 15.707, 0.150, 15.78, 2.367, 0.612, 0.280,
        (
            TableIRow(2, 980.015, 473.070, 4119.339, 0.750),
            TableIRow(4, 2027.762, 946.140, 8238.678, 1.230),
            TableIRow(6, 3028.122, 1419.210, 12358.017, 1.700),
        ),
    ),
    4: TableIUnit(
        4, 15.142, 0.050, 15.15, 0.757, 0.620, 0.288,
        (
            TableIRow(1, 524.522, 236.530, 2059.664, 0.290),
            TableIRow(2, 1046.292, 473.070, 4119.339, 0.510),
            TableIRow(3, 1573.109, 709.600, 6179.003, 0.710),
        ),
    ),
    5: TableIUnit(
        5, 15.143, 0.055, 15.15, 0.833, 0.506, 0.244,
        (
            TableIRow(1, 439.167, 236.530, 2059.664, 0.333),
            TableIRow(3, 1324.385, 709.600, 6179.003, 0.650),
            TableIRow(5, 2196.290, 1182.670, 10298.342, 0.941),
        ),
    ),
}  # fmt: skip
