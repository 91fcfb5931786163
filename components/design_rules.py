"""Consistency rules of a mechanism design, and how a broken one is refused.

A design is the data a source program read as input (the SANDA2V deck, the ISAD inputs,
Monday's deck, Xu's Table 1).  Before anything runs, each family's rules check it; a broken
rule is refused in one line that names the rule, the quantities with their values (in the
source's units, where the user typed them from) and what was expected:

    design rule 'involute base radius' broken: mesh 1 gear: RB1 = 0.37000 in against
    RP1 cos(THETA1) = 0.37588 in; expected equal within 0.1 %

``check_design`` and FMU initialization both raise ``DesignError`` on the first broken rule;
``mechcosim check`` lists every broken rule of a scene's design.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from .base import ComponentError
from .units import DEG, INCH


@dataclass(frozen=True)
class Violation:
    """One broken rule: its name, and the quantities and expectation in words."""

    rule: str
    detail: str

    def __str__(self) -> str:
        return f"design rule '{self.rule}' broken: {self.detail}"


class DesignError(ComponentError):
    """A design that breaks a consistency rule (the first one found)."""

    def __init__(self, violation: Violation) -> None:
        super().__init__(str(violation))
        self.violation = violation


def raise_first(violations: Iterable[Violation]) -> None:
    """Raise DesignError for the first broken rule, if any."""
    for v in violations:
        raise DesignError(v)


def inches(symbol: str, value_m: float, digits: int = 5) -> str:
    """``SYMBOL = 0.22600 in`` from a length in metres."""
    return f"{symbol} = {value_m / INCH:.{digits}f} in"


def degrees(symbol: str, value_rad: float, digits: int = 3) -> str:
    """``SYMBOL = 43.535 deg`` from an angle in radians."""
    return f"{symbol} = {value_rad / DEG:.{digits}f} deg"


def plain(symbol: str, value: float, digits: int = 5) -> str:
    """``SYMBOL = 0.99930`` for a number without unit."""
    return f"{symbol} = {value:.{digits}g}"
