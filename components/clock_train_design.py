"""A user's clock-train S&A as ClockGearTrain design parameters, and its consistency rules.

The clock teeth of each mesh are the quantities of the kinematics of the US Army fuze report
of about 1980 (Task 2, eqs. 1-126; "003" in the descriptions): frame b, beta; gear tip round
a_G, delta_G, rho_G; radial pinion flank alpha_P, f_P and leaf round rho_P; the tooth numbers
(the tooth spacings of the sensing equations 41-45, 83-87); and the cluster phasing kappa2
(phi2G = phi2P + kappa2: the report couples gear 2 and pinion 2 "by increments", eq. 61).
The bodies are the train entries of the SANDA2V deck (``components.sanda2v_deck``: masses,
inertias, rotor offset and start angle, pivot distances and radii, spin, mu), the same
parameters with the same names as the M739 S&A's gear train.  Defaults: the representative
M739-like clock train (``components.clock_train_kinematics.M739_TRAIN``) and the M739 deck.

Tepper (1981) Tables 1-4 give real clock meshes in another form (pitch radii, arc centre
distances a, arc radii rho, tooth thicknesses t); ``tepper_mesh`` converts one (see there for
what is exact and what is not).

``train_violations`` lists the broken rules of a clock train (empty: consistent), each a
``Violation``; ClockGearTrain refuses the first at initialization, the clock_train family's
``design_check`` lists them when a scene is loaded.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from .base import Variable, design_parameter
from .clock_train_kinematics import M739_MESH1, M739_MESH2, M739_TRAIN, ClockMesh, ClockTrain
from .design_rules import Violation, degrees, inches, plain
from .m739_data import M739Data
from .mesh_efficiency_data import ClockMeshData
from .sanda2v_deck import BY_NAME, data_from
from .units import INCH

_POSITIVE = {"min": 0.0, "exclusive_min": True}

#: The SANDA2V train entries the clock train takes (its bodies, spin, friction, tooth numbers).
BODY_NAMES = (
    "mu",
    "spin",
    "rotor_mass",
    "gear2_mass",
    "wheel_mass",
    "rotor_inertia",
    "gear2_inertia",
    "wheel_inertia",
    "rotor_offset",
    "rotor_start_angle",
    "rotor_pivot_distance",
    "gear2_pivot_distance",
    "wheel_pivot_distance",
    "rotor_pivot_radius",
    "gear2_pivot_radius",
    "wheel_pivot_radius",
)
#: Tooth numbers of each mesh (gear, pinion): SANDA2V entries too, the spacings of 003.
TEETH = (("gear1_teeth", "pinion2_teeth"), ("gear2_teeth", "pinion3_teeth"))

#: ClockMesh field -> (parameter stem, unit, meaning, 003 symbol stem, bounds).  The stem
#: takes the mesh's member names: mesh 1 is gear 1 on pinion 2, mesh 2 gear 2 on pinion 3.
_MESH_FIELDS = (
    ("b", "mesh{i}_center_distance", "m", "centre distance of mesh {i}, O_gear to O_pinion",
     "b{i}", _POSITIVE),
    ("beta", "mesh{i}_direction", "rad", "direction of O_gear -> O_pinion of mesh {i}",
     "beta{i}", {}),
    ("a_g", "gear{g}_round_distance", "m", "gear {g} pivot to its tip-round centre C_G",
     "a_G{i}", _POSITIVE),
    ("delta_g", "gear{g}_round_offset", "rad", "gear {g} tip-round centre angular offset",
     "delta_G{i}", {}),
    ("rho_g", "gear{g}_round_radius", "m", "gear {g} tip-round radius", "rho_G{i}", _POSITIVE),
    ("alpha_p", "pinion{p}_flank_angle", "rad", "pinion {p} radial flank direction offset",
     "alpha_P{i}", {}),
    ("f_p", "pinion{p}_flank_length", "m",
     "pinion {p} pivot to where the flank meets the leaf round", "f_P{i}", _POSITIVE),
    ("rho_p", "pinion{p}_round_radius", "m", "pinion {p} leaf-round radius", "rho_P{i}",
     _POSITIVE),
)  # fmt: skip
_MEMBERS = {1: (1, 2), 2: (2, 3)}


def mesh_names(i: int) -> dict[str, str]:
    """ClockMesh field -> parameter name of mesh i (1 or 2)."""
    g, p = _MEMBERS[i]
    return {f: stem.format(i=i, g=g, p=p) for f, stem, *_ in _MESH_FIELDS}


def _mesh_variables(i: int, mesh: ClockMesh) -> tuple[Variable, ...]:
    g, p = _MEMBERS[i]
    return tuple(
        design_parameter(
            stem.format(i=i, g=g, p=p),
            unit,
            getattr(mesh, f),
            meaning.format(i=i, g=g, p=p),
            f"003: {symbol.format(i=i)}",
            **bounds,
        )
        for f, stem, unit, meaning, symbol, bounds in _MESH_FIELDS
    )


KAPPA2 = design_parameter(
    "cluster_phasing",
    "rad",
    M739_TRAIN.kappa2,
    "gear 2 angle minus pinion 2 angle on their shaft (phi2G = phi2P + kappa2)",
    "003: kappa2",
)
#: The clock-tooth geometry of both meshes and the cluster phasing.
GEOMETRY_VARIABLES: tuple[Variable, ...] = (
    *_mesh_variables(1, M739_MESH1),
    *_mesh_variables(2, M739_MESH2),
    KAPPA2,
)
#: The bodies and tooth numbers: the SANDA2V deck's own parameters.
BODY_VARIABLES: tuple[Variable, ...] = tuple(
    BY_NAME[n].variable() for n in (*BODY_NAMES, *TEETH[0], *TEETH[1])
)
DESIGN_VARIABLES = BODY_VARIABLES + GEOMETRY_VARIABLES
DESIGN_NAMES = tuple(v.name for v in DESIGN_VARIABLES)


def design_defaults() -> dict[str, float]:
    """Every design parameter at its default (the representative M739-like train)."""
    return {v.name: v.start for v in DESIGN_VARIABLES}


def values_of(component: Any) -> dict[str, float]:
    """The design parameters a component (or any object with them as attributes) holds."""
    return {n: getattr(component, n) for n in DESIGN_NAMES}


def clock_mesh(values: Mapping[str, float], i: int) -> ClockMesh:
    """Mesh i (1 or 2) of design values (SI); mesh 2 in its own (mirrored) convention."""
    names = mesh_names(i)
    gear, pinion = TEETH[i - 1]
    return ClockMesh(
        **{f: float(values[n]) for f, n in names.items()},
        n_gear=int(values[gear]),
        n_pinion=int(values[pinion]),
        mirrored=i == 2,
    )


def clock_train(values: Mapping[str, float]) -> ClockTrain:
    """The clock train of design values (the stored M739_TRAIN when they are its own, so its
    cached transition and handover angles serve)."""
    train = ClockTrain(
        clock_mesh(values, 1), clock_mesh(values, 2), float(values["cluster_phasing"])
    )
    return M739_TRAIN if train == M739_TRAIN else train


def body_data(values: Mapping[str, float]) -> M739Data:
    """The M739 data with the bodies, spin, friction and tooth numbers of design values."""
    return data_from({n: values[n] for n in (*BODY_NAMES, *TEETH[0], *TEETH[1]) if n in values})


def mesh_values(mesh: ClockMesh, i: int) -> dict[str, float]:
    """The design parameters of mesh i (1 or 2) that enter a ClockMesh (as a scene gives)."""
    out = {n: getattr(mesh, f) for f, n in mesh_names(i).items()}
    gear, pinion = TEETH[i - 1]
    out[gear], out[pinion] = float(mesh.n_gear), float(mesh.n_pinion)
    return out


# ------------------------------------------------------------------------------------------
# Tepper (1981) Tables 1-4 in the form of report 003
# ------------------------------------------------------------------------------------------
def tepper_mesh(
    mesh: ClockMeshData,
    center_distance: float | None = None,
    beta: float = 0.0,
    mirrored: bool = False,
) -> ClockMesh:
    """A clock mesh of Tepper 1981's Tables 1-4 in report 003's form.

    Both describe the gear tooth by a round (Tepper: the arc of radius rho_G centred a_G from
    the pivot, C_x = rho_G - t_G / 2 off the tooth centreline, App. A) and the pinion leaf by a
    round of radius rho_P centred a_P from its pivot; the rounds convert exactly:
    a_G, rho_G, rho_P as given, delta_G = asin(C_xG / a_G) (the gear angle is then Tepper's
    tooth centreline), f_P = sqrt(a_P^2 - rho_P^2) (003's consistency a_P = sqrt(f_P^2 +
    rho_P^2)) and alpha_P = asin(rho_P / a_P) - asin(C_xP / a_P) (the pinion angle is then
    Tepper's leaf centreline).  Round-on-round contact, a four-bar O_G C_G C_P O_P, is therefore
    the same.  What differs: 003's pinion flank is radial (through O_P) where the library's
    Tables 1-4 flank (``ClockMeshModel``) is parallel to the leaf centreline, t_P / 2 from it;
    003 has no gear flank (the library's flank-on-round phase); and 003 hands over where the
    next pair touches (sensing equation), the library to the pair that holds the pinion
    furthest back.  b: not tabulated, R_G + R_P as in the library.
    """
    cx_g = mesh.gear_arc_radius - 0.5 * mesh.gear_tooth_thickness
    cx_p = mesh.pinion_arc_radius - 0.5 * mesh.pinion_tooth_thickness
    a_p, rho_p = mesh.pinion_center_distance, mesh.pinion_arc_radius
    return ClockMesh(
        b=center_distance or (mesh.gear_pitch_radius + mesh.pinion_pitch_radius),
        beta=beta,
        a_g=mesh.gear_center_distance,
        delta_g=math.asin(cx_g / mesh.gear_center_distance),
        rho_g=mesh.gear_arc_radius,
        alpha_p=math.asin(rho_p / a_p) - math.asin(cx_p / a_p),
        f_p=math.sqrt(a_p * a_p - rho_p * rho_p),
        rho_p=rho_p,
        n_gear=mesh.n_gear,
        n_pinion=mesh.n_pinion,
        mirrored=mirrored,
    )


# ------------------------------------------------------------------------------------------
# Rules
# ------------------------------------------------------------------------------------------
#: The gear travel over one pair window must be one gear pitch to this (relative): the mean
#: ratio N_G / N_P of a consistent mesh holds to rounding.
MEAN_RATIO_TOLERANCE = 1.0e-9
#: Points per pair window at which the positions are solved.
WINDOW_POINTS = 64


def _symbols(i: int) -> dict[str, str]:
    """ClockMesh field -> 'symbol (parameter)' for messages."""
    names = mesh_names(i)
    return {f: f"{sym.format(i=i)} ({names[f]})" for f, _, _, _, sym, _ in _MESH_FIELDS}


def _lengths(i: int, m: ClockMesh) -> str:
    s = _symbols(i)
    return ", ".join(inches(s[f], getattr(m, f)) for f in ("b", "a_g", "rho_g", "f_p", "rho_p"))


def _first_touch(m: ClockMesh, lo: float, hi: float) -> float | None:
    """The first gear angle in (lo, hi) where the next pair touches (its sensing gap falls
    through zero), None if it does not there."""
    grid = np.linspace(lo, hi, 101)
    try:
        gaps = [m.sensing_gap(float(x)) for x in grid]
    except ValueError:
        return None
    for k in range(100):
        if gaps[k] > 0.0 >= gaps[k + 1]:
            from scipy.optimize import brentq  # here: scipy.optimize costs 0.3-0.6 s to import

            return float(brentq(m.sensing_gap, grid[k], grid[k + 1], xtol=1e-15))
    return None


def mesh_violations(m: ClockMesh, i: int) -> list[Violation]:
    """The broken rules of mesh i, in the order a later rule needs the earlier ones."""
    where = f"mesh {i}"
    sides = (("b", m.b), ("a_G", m.a_g), ("a_P", m.a_p), ("L", m.rho_g + m.rho_p))
    longest = max(sides, key=lambda s: s[1])
    if not longest[1] < sum(v for _, v in sides) - longest[1]:
        return [
            Violation(
                "coupler L = rho_G + rho_P",
                f"{where}: the four-bar O_G C_G C_P O_P cannot close: {longest[0]} = "
                f"{longest[1] / INCH:.5f} in is not shorter than the other three sides together "
                f"({_lengths(i, m)}, a_P = sqrt(f_P^2 + rho_P^2) = {m.a_p / INCH:.5f} in, "
                f"L = rho_G + rho_P = {(m.rho_g + m.rho_p) / INCH:.5f} in; eqs. 6-7)",
            )
        ]
    if m.n_gear < 1 or m.n_pinion < 1:
        return [Violation("tooth counts", f"{where}: N_G = {m.n_gear}, N_P = {m.n_pinion}")]
    try:
        m.transition()
    except ValueError:
        return [
            Violation(
                "positions exist over the cycle",
                f"{where}: the gear round never reaches the pinion flank's end (no transition "
                f"angle, eqs. 37-40: A^2 + B^2 < C^2) with {_lengths(i, m)}",
            )
        ]
    t_gear, t_pin = m.transition()
    pitch = 2.0 * math.pi / m.n_gear
    touch = _first_touch(m, t_gear - pitch, t_gear + 1.5 * pitch)
    if touch is None or not t_gear < touch < t_gear + pitch:
        where_touch = (
            "never within a gear pitch either side of it"
            if touch is None
            else f"at {degrees('phi_G', touch)}"
        )
        return [
            Violation(
                "hand-over inside its window",
                f"{where}: the flank is reached at {degrees('phi_GT', t_gear)} and the next pair "
                f"touches {where_touch} (sensing equation, eqs. 41-45/83-87); expected the "
                f"hand-over on the flank, less than a gear pitch {degrees('2 pi/N_G', pitch)} "
                f"after it ({_lengths(i, m)}, {plain('N_G', m.n_gear)}, "
                f"{plain('N_P', m.n_pinion)})",
            )
        ]
    end = m.window_end
    q = m.pinion_pitch
    for j in range(WINDOW_POINTS + 1):
        x = end + q * j / WINDOW_POINTS
        phase = "ror" if x > t_pin else "rof"
        try:
            m._pair_inverse(x, phase)
        except ValueError:
            return [
                Violation(
                    "positions exist over the cycle",
                    f"{where}: no gear position for pinion angle {x:.6f} rad "
                    f"({'round on round' if phase == 'ror' else 'round on flank'}, "
                    f"A^2 + B^2 < C^2 of eqs. 91/100) with {_lengths(i, m)}",
                )
            ]
    start = m._pair_inverse(end + q, "ror")[0]
    stop = m._pair_inverse(end, "rof")[0]
    travel = abs(stop - start)
    if abs(travel - pitch) > MEAN_RATIO_TOLERANCE * pitch:
        return [
            Violation(
                "mean ratio N_G/N_P",
                f"{where}: over one pair window the pinion turns 2 pi/N_P = "
                f"{q:.6f} rad while the gear turns {travel:.6f} rad: mean ratio "
                f"{q / travel:.6f} against N_G/N_P = {m.n_gear}/{m.n_pinion} = "
                f"{m.n_gear / m.n_pinion:.6f}; expected equal to {MEAN_RATIO_TOLERANCE:g} "
                "(the next pair must touch one tooth on, on the four-bar's branch)",
            )
        ]
    return []


def train_violations(train: ClockTrain) -> list[Violation]:
    """The broken rules of both meshes of a clock train."""
    return mesh_violations(train.mesh1, 1) + mesh_violations(train.mesh2, 2)


def design_violations(values: Mapping[str, float]) -> list[Violation]:
    """The broken rules of a clock-train design (parameter values, SI)."""
    return train_violations(clock_train(values))
