"""SI unit strings (FMI style, e.g. ``N.m.s/rad``, ``kg.m2``) as FMI base-unit exponents."""

from __future__ import annotations

import re

# Base-unit exponents (kg, m, s, rad) of every symbol the components use.
_SYMBOLS: dict[str, dict[str, int]] = {
    "kg": {"kg": 1},
    "m": {"m": 1},
    "s": {"s": 1},
    "rad": {"rad": 1},
    "N": {"kg": 1, "m": 1, "s": -2},
    "J": {"kg": 1, "m": 2, "s": -2},
    "W": {"kg": 1, "m": 2, "s": -3},
    "Pa": {"kg": 1, "m": -1, "s": -2},
    "Hz": {"s": -1},
    "1": {},
}
_TOKEN = re.compile(r"^([A-Za-z]+|1)(-?\d+)?$")


def base_unit_exponents(unit: str) -> dict[str, int]:
    """Exponents of kg, m, s, rad in ``unit`` (products with '.', one optional '/')."""
    numerator, _, denominator = unit.partition("/")
    total: dict[str, int] = {}
    for part, sign in ((numerator, 1), (denominator, -1)):
        if not part:
            continue
        for token in part.split("."):
            match = _TOKEN.match(token)
            if not match or match.group(1) not in _SYMBOLS:
                raise ValueError(f"unknown unit symbol {token!r} in {unit!r}")
            power = int(match.group(2) or 1) * sign
            for base, exp in _SYMBOLS[match.group(1)].items():
                total[base] = total.get(base, 0) + exp * power
    return {k: v for k, v in total.items() if v}
