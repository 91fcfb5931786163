"""The SANDA2V input deck as design parameters, and its consistency rules.

Program SANDA2V (Lowen & Tepper 1982, ARLCD-TR-82013, App. A) read any S&A of the M739 type
from 15 cards, 57 quantities (the report's "Input Data" section, pp. 7-11).  Each quantity
is a parameter of the FMU that uses it, named here once with its card, its SANDA2V symbol,
its unit and its M739 value (``M739Data``) as default:

* the gear train (``GearTrain``) takes the rotor, gear 2 and escape-wheel bodies and the
  involute meshes (cards 3-15 without the pallet's quantities);
* the verge (``VergeEscapement``) takes the escapement (cards 1-2), the pallet's body and
  the train geometry that places its pivot in the fuze body (B1-B31: CONFIG, the pitch
  radii, R1-R4) and the escape-wheel pivot radius RHO3 of its friction (A17);
* what both take (SHARED) is one quantity of the mechanism, stated once in a scene.

The rules are those the report's equations assume: closed pivot triangles (B1-B12),
involute meshes (base radius = operating pitch radius x cos(operating pressure angle),
equal base pitches, pitch radii in the tooth ratio, contact ratio about 1 so that one pair
carries the load, contact starting on the driver's involute), the verge geometry of App. F
(F1-F3), the contact loop C10 and the escapement function (the tooth NT x Delta ahead
meets the exit face when the entrance face lets go).  ``violations`` lists every broken
rule of a design; FMU initialization refuses the first one of the rules it can decide.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, fields
from typing import Any

from .base import Variable, design_parameter
from .design_rules import Violation, degrees, inches, plain
from .m739_data import INERTIA_US, M739, MASS_US, M739Data
from .units import DEG, INCH, RPM_PER_RAD_S, rpm_to_rad_s
from .verge_geometry import contact_sensing, kinem

TRAIN = "train"
VERGE = "verge"
BOTH = frozenset({TRAIN, VERGE})

#: Source unit of each kind of quantity, as a scene may write it (pint).
SOURCE_UNITS = {
    "m": ("in", INCH),
    "rad": ("deg", DEG),
    "kg": ("lbf*s^2/in", MASS_US),
    "kg.m2": ("lbf*in*s^2", INERTIA_US),
    "rad/s": ("rpm", rpm_to_rad_s(1.0)),
    "1": ("", 1.0),
}


@dataclass(frozen=True)
class DeckEntry:
    """One quantity of the deck: where SANDA2V read it and which parameter carries it."""

    card: int
    symbol: str  # SANDA2V's name (FORTRAN variable)
    field: str  # M739Data field
    name: str  # the FMU parameter
    unit: str  # SI unit of the parameter
    meaning: str
    users: frozenset[str]
    integer: bool = False
    bounds: tuple[tuple[str, Any], ...] = ()

    @property
    def source(self) -> str:
        return f"SANDA2V: {self.symbol}"

    def default(self) -> float:
        """The M739's value, SI (the spin in rad/s from its rev/min)."""
        if self.field == "rpm":
            return M739.omega
        return getattr(M739, self.field)

    def variable(self) -> Variable:
        return design_parameter(
            self.name,
            self.unit,
            self.default(),
            self.meaning,
            self.source,
            "Integer" if self.integer else "Real",
            **dict(self.bounds),
        )


_POSITIVE = (("min", 0.0), ("exclusive_min", True))
_NONNEGATIVE = (("min", 0.0),)


def _e(card, symbol, field, name, unit, meaning, users, integer=False, bounds=()) -> DeckEntry:
    return DeckEntry(card, symbol, field, name, unit, meaning, users, integer, bounds)


T, V = frozenset({TRAIN}), frozenset({VERGE})
DECK: tuple[DeckEntry, ...] = (
    # Card 1: the escapement.
    _e(
        1,
        "A",
        "a",
        "center_distance",
        "m",
        "escapement centre distance O_p-O_s",
        V,
        False,
        _POSITIVE,
    ),
    _e(1, "B", "b", "wheel_tip_radius", "m", "escape-wheel tip radius b", V, False, _POSITIVE),
    _e(
        1,
        "C",
        "c",
        "pallet_radius",
        "m",
        "pallet radius c (pivot to face corner)",
        V,
        False,
        _POSITIVE,
    ),
    _e(1, "ALPHEN", "alpha_en", "entrance_face_angle", "rad", "entrance working-face angle", V),
    _e(1, "ALPHEX", "alpha_ex", "exit_face_angle", "rad", "exit working-face angle", V),
    _e(
        1,
        "NT",
        "nt",
        "teeth_spanned",
        "1",
        "escape-wheel teeth spanned by the verge",
        V,
        True,
        (("min", 1.0),),
    ),
    _e(
        1,
        "CONFIG",
        "config",
        "configuration",
        "1",
        "fuze-body configuration: 1 or 2 (the sign s6 of B1-B31)",
        BOTH,
        True,
        (("min", 1.0), ("max", 2.0)),
    ),
    # Card 2.
    _e(
        2,
        "EREST",
        "e_rest",
        "e_rest",
        "1",
        "coefficient of restitution",
        V,
        False,
        (("min", 0.0), ("max", 1.0)),
    ),
    _e(
        2,
        "LAMBDA",
        "lam",
        "pallet_angle",
        "rad",
        "angle between the entrance and exit pallet radii, lambda",
        V,
    ),
    _e(2, "N", "n_teeth", "wheel_teeth", "1", "escape-wheel teeth", V, True, (("min", 3.0),)),
    # Card 3: masses.
    _e(3, "M1", "m1", "rotor_mass", "kg", "rotor (gear 1) mass", T, False, _POSITIVE),
    _e(3, "M2", "m2", "gear2_mass", "kg", "gear 2 and pinion 2 mass", T, False, _POSITIVE),
    _e(3, "M3", "m3", "wheel_mass", "kg", "escape wheel and pinion 3 mass", T, False, _POSITIVE),
    _e(3, "MP", "mp", "pallet_mass", "kg", "pallet (verge) mass", V, False, _POSITIVE),
    # Card 4: moments of inertia about the pivots.
    _e(4, "I1", "i1", "rotor_inertia", "kg.m2", "rotor moment of inertia", T, False, _POSITIVE),
    _e(
        4,
        "I2",
        "i2",
        "gear2_inertia",
        "kg.m2",
        "gear 2 and pinion 2 moment of inertia",
        T,
        False,
        _POSITIVE,
    ),
    _e(
        4,
        "I3",
        "i3",
        "wheel_inertia",
        "kg.m2",
        "escape wheel and pinion 3 moment of inertia",
        T,
        False,
        _POSITIVE,
    ),
    _e(
        4,
        "IP",
        "ip",
        "pallet_inertia",
        "kg.m2",
        "verge (pallet) moment of inertia, I_p",
        V,
        False,
        _POSITIVE,
    ),
    # Cards 5 and 6.
    _e(
        5,
        "RC1",
        "rc1",
        "rotor_offset",
        "m",
        "rotor centre-of-mass offset from its pivot",
        T,
        False,
        _NONNEGATIVE,
    ),
    _e(
        5,
        "RCP",
        "rcp",
        "pallet_offset",
        "m",
        "pallet centre-of-mass offset from its pivot",
        V,
        False,
        _NONNEGATIVE,
    ),
    _e(
        5,
        "RHOP",
        "rho_p",
        "pallet_pivot_radius",
        "m",
        "pallet pivot (journal) radius",
        V,
        False,
        _NONNEGATIVE,
    ),
    _e(5, "RPM", "rpm", "spin", "rad/s", "fuze spin rate omega", BOTH, False, _NONNEGATIVE),
    _e(5, "PHI1CD", "phi1c", "rotor_start_angle", "rad", "rotor start angle Phi_1c", T),
    _e(5, "PSICCD", "psic", "pallet_offset_angle", "rad", "pallet eccentricity angle psi_c", V),
    _e(
        5,
        "PHID",
        "phi_start",
        "phi_local_start",
        "rad",
        "escape-wheel start angle on the entrance face (at phi = 0)",
        V,
    ),
    _e(
        6,
        "PHICUTD",
        "phi_cut",
        "arming_angle",
        "rad",
        "cumulative escape-wheel angle at which the rotor arms",
        T,
        False,
        _POSITIVE,
    ),
    _e(
        6,
        "MU",
        "mu",
        "mu",
        "1",
        "Coulomb friction of the train teeth and pivots (and the escape-wheel pivot)",
        BOTH,
        False,
        _NONNEGATIVE,
    ),
    _e(
        6,
        "MU1",
        "mu1",
        "mu1",
        "1",
        "Coulomb friction of the tooth faces and the verge pivot",
        V,
        False,
        _NONNEGATIVE,
    ),
    # Cards 7-10: the involute meshes.
    _e(
        7,
        "PSUBD1",
        "psubd1",
        "diametral_pitch1",
        "1/m",
        "diametral pitch, mesh 1",
        T,
        False,
        _POSITIVE,
    ),
    _e(
        7,
        "PSUBD2",
        "psubd2",
        "diametral_pitch2",
        "1/m",
        "diametral pitch, mesh 2",
        T,
        False,
        _POSITIVE,
    ),
    _e(8, "NG1", "ng1", "gear1_teeth", "1", "rotor gear (gear 1) teeth", T, True, (("min", 3.0),)),
    _e(8, "NG2", "ng2", "gear2_teeth", "1", "gear 2 teeth", T, True, (("min", 3.0),)),
    _e(8, "NP2", "np2", "pinion2_teeth", "1", "pinion 2 teeth", T, True, (("min", 3.0),)),
    _e(
        8,
        "NP3",
        "np3",
        "pinion3_teeth",
        "1",
        "pinion 3 (escape-wheel pinion) teeth",
        T,
        True,
        (("min", 3.0),),
    ),
    _e(
        9,
        "CAPRP1",
        "rp1_cap",
        "gear1_pitch_radius",
        "m",
        "operating pitch radius, gear 1",
        BOTH,
        False,
        _POSITIVE,
    ),
    _e(
        9,
        "CAPRP2",
        "rp2_cap",
        "gear2_pitch_radius",
        "m",
        "operating pitch radius, gear 2",
        BOTH,
        False,
        _POSITIVE,
    ),
    _e(
        9,
        "RP2",
        "rp2",
        "pinion2_pitch_radius",
        "m",
        "operating pitch radius, pinion 2",
        BOTH,
        False,
        _POSITIVE,
    ),
    _e(
        9,
        "RP3",
        "rp3",
        "pinion3_pitch_radius",
        "m",
        "operating pitch radius, pinion 3",
        BOTH,
        False,
        _POSITIVE,
    ),
    _e(10, "THETA1", "theta1", "pressure_angle1", "rad", "operating pressure angle, mesh 1", T),
    _e(10, "THETA2", "theta2", "pressure_angle2", "rad", "operating pressure angle, mesh 2", T),
    # Card 11: pivot distances from the spin axis.
    _e(
        11,
        "R1",
        "r1",
        "rotor_pivot_distance",
        "m",
        "rotor pivot distance from the spin axis",
        BOTH,
        False,
        _POSITIVE,
    ),
    _e(
        11,
        "R2",
        "r2",
        "gear2_pivot_distance",
        "m",
        "gear 2 pivot distance from the spin axis",
        BOTH,
        False,
        _POSITIVE,
    ),
    _e(
        11,
        "R3",
        "r3",
        "wheel_pivot_distance",
        "m",
        "escape-wheel pivot distance from the spin axis",
        BOTH,
        False,
        _POSITIVE,
    ),
    _e(
        11,
        "R4",
        "r4",
        "pallet_pivot_distance",
        "m",
        "pallet pivot distance from the spin axis",
        V,
        False,
        _POSITIVE,
    ),
    # Card 12: pivot (journal) radii.
    _e(12, "RHO1", "rho1", "rotor_pivot_radius", "m", "rotor pivot radius", T, False, _NONNEGATIVE),
    _e(
        12, "RHO2", "rho2", "gear2_pivot_radius", "m", "gear 2 pivot radius", T, False, _NONNEGATIVE
    ),
    _e(
        12,
        "RHO3",
        "rho3",
        "wheel_pivot_radius",
        "m",
        "escape-wheel pivot radius",
        BOTH,
        False,
        _NONNEGATIVE,
    ),
    # Card 13: base radii.
    _e(
        13,
        "CAPRB1",
        "rb1_cap",
        "gear1_base_radius",
        "m",
        "base radius, gear 1",
        T,
        False,
        _POSITIVE,
    ),
    _e(
        13,
        "CAPRB2",
        "rb2_cap",
        "gear2_base_radius",
        "m",
        "base radius, gear 2",
        T,
        False,
        _POSITIVE,
    ),
    _e(13, "RB2", "rb2", "pinion2_base_radius", "m", "base radius, pinion 2", T, False, _POSITIVE),
    _e(13, "RB3", "rb3", "pinion3_base_radius", "m", "base radius, pinion 3", T, False, _POSITIVE),
    # Card 14: outside radii.
    _e(
        14,
        "CAPRO1",
        "ro1_cap",
        "gear1_outside_radius",
        "m",
        "outside radius, gear 1",
        T,
        False,
        _POSITIVE,
    ),
    _e(
        14,
        "CAPRO2",
        "ro2_cap",
        "gear2_outside_radius",
        "m",
        "outside radius, gear 2",
        T,
        False,
        _POSITIVE,
    ),
    _e(
        14,
        "RO2",
        "ro2",
        "pinion2_outside_radius",
        "m",
        "outside radius, pinion 2",
        T,
        False,
        _POSITIVE,
    ),
    _e(
        14,
        "RO3",
        "ro3",
        "pinion3_outside_radius",
        "m",
        "outside radius, pinion 3",
        T,
        False,
        _POSITIVE,
    ),
    # Card 15: where each mesh starts in its contact range.
    _e(
        15,
        "J1",
        "j1",
        "mesh1_start",
        "1",
        "mesh 1 start as a fraction of its contact range (0 earliest contact)",
        T,
        False,
        (("min", 0.0), ("max", 1.0)),
    ),
    _e(
        15,
        "J2",
        "j2",
        "mesh2_start",
        "1",
        "mesh 2 start as a fraction of its contact range (0 earliest contact)",
        T,
        False,
        (("min", 0.0), ("max", 1.0)),
    ),
)
#: Whether an FMU refuses a design that breaks a rule (0 runs it all the same: to study a
#: failure; the verge still ends a run whose wheel skips teeth).
CHECK_DESIGN = Variable(
    "check_design",
    "parameter",
    "1",
    1,
    "1: refuse a design that breaks a consistency rule of the source; 0: run it anyway",
    "Integer",
    min=0.0,
    max=1.0,
)
#: Parameter name -> entry.
BY_NAME = {e.name: e for e in DECK}
#: The quantities both FMUs take: one value for the mechanism.
SHARED = tuple(e.name for e in DECK if e.users == BOTH)


#: The operating point (friction, spin, restitution): the quantities a scene varies most,
#: declared first.
OPERATING = ("mu1", "mu", "spin", "e_rest")


def deck_variables(user: str) -> tuple[Variable, ...]:
    """The design parameters of one FMU (``TRAIN`` or ``VERGE``): its operating point, then
    the drawing's quantities in deck order, and whether it checks them."""
    mine = [e for e in DECK if user in e.users]
    first = [e for name in OPERATING for e in mine if e.name == name]
    rest = [e for e in mine if e.name not in OPERATING]
    return (*(e.variable() for e in first + rest), CHECK_DESIGN)


def design_of(component: Any, user: str) -> M739Data:
    """The design a component was given: its deck parameters, the M739's values for the
    quantities it does not take (they do not enter its equations)."""
    return data_from({e.name: getattr(component, e.name) for e in DECK if user in e.users})


def data_from(values: dict[str, float]) -> M739Data:
    """A design from parameter values by name (SI; missing ones: the M739's)."""
    known = {f.name for f in fields(M739Data)}
    changes = {}
    for name, value in values.items():
        e = BY_NAME[name]
        if e.field not in known:
            continue
        if e.field == "rpm":
            value = value * RPM_PER_RAD_S if value != M739.omega else M739.rpm
        elif e.integer:
            value = int(value)
        if value != getattr(M739, e.field):
            changes[e.field] = value
    return M739.with_(**changes) if changes else M739


# ---------------------------------------------------------------------------------------
# Rules
# ---------------------------------------------------------------------------------------
#: The deck gives radii to 4-5 significant digits: relations between them hold to this.
ROUNDING = 5.0e-4
#: Contact ratios the one-pair mesh model of SANDA2V holds for (the M739's: 0.9990, 0.9993).
CONTACT_RATIO_RANGE = (0.95, 1.05)
#: App. F (F1, F2): alpha_en = 90 deg - lambda/2, to the deck's rounding of lambda.
FACE_ANGLE_TOLERANCE = 0.01 * DEG


#: SANDA2V symbol -> the parameter that carries it.
_BY_SYMBOL = {e.symbol: e.name for e in DECK}


def _named(symbol: str, text: str) -> str:
    """A quantity as the rules print it: its SANDA2V symbol and value, then the parameter
    that carries it (what a user sets)."""
    name = _BY_SYMBOL.get(symbol)
    return f"{text} ({name})" if name else text


def _in(symbol: str, value: float, digits: int = 5) -> str:
    return _named(symbol, inches(symbol, value, digits))


def _deg(symbol: str, value: float, digits: int = 3) -> str:
    return _named(symbol, degrees(symbol, value, digits))


def _triangle(rule: str, sides: tuple[tuple[str, float], ...], what: str) -> Iterator[Violation]:
    (n1, a), (n2, b), (n3, c) = sides
    if not abs(a - b) < c < a + b:
        yield Violation(
            rule,
            f"{what}: {_in(n1, a)}, {_in(n2, b)}, {_in(n3, c)}; expected "
            f"|{n1} - {n2}| < {n3} < {n1} + {n2}",
        )


def _mesh_limits(rb_drv: float, rb_dvn: float, theta: float, ro_drv: float, ro_dvn: float):
    al_in = ((rb_drv + rb_dvn) * math.tan(theta) - math.sqrt(ro_dvn**2 - rb_dvn**2)) / rb_drv
    al_fin = math.sqrt(ro_drv**2 - rb_drv**2) / rb_drv
    return al_in, al_fin


def train_violations(d: M739Data) -> list[Violation]:
    """The rules of the pivots and the involute train (cards 7-15)."""
    out: list[Violation] = []
    if d.config not in (1, 2):
        out.append(Violation("configuration", f"CONFIG = {d.config}; expected 1 or 2"))
    out += _triangle(
        "pivot triangle",
        (("R1", d.r1), ("R2", d.r2), ("CAPRP1 + RP2", d.rp1_cap + d.rp2)),
        "rotor and gear 2 pivots with the mesh-1 centre distance",
    )
    out += _triangle(
        "pivot triangle",
        (("R2", d.r2), ("R3", d.r3), ("CAPRP2 + RP3", d.rp2_cap + d.rp3)),
        "gear 2 and escape-wheel pivots with the mesh-2 centre distance",
    )
    meshes = (
        (
            1,
            ("CAPRP1", d.rp1_cap, "CAPRB1", d.rb1_cap, "CAPRO1", d.ro1_cap, "NG1", d.ng1),
            ("RP2", d.rp2, "RB2", d.rb2, "RO2", d.ro2, "NP2", d.np2),
            d.theta1,
            "THETA1",
            d.j1,
        ),
        (
            2,
            ("CAPRP2", d.rp2_cap, "CAPRB2", d.rb2_cap, "CAPRO2", d.ro2_cap, "NG2", d.ng2),
            ("RP3", d.rp3, "RB3", d.rb3, "RO3", d.ro3, "NP3", d.np3),
            d.theta2,
            "THETA2",
            d.j2,
        ),
    )
    for k, drv, dvn, theta, theta_name, j in meshes:
        out += _mesh_violations(k, drv, dvn, theta, theta_name, j)
    if not d.phi_cut > 0.0:
        out.append(Violation("arming angle", f"{_deg('PHICUTD', d.phi_cut)}; expected > 0"))
    return out


def _mesh_violations(k, drv, dvn, theta, theta_name, j) -> list[Violation]:
    out: list[Violation] = []
    cos_t = math.cos(theta)
    for rp_n, rp, rb_n, rb, ro_n, ro, _, _ in (drv, dvn):
        if abs(rb - rp * cos_t) > ROUNDING * rp:
            out.append(
                Violation(
                    "involute base radius",
                    f"mesh {k}: {_in(rb_n, rb)} against {rp_n} cos({theta_name}) = "
                    f"{rp * cos_t / INCH:.5f} in; expected equal within {ROUNDING:.2%}",
                )
            )
        if not ro > rb:
            out.append(
                Violation(
                    "outside radius beyond the base circle",
                    f"mesh {k}: {_in(ro_n, ro)}, {_in(rb_n, rb)}; expected {ro_n} > {rb_n}",
                )
            )
    (rpg_n, rpg, rbg_n, rbg, _, rog, ng_n, ng) = drv
    (rpp_n, rpp, rbp_n, rbp, _, rop, np_n, np_) = dvn
    if ng < 1 or np_ < 1:
        return out + [Violation("tooth counts", f"mesh {k}: {ng_n} = {ng}, {np_n} = {np_}")]
    ratio, teeth = rpg / rpp, ng / np_
    if abs(ratio - teeth) > ROUNDING * teeth:
        out.append(
            Violation(
                "pitch radii in the tooth ratio",
                f"mesh {k}: {rpg_n}/{rpp_n} = {ratio:.5f} against {ng_n}/{np_n} = {teeth:.5f}; "
                f"expected equal within {ROUNDING:.2%}",
            )
        )
    pitch_g, pitch_p = 2.0 * math.pi * rbg / ng, 2.0 * math.pi * rbp / np_
    if abs(pitch_g - pitch_p) > ROUNDING * pitch_g:
        out.append(
            Violation(
                "equal base pitch",
                f"mesh {k}: 2 pi {rbg_n}/{ng_n} = {pitch_g / INCH:.5f} in against 2 pi "
                f"{rbp_n}/{np_n} = {pitch_p / INCH:.5f} in; expected equal within {ROUNDING:.2%}",
            )
        )
    if not (rog > rbg and rop > rbp):
        return out
    al_in, al_fin = _mesh_limits(rbg, rbp, theta, rog, rop)
    if not al_in > 0.0:
        out.append(
            Violation(
                "contact on the involute",
                f"mesh {k}: contact starts at driver roll angle {al_in:.5f} rad "
                f"({theta_name}, {rbg_n}, {rbp_n} and the {np_n} outside radius); expected > 0: "
                f"the {np_n} tip meets the line of action inside the {ng_n} base circle "
                "(interference)",
            )
        )
    ratio_c = (al_fin - al_in) / (2.0 * math.pi / ng)
    lo, hi = CONTACT_RATIO_RANGE
    if not lo <= ratio_c <= hi:
        out.append(
            Violation(
                "contact ratio",
                f"mesh {k}: {plain('contact ratio', ratio_c)}; expected {lo} to {hi} (the "
                "SANDA2V mesh model carries the load on one tooth pair at a time)",
            )
        )
    if not 0.0 <= j <= 1.0:
        out.append(Violation("mesh start", f"{plain(f'J{k}', j)}; expected 0 to 1"))
    return out


def verge_violations(d: M739Data) -> list[Violation]:
    """The rules of the escapement (cards 1-2, App. C, E, F) and of its pallet pivot."""
    out: list[Violation] = []
    if not abs(d.r3 - d.r4) < d.a < d.r3 + d.r4:
        out.append(
            Violation(
                "pallet pivot triangle",
                f"{_in('A', d.a)}, {_in('R3', d.r3)}, {_in('R4', d.r4)}; expected "
                "|R3 - R4| < A < R3 + R4 (the pallet pivot at R4 from the spin axis)",
            )
        )
    if not abs(d.b - d.c) < d.a < d.b + d.c:
        out.append(
            Violation(
                "contact loop",
                f"{_in('A', d.a)}, {_in('B', d.b)}, {_in('C', d.c)}; expected "
                "|B - C| < A < B + C (the tooth-tip circle meets the pallet corners, C10)",
            )
        )
    expected = 0.5 * math.pi - 0.5 * d.lam
    if abs(d.alpha_en - expected) > FACE_ANGLE_TOLERANCE:
        out.append(
            Violation(
                "entrance face angle",
                f"{_deg('ALPHEN', d.alpha_en, 4)} against 90 deg - LAMBDA/2 = "
                f"{expected / DEG:.4f} deg ({_deg('LAMBDA', d.lam)}); expected equal "
                f"within {FACE_ANGLE_TOLERANCE / DEG:g} deg (App. F, F1-F2)",
            )
        )
    eta = 0.5 * d.lam - d.alpha_ex
    if not 0.0 < eta < 0.5 * math.pi:
        out.append(
            Violation(
                "exit face angle",
                f"eta = LAMBDA/2 - ALPHEX = {eta / DEG:.4f} deg ({_deg('LAMBDA', d.lam)}, "
                f"{_deg('ALPHEX', d.alpha_ex, 4)}); expected 0 < eta < 90 deg (App. F, F3)",
            )
        )
    if not 1 <= d.nt < d.n_teeth / 2:
        out.append(
            Violation(
                "teeth spanned",
                f"NT = {d.nt}, N = {d.n_teeth}; expected 1 <= NT < N/2",
            )
        )
    if out:
        return out  # the face kinematics below need a closed contact loop
    out += _escapement_function(d)
    return out


def _face_end(d: M739Data, phi0: float, alpha: float, sign: int) -> float | None:
    """The wheel angle, from phi0 on, where the tooth tip reaches the face end (g = 0);
    sign +1 on the entrance face (g > 0 on it), -1 on the exit face."""
    step = 0.05 * DEG
    phi = phi0
    while sign * kinem(phi, alpha, d.a, d.b, d.c)[1] > 0.0:
        phi += step
        if phi > phi0 + 2.0 * math.pi / d.n_teeth * (d.nt + 1):
            return None
    lo, hi = phi - step, phi
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        if sign * kinem(mid, alpha, d.a, d.b, d.c)[1] > 0.0:
            lo = mid
        else:
            hi = mid
    return lo


def _escapement_function(d: M739Data) -> list[Violation]:
    """With the tooth at PHID on the entrance face, the face must hold it (g > 0, C15), and
    when it slides off the face end the tooth NT x Delta ahead must lie before the exit
    face's end (E5: g' <= 0), so that it lands on that face; otherwise the wheel runs past
    the verge (skips teeth)."""
    phi0 = d.phi_start
    cap_a = d.a * math.cos(d.alpha_en) + d.b * math.cos(phi0 - d.alpha_en)
    cap_b = d.a * math.sin(d.alpha_en) - d.b * math.sin(phi0 - d.alpha_en)
    cap_c = d.c * math.sin(d.alpha_en)
    if cap_a**2 + cap_b**2 < cap_c**2 or kinem(phi0, d.alpha_en, d.a, d.b, d.c)[1] <= 0.0:
        return [
            Violation(
                "start on the entrance face",
                f"{_deg('PHID', phi0)} with {_in('A', d.a)}, {_in('B', d.b)}, "
                f"{_in('C', d.c)}, {_deg('ALPHEN', d.alpha_en, 4)}: the tooth tip is "
                "not on the entrance face; expected g > 0 (C15)",
            )
        ]
    end = _face_end(d, phi0, d.alpha_en, 1)
    if end is None:
        return []
    psi = kinem(end, d.alpha_en, d.a, d.b, d.c)[0]
    delta = 2.0 * math.pi / d.n_teeth
    _, g_exit = contact_sensing(
        end + d.nt * delta, psi + 2.0 * math.pi - d.lam, d.alpha_ex, d.a, d.b, d.c
    )
    if g_exit > 0.0:
        return [
            Violation(
                "escapement function",
                f"when the entrance face lets the tooth go (phi = {end / DEG:.3f} deg, "
                f"psi = {psi / DEG:.3f} deg), the tooth NT x Delta = {d.nt} x "
                f"{delta / DEG:.4f} deg ahead is {g_exit / INCH:.5f} in past the exit face's "
                f"end; expected before it (E5: g' <= 0), else the wheel skips teeth "
                f"({_in('A', d.a)}, {_in('B', d.b)}, {_in('C', d.c)}, "
                f"{_deg('LAMBDA', d.lam)}, {_deg('ALPHEX', d.alpha_ex, 4)})",
            )
        ]
    return []


def violations(d: M739Data, users: frozenset[str] = BOTH) -> list[Violation]:
    """Every broken rule of a design, of the FMUs in ``users``."""
    out: list[Violation] = []
    if TRAIN in users:
        out += train_violations(d)
    if VERGE in users:
        out += verge_violations(d)
    return out
