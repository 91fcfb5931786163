"""Scenario values with units, converted once at load to the SI unit a variable declares."""

from __future__ import annotations

import pickle
import re
import shutil
import sys
from functools import cache

from components.units import INCH, LBF


def _import_pint():
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


pint = _import_pint()


def _unit_registry() -> pint.UnitRegistry:
    """pint's registry, its parsed definitions cached beside the FMUs: building it from the
    definition files costs 0.2-0.8 s a process, loading the cache a tenth of that. A cache
    that cannot be read (half-written by a process that died) is cleared and written again;
    one that cannot be written is passed over, and the registry built from the files."""
    from fmus.build import default_cache_dir  # the FMU cache's location, read once here

    folder = default_cache_dir() / "units"
    for _ in range(2):
        try:
            return pint.UnitRegistry(cache_folder=folder)
        except (EOFError, pickle.UnpicklingError, AttributeError, ValueError):
            shutil.rmtree(folder, ignore_errors=True)
        except OSError:
            break
    return pint.UnitRegistry()


UREG = _unit_registry()
_POWER = re.compile(r"([A-Za-z]+)(-?\d+)")
#: The sources' mass and inertia units, converted with the factors the physics defines its
#: data with (components.units), so that a deck typed in them gives the built-in values to
#: the bit (pint's pound-force differs from the exact 4.4482216152605 N in the last digit).
_EXACT = {
    UREG.Unit("lbf*s**2/in"): ("kg", LBF / INCH),
    UREG.Unit("lbf*in*s**2"): ("kg*m**2", LBF * INCH),
}


@cache
def pint_unit(fmi_unit: str) -> pint.Unit:
    """'N.m.s/rad' -> N*m*s/rad, 'kg.m2' -> kg*m**2, '1' -> dimensionless."""
    if fmi_unit == "1":
        return UREG.dimensionless
    text = _POWER.sub(r"\1**\2", fmi_unit.replace(".", "*"))
    numerator, _, denominator = text.partition("/")
    expr = numerator if not denominator else f"({numerator})/({denominator.replace('*', '/')})"
    return UREG.Unit(expr)


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
    try:
        quantity = UREG.Quantity(value.strip())
    except Exception as exc:  # pint raises several unrelated types for bad text
        raise ValueError(f"cannot read {value!r} as a quantity ({exc})") from None
    target = pint_unit(fmi_unit)
    try:
        if isinstance(quantity, int | float):
            return float(quantity)
        if quantity.unitless:  # a bare number written as text ("2.5", "nan"): taken as SI
            return float(quantity.magnitude)
        factor = _EXACT.get(quantity.units) if exact else None
        if factor is not None and UREG.Unit(factor[0]) == target:
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
