"""Scenario values with units, converted once at load to the SI unit a variable declares.

pint reads the quantities.  Importing it and loading its registry costs 0.15-0.4 s a
process, more than the rest of a scene's load, so both happen only when a conversion is not
already known: every conversion made is kept in a memo beside the FMUs
(``orchestrator.unit_memo``), and a scene whose quantities are all in it loads without
pint.
"""

from __future__ import annotations

import pickle
import re
import shutil
import sys
from functools import cache
from typing import TYPE_CHECKING, Any

from components.units import INCH, LBF
from orchestrator import unit_memo

if TYPE_CHECKING:
    import pint


@cache
def _pint() -> Any:
    """pint, without its optional dask support: pint imports dask whenever it is installed
    (0.15-0.45 s a process), and no quantity here is a dask array."""
    blocked = "dask" not in sys.modules
    if blocked:
        sys.modules["dask"] = None  # makes pint's `import dask` fail as if it were absent
    try:
        import pint
    finally:
        if blocked:
            del sys.modules["dask"]
    return pint


@cache
def ureg() -> pint.UnitRegistry:
    """pint's registry, its parsed definitions cached beside the FMUs: building it from the
    definition files costs 0.2-0.8 s a process, loading the cache a tenth of that. A cache
    that cannot be read (half-written by a process that died) is cleared and written again;
    one that cannot be written is passed over, and the registry built from the files."""
    from fmus.cache_dir import default_cache_dir  # the FMU cache's location

    pint = _pint()
    folder = default_cache_dir() / "units"
    for _ in range(2):
        try:
            return pint.UnitRegistry(cache_folder=folder)
        except (EOFError, pickle.UnpicklingError, AttributeError, ValueError):
            shutil.rmtree(folder, ignore_errors=True)
        except OSError:
            break
    return pint.UnitRegistry()


_POWER = re.compile(r"([A-Za-z]+)(-?\d+)")


@cache
def _exact() -> dict[Any, tuple[str, float]]:
    """The sources' mass and inertia units, converted with the factors the physics defines
    its data with (components.units), so that a deck typed in them gives the built-in
    values to the bit (pint's pound-force differs from the exact 4.4482216152605 N in the
    last digit)."""
    return {
        ureg().Unit("lbf*s**2/in"): ("kg", LBF / INCH),
        ureg().Unit("lbf*in*s**2"): ("kg*m**2", LBF * INCH),
    }


@cache
def pint_unit(fmi_unit: str) -> pint.Unit:
    """'N.m.s/rad' -> N*m*s/rad, 'kg.m2' -> kg*m**2, '1' -> dimensionless."""
    if fmi_unit == "1":
        return ureg().dimensionless
    text = _POWER.sub(r"\1**\2", fmi_unit.replace(".", "*"))
    numerator, _, denominator = text.partition("/")
    expr = numerator if not denominator else f"({numerator})/({denominator.replace('*', '/')})"
    return ureg().Unit(expr)


def to_si(value: object, fmi_unit: str, exact: bool = False) -> float:
    """A number (taken as already SI) or a string such as '0.4701 in' -> float in fmi_unit.

    ``exact``: a mass in lbf*s^2/in or an inertia in lbf*in*s^2 is converted with the
    exact pound-force of components.units, as the M739's built-in data are.

    Raises ValueError with a message naming the expected unit.
    """
    if isinstance(value, bool):
        raise ValueError(f"expected a number or a quantity in {fmi_unit}, got a boolean")
    if isinstance(value, int | float):
        return float(value)
    if not isinstance(value, str):
        raise ValueError(f"expected a number or a quantity in {fmi_unit}, got {value!r}")
    known = unit_memo.recall(value, fmi_unit, exact)
    if known is not None:
        return known
    converted = _convert(value, fmi_unit, exact)
    unit_memo.remember(value, fmi_unit, exact, converted)
    return converted


def _convert(value: str, fmi_unit: str, exact: bool) -> float:
    """``to_si`` of a text, by pint."""
    pint = _pint()
    try:
        quantity = ureg().Quantity(value.strip())
    except Exception as exc:  # pint raises several unrelated types for bad text
        raise ValueError(f"cannot read {value!r} as a quantity ({exc})") from None
    target = pint_unit(fmi_unit)
    try:
        if isinstance(quantity, int | float):
            return float(quantity)
        if quantity.unitless:  # a bare number written as text ("2.5", "nan"): taken as SI
            return float(quantity.magnitude)
        factor = _exact().get(quantity.units) if exact else None
        if factor is not None and ureg().Unit(factor[0]) == target:
            return float(quantity.magnitude) * factor[1]
        return float(quantity.to(target).magnitude)
    except pint.DimensionalityError:
        hint = (
            " (the sources' lb of a mass or an inertia is a pound-force: lbf*s^2/in, lbf*in*s^2)"
            if re.search(r"\blb\b", value)
            else ""
        )
        raise ValueError(
            f"{value!r} has units of {quantity.units:~}, which cannot be converted to "
            f"{fmi_unit}{hint}"
        ) from None
