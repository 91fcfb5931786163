"""A user's gear pair as GearMesh design parameters, and its consistency rules.

Involute pair: every input of the programs ISAD1/ISAD2 of Tepper (1981), ARLCD-TR-81020
(Apps. C-D: ``READ PSUBD,NP,CAPRP,RP,CAPRO,RO,THETAD,RHOCAPN,RHON,CD,HOBTIPR,K,RASFACT``) and
which member drives (ISAD1: the pinion, ISAD2: the gear), in SI.  Clock mesh: the quantities of
the report's Tables 1-4 (tooth numbers, pitch radii, pivot to centre of curvature a, arc radius
rho, tooth thickness t, pivot radii) and the pivot distance b that CLOCK2 reads (not tabulated:
taken as R_G + R_P by default).  The defaults are the stored Table 6 pair as published (pinion
drives) and Table 1, so a scene that selects the user pair without entering anything gets them.

``check_involute_design`` / ``check_clock_design`` list the broken rules (empty: consistent),
each a ``Violation`` in the source's units (inches, degrees); GearMesh refuses the first at
initialization.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from .base import Variable, design_parameter
from .design_rules import Violation, degrees, inches, plain
from .mesh_efficiency import ClockMeshModel, inner_form_radius
from .mesh_efficiency_data import CLOCK_MESHES, INVOLUTE_MESHES, ClockMeshData, InvoluteMesh
from .units import INCH

#: Radii of the report's tables are printed to 5 decimals of an inch: two half units of the
#: last digit is how far two radii that should agree may differ (Table 10 prints
#: RP = 0.10938 for 14 / 128 = 0.109375 in; Table 3's pitch radii 0.18535 / 0.02595 in give
#: 50 : 7.00038).
RADIUS_ROUNDING = 1.0e-5 * INCH

_T6 = INVOLUTE_MESHES[6]
_T1 = CLOCK_MESHES[1]


def _isad(name: str, unit: str, start: float, meaning: str, symbol: str, **kw) -> Variable:
    return design_parameter(name, unit, start, meaning, f"ISAD: {symbol}", **kw)


def _table(name: str, unit: str, start: float, meaning: str, symbol: str, **kw) -> Variable:
    return design_parameter(name, unit, start, meaning, f"Tepper 1981 Tables 1-4: {symbol}", **kw)


#: The user involute pair (GearMesh ``mesh = 0``); defaults: Table 6 as published (ISAD1).
INVOLUTE_DESIGN: tuple[Variable, ...] = (
    _isad("diametral_pitch", "1/m", _T6.diametral_pitch / INCH,
          "diametral pitch (teeth per pitch diameter)", "PSUBD", min=0.0, exclusive_min=True),
    _isad("n_pinion", "1", _T6.n_pinion, "pinion tooth number", "NP", type="Integer", min=1),
    _isad("gear_pitch_radius", "m", _T6.gear_pitch_radius, "gear standard pitch radius",
          "CAPRP", min=0.0, exclusive_min=True),
    _isad("pinion_pitch_radius", "m", _T6.pinion_pitch_radius, "pinion standard pitch radius",
          "RP", min=0.0, exclusive_min=True),
    _isad("gear_outside_radius", "m", _T6.gear_outside_radius, "gear outside radius", "CAPRO",
          min=0.0, exclusive_min=True),
    _isad("pinion_outside_radius", "m", _T6.pinion_outside_radius, "pinion outside radius",
          "RO", min=0.0, exclusive_min=True),
    _isad("pressure_angle", "rad", _T6.pressure_angle, "standard (cutter) pressure angle",
          "THETAD", min=0.0, max=math.pi / 2, exclusive_min=True),
    _isad("gear_pivot_radius", "m", _T6.gear_pivot_radius, "gear pivot (journal) radius",
          "RHOCAPN", min=0.0),
    _isad("pinion_pivot_radius", "m", _T6.pinion_pivot_radius, "pinion pivot (journal) radius",
          "RHON", min=0.0),
    _isad("center_distance", "m", _T6.center_distance, "operating centre distance", "CD",
          min=0.0, exclusive_min=True),
    _isad("hob_tip_radius", "m", _T6.hob_tip_radius, "hob tip radius", "HOBTIPR", min=0.0),
    _isad("points_per_cycle", "1", 25, "points of the report's cycle efficiency (plot only)",
          "K", type="Integer", min=1),
    _isad("undercut_factor", "1", 0.883, "1 - b / r_p at the undercut limit (eqs. 37/38)",
          "RASFACT", min=0.0),
    _isad("gear_drives", "1", 0, "1: the gear drives (ISAD2), 0: the pinion drives (ISAD1)",
          "ISAD1/ISAD2", type="Integer", min=0, max=1),
)  # fmt: skip

#: The user clock mesh (GearMesh ``model = 2, clock_mesh = 0``); defaults: Table 1.
CLOCK_DESIGN: tuple[Variable, ...] = (
    _table("clock_n_gear", "1", _T1.n_gear, "gear tooth number", "N_G", type="Integer", min=1),
    _table("clock_n_pinion", "1", _T1.n_pinion, "pinion leaf number", "N_P", type="Integer",
           min=1),
    _table("clock_gear_pitch_radius", "m", _T1.gear_pitch_radius, "gear pitch radius", "R_G",
           min=0.0, exclusive_min=True),
    _table("clock_pinion_pitch_radius", "m", _T1.pinion_pitch_radius, "pinion pitch radius",
           "R_P", min=0.0, exclusive_min=True),
    _table("clock_gear_arc_center_distance", "m", _T1.gear_center_distance,
           "gear pivot to the centre of curvature of the tooth arc", "a_G", min=0.0,
           exclusive_min=True),
    _table("clock_pinion_arc_center_distance", "m", _T1.pinion_center_distance,
           "pinion pivot to the centre of curvature of the leaf arc", "a_P", min=0.0,
           exclusive_min=True),
    _table("clock_gear_arc_radius", "m", _T1.gear_arc_radius, "gear tooth arc radius", "rho_G",
           min=0.0, exclusive_min=True),
    _table("clock_pinion_arc_radius", "m", _T1.pinion_arc_radius, "pinion leaf arc radius",
           "rho_P", min=0.0, exclusive_min=True),
    _table("clock_gear_tooth_thickness", "m", _T1.gear_tooth_thickness,
           "gear tooth thickness at the pitch circle", "t_G", min=0.0, exclusive_min=True),
    _table("clock_pinion_tooth_thickness", "m", _T1.pinion_tooth_thickness,
           "pinion leaf thickness at the pitch circle", "t_P", min=0.0, exclusive_min=True),
    _table("clock_gear_pivot_radius", "m", _T1.gear_pivot_radius, "gear pivot radius", "rho_N",
           min=0.0),
    _table("clock_pinion_pivot_radius", "m", _T1.pinion_pivot_radius, "pinion pivot radius",
           "rho_n", min=0.0),
    _table("clock_center_distance", "m", _T1.gear_pitch_radius + _T1.pinion_pitch_radius,
           "pivot distance (not tabulated: R_G + R_P)", "b", min=0.0, exclusive_min=True),
)  # fmt: skip

DESIGN_NAMES = tuple(v.name for v in INVOLUTE_DESIGN + CLOCK_DESIGN)


def design_defaults() -> dict[str, float]:
    """Every design parameter at its start value."""
    return {v.name: float(v.start) for v in INVOLUTE_DESIGN + CLOCK_DESIGN}


def involute_design_values(mesh: InvoluteMesh, driver: str | None = None) -> dict[str, float]:
    """The design parameters that enter a stored involute mesh (SI), as a scene would."""
    return {
        "diametral_pitch": mesh.diametral_pitch / INCH,
        "n_pinion": float(mesh.n_pinion),
        "gear_pitch_radius": mesh.gear_pitch_radius,
        "pinion_pitch_radius": mesh.pinion_pitch_radius,
        "gear_outside_radius": mesh.gear_outside_radius,
        "pinion_outside_radius": mesh.pinion_outside_radius,
        "pressure_angle": mesh.pressure_angle,
        "gear_pivot_radius": mesh.gear_pivot_radius,
        "pinion_pivot_radius": mesh.pinion_pivot_radius,
        "center_distance": mesh.center_distance,
        "hob_tip_radius": mesh.hob_tip_radius,
        "points_per_cycle": 25.0,
        "undercut_factor": 0.883,
        "gear_drives": 1.0 if (driver or mesh.driver) == "gear" else 0.0,
    }


def clock_design_values(mesh: ClockMeshData) -> dict[str, float]:
    """The design parameters of a stored clock mesh (Tables 1-4), SI."""
    return {
        "clock_n_gear": float(mesh.n_gear),
        "clock_n_pinion": float(mesh.n_pinion),
        "clock_gear_pitch_radius": mesh.gear_pitch_radius,
        "clock_pinion_pitch_radius": mesh.pinion_pitch_radius,
        "clock_gear_arc_center_distance": mesh.gear_center_distance,
        "clock_pinion_arc_center_distance": mesh.pinion_center_distance,
        "clock_gear_arc_radius": mesh.gear_arc_radius,
        "clock_pinion_arc_radius": mesh.pinion_arc_radius,
        "clock_gear_tooth_thickness": mesh.gear_tooth_thickness,
        "clock_pinion_tooth_thickness": mesh.pinion_tooth_thickness,
        "clock_gear_pivot_radius": mesh.gear_pivot_radius,
        "clock_pinion_pivot_radius": mesh.pinion_pivot_radius,
        "clock_center_distance": mesh.gear_pitch_radius + mesh.pinion_pitch_radius,
    }


def involute_pair(p: Mapping[str, float]) -> InvoluteMesh:
    """The user involute pair of design parameters ``p`` (SI) as the library's InvoluteMesh."""
    return InvoluteMesh(
        0, 0, "user involute pair", p["diametral_pitch"] * INCH, int(p["n_pinion"]),
        p["gear_pitch_radius"], p["pinion_pitch_radius"], p["gear_outside_radius"],
        p["pinion_outside_radius"], p["gear_pivot_radius"], p["pinion_pivot_radius"],
        p["center_distance"], "gear" if int(p["gear_drives"]) == 1 else "pinion",
        p["pressure_angle"], p["hob_tip_radius"],
    )  # fmt: skip


def clock_pair(p: Mapping[str, float]) -> ClockMeshData:
    """The user clock mesh of design parameters ``p`` (SI) as the library's ClockMeshData."""
    return ClockMeshData(
        0, "user clock mesh", int(p["clock_n_gear"]), int(p["clock_n_pinion"]),
        p["clock_gear_pitch_radius"], p["clock_pinion_pitch_radius"],
        p["clock_gear_arc_center_distance"], p["clock_pinion_arc_center_distance"],
        p["clock_gear_arc_radius"], p["clock_pinion_arc_radius"],
        p["clock_gear_tooth_thickness"], p["clock_pinion_tooth_thickness"],
        p["clock_gear_pivot_radius"], p["clock_pinion_pivot_radius"],
    )  # fmt: skip


# ------------------------------------------------------------------------------------------
# Involute rules (Tepper 1981, pp. 2-13, eqs. 1-45, 49)
# ------------------------------------------------------------------------------------------
def gear_tooth_number(mesh: InvoluteMesh) -> int:
    """Gear tooth number N_G = 2 Pd R_p (not an ISAD input), to the nearest whole number."""
    return max(1, round(2.0 * mesh.diametral_pitch * mesh.gear_pitch_radius / INCH))


def check_involute_design(mesh: InvoluteMesh, rasfact: float = 0.883) -> list[Violation]:
    """Broken consistency rules of an involute pair (empty: consistent), in the order a later
    rule needs the earlier ones: base radius, base pitch, outside radii, centre distance,
    undercut, contact ratio."""
    out: list[Violation] = []
    phi = mesh.pressure_angle
    cos_phi = math.cos(phi)
    pd = mesh.diametral_pitch / INCH  # 1/m
    rg, rp, cd = mesh.gear_pitch_radius, mesh.pinion_pitch_radius, mesh.center_distance
    big_rb, rb = rg * cos_phi, rp * cos_phi
    tol = RADIUS_ROUNDING * cos_phi
    # The pinion's base circle is that of its tooth number and pitch: NP cos(THETAD) / (2 PSUBD).
    rb_teeth = mesh.n_pinion * cos_phi / (2.0 * pd)
    if abs(rb - rb_teeth) > tol:
        out.append(Violation(
            "involute base radius",
            f"pinion: {inches('RP cos(THETAD)', rb)} against "
            f"{inches('NP cos(THETAD) / (2 PSUBD)', rb_teeth)} ({plain('NP', mesh.n_pinion)}, "
            f"PSUBD = {pd * INCH:g} /in, {degrees('THETAD', phi)}); expected equal within "
            f"{tol / INCH:.1e} in",
        ))  # fmt: skip
    # Both members share the base pitch of the diametral pitch, pi cos(THETAD) / PSUBD (the
    # pinion's, by the rule above): the gear's tooth number is a whole number.
    n_gear = gear_tooth_number(mesh)
    pb_pitch = math.pi * cos_phi / pd
    pb_gear = 2.0 * math.pi * big_rb / n_gear
    tol_pb = 2.0 * math.pi * tol / n_gear
    if abs(pb_gear - pb_pitch) > tol_pb:
        out.append(Violation(
            "equal base pitch",
            f"{inches('PB gear = 2 pi CAPRP cos(THETAD) / NG', pb_gear)} (NG = {n_gear}) against "
            f"{inches('PB = pi cos(THETAD) / PSUBD', pb_pitch)} (the pinion's); expected equal "
            f"within {tol_pb / INCH:.1e} in",
        ))  # fmt: skip
    for who, ro, rb_, sym, sym_b in (
        ("gear", mesh.gear_outside_radius, big_rb, "CAPRO", "CAPRB"),
        ("pinion", mesh.pinion_outside_radius, rb, "RO", "RB"),
    ):
        if not ro > rb_:
            out.append(Violation(
                "outside radius above base radius",
                f"{who}: {inches(sym, ro)} against {inches(sym_b, rb_)}; expected "
                f"{sym} > {sym_b} (the involute starts at the base circle)",
            ))  # fmt: skip
    if cd < rg + rp - RADIUS_ROUNDING:
        out.append(Violation(
            "centre distance",
            f"{inches('CD', cd)} against {inches('CAPRP + RP', rg + rp)}; expected CD >= "
            "CAPRP + RP (eqs. 39-45: extended centre distance, operating pitch radii "
            "CAPRP CD / (CAPRP + RP) and RP CD / (CAPRP + RP) summing to CD)",
        ))  # fmt: skip
    if out:
        return out  # the operating geometry below needs the rules above
    b = (1.2 / mesh.diametral_pitch + 0.002) * INCH - mesh.hob_tip_radius * (1.0 - math.sin(phi))
    op = math.acos((rg + rp) * cos_phi / cd)  # eq. 45
    rp_op = rp * cd / (rg + rp)
    try:
        rf = inner_form_radius(rb, rp, b, phi)
    except ValueError:
        rf = math.inf
    u = 1.0 - b / rp
    if u <= rasfact and not rf < rp_op:
        form = inches("RF", rf) if math.isfinite(rf) else "no root RF of eq. 49 below RP"
        out.append(Violation(
            "undercut",
            f"the pinion is undercut ({plain('U = 1 - B / RP', u, 4)} <= "
            f"{plain('RASFACT', rasfact, 4)}, {inches('B', b)}) with {form} against the "
            f"operating {inches('RP', rp_op)}; expected the true involute (from RF, eq. 49) "
            "to reach below the pitch point",
        ))  # fmt: skip
        return out
    s_gear = math.sqrt(mesh.gear_outside_radius**2 - big_rb**2)
    s_pin = math.sqrt(mesh.pinion_outside_radius**2 - rb**2)
    s_form = math.sqrt(max(rf**2 - rb**2, 0.0))
    tan_op = math.tan(op)
    pz_form, pz_tip = rb * tan_op - s_form, s_gear - big_rb * tan_op  # eqs. 4, 8
    path = s_gear + s_pin - (big_rb + rb) * tan_op if pz_form > pz_tip else s_pin - s_form
    pb_pinion = 2.0 * math.pi * rb / mesh.n_pinion  # PB as ISAD computes it
    cr = path / pb_pinion  # eqs. 25/26
    if not 1.0 < cr < 2.0:
        out.append(Violation(
            "contact ratio",
            f"{plain('CR', cr, 4)} ({inches('path of contact', path)}, "
            f"{inches('PB', pb_pinion)}, {degrees('THETA', op)}); expected 1 < CR < 2 "
            "(ISAD: one or two pairs in contact)",
        ))  # fmt: skip
    return out


# ------------------------------------------------------------------------------------------
# Clock rules (Tables 1-4; App. A constant-curvature tooth)
# ------------------------------------------------------------------------------------------
def check_clock_design(mesh: ClockMeshData, center_distance: float) -> list[Violation]:
    """Broken consistency rules of a clock mesh in the form of Tables 1-4 (empty: consistent):
    equal circular pitch, the App. A tooth (0 < t <= 2 rho, a > C_x, pointed tip outside the
    pitch circle), and contact over a whole gear pitch (derived model)."""
    out: list[Violation] = []
    ng, npn = mesh.n_gear, mesh.n_pinion
    p_gear = 2.0 * math.pi * mesh.gear_pitch_radius / ng
    p_pin = 2.0 * math.pi * mesh.pinion_pitch_radius / npn
    tol = 2.0 * math.pi * RADIUS_ROUNDING * (1.0 / ng + 1.0 / npn)
    if abs(p_gear - p_pin) > tol:
        out.append(Violation(
            "clock circular pitch",
            f"{inches('2 pi R_G / N_G', p_gear)} (N_G = {ng}) against "
            f"{inches('2 pi R_P / N_P', p_pin)} (N_P = {npn}); expected equal within "
            f"{tol / INCH:.1e} in",
        ))  # fmt: skip
    for who, rho, t, a, r in (
        ("gear", mesh.gear_arc_radius, mesh.gear_tooth_thickness, mesh.gear_center_distance,
         mesh.gear_pitch_radius),
        ("pinion", mesh.pinion_arc_radius, mesh.pinion_tooth_thickness,
         mesh.pinion_center_distance, mesh.pinion_pitch_radius),
    ):  # fmt: skip
        s = "G" if who == "gear" else "P"
        cx = rho - 0.5 * t  # eq. A1
        if not 0.0 <= cx < rho:
            out.append(Violation(
                "clock tooth thickness",
                f"{who}: {inches(f't_{s}', t)} against {inches(f'rho_{s}', rho)}; expected "
                f"0 < t_{s} <= 2 rho_{s} (App. A: C_x = rho - t/2 >= 0, h = sqrt(rho^2 - C_x^2))",
            ))  # fmt: skip
            continue
        if not a > cx:
            out.append(Violation(
                "clock centre of curvature",
                f"{who}: {inches(f'a_{s}', a)} against {inches('C_x = rho - t/2', cx)}; "
                f"expected a_{s} > C_x (eq. A17: a = sqrt((r_om - h)^2 + C_x^2))",
            ))  # fmt: skip
            continue
        r_om = math.sqrt(a * a - cx * cx) + math.sqrt(rho * rho - cx * cx)  # eqs. A2, A17
        if not r_om > r:
            out.append(Violation(
                "clock tooth tip",
                f"{who}: pointed tip radius {inches('r_om = sqrt(a^2 - C_x^2) + h', r_om)} "
                f"against {inches(f'R_{s}', r)}; expected the tip outside the pitch circle "
                "(eqs. A2, A17)",
            ))  # fmt: skip
    if out:
        return out
    model = ClockMeshModel(mesh, center_distance)
    n = 64
    for k in range(n):
        phi = model.pitch_g * (k / n - 0.5)
        if model.contact(phi) is None:
            out.append(Violation(
                "clock contact",
                f"no tooth pair in contact at gear angle {math.degrees(phi):.3f} deg with "
                f"{inches('b', center_distance)} ({inches('R_G + R_P', mesh.gear_pitch_radius + mesh.pinion_pitch_radius)}); "  # noqa: E501
                "expected a pair in contact over the whole gear pitch",
            ))  # fmt: skip
            break
    return out


def check_mesh_design(params: Mapping[str, float]) -> list[Violation]:
    """Broken rules of the user pair GearMesh parameters ``params`` select (model 2 with
    clock_mesh 0: the clock mesh; mesh 0 otherwise); missing design keys take their defaults.
    Empty when the parameters select a stored mesh."""
    p = design_defaults() | {k: float(v) for k, v in params.items()}
    model = int(p.get("model", 1))
    if model == 2:
        if int(p.get("clock_mesh", 1)) != 0:
            return []
        return check_clock_design(clock_pair(p), p["clock_center_distance"])
    if int(p.get("mesh", 2)) != 0:
        return []
    return check_involute_design(involute_pair(p), p["undercut_factor"])
