"""Data of the press roll feed of Xu (1993), converted once to SI.

Xu (1993), *Contributions to the Theory of Machine Dynamics* (PhD thesis, CUNY): Table 1 (p. 36),
Part I §7d-e (pp. 35-46), Tables 2-5 (pp. 82-105) and App. H (pp. 168-177).  Source units are
inch, lbf, second and radian.
Every constant below states its printed value and unit in the comment next to it; the
conversion factors are the only place where inch/lbf appear.  Tests convert back with the
same factors when they compare against printed numbers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

# -- unit factors (exact definitions) -------------------------------------------------------
from .units import INCH as IN
from .units import LB_PER_IN, LBF, LBF_IN, PSI

RHO_UNIT = LBF / IN**4  # kg/m^3 per lbf.s^2/in^4
G_STD = 9.80665  # m/s^2, converts the 9.1 lb lumped weight


@dataclass(frozen=True)
class RSSRLinkage:
    """RSSR dimensions (Appendix A): crank a1, coupler chord a3, rocker a4, frame s1..s3 [m]."""

    a1: float
    a3: float
    a4: float
    s1: float
    s2: float
    s3: float


@dataclass(frozen=True)
class BentCoupler:
    """Bent tubular coupler of Part I §4 (pp. 15-18): two sections of length L at +-alpha to AC."""

    length: float  # L, one section [m]
    alpha: float  # half bend angle [rad]
    d_outer: float  # [m]
    d_inner: float  # [m]
    youngs: float  # E [Pa]
    density: float  # rho [kg/m^3]
    c_co: float  # distributed viscous damping per unit length [N.s/m^2]
    p1: float  # regime-2 mean of the extra inertia function P1 (B.17) [m]
    gauge_x1: float  # strain gauge position on section 1, measured from A [m]
    lumped_mass: float = 0.0  # App. G: mass clamped at B [kg] (Run 3)
    # rho_M = lumped_factor M / A (G.9): 0.05 per inch as printed [1/m]
    lumped_factor: float = 0.05 / IN  # = LUMPED_MASS_FACTOR
    # the coupler damping 0.45 L C_co (18.e): 0.45 as printed, 3 - 8/pi exactly (B.7)
    damping_factor: float = 0.45


@dataclass(frozen=True)
class FourierForcing:
    """App. H Fourier coefficients (full cycle, constant + first harmonic).

    ``f1`` are those of F1/phi1dot^2 (coupler inertia forcing, B.20) [m^2];
    ``phi4`` are those of phi4r [rad] (thesis sign, phi4 decreasing on the feed stroke).
    """

    f1: tuple[float, float, float]  # a10, a11, b11
    phi4: tuple[float, float, float]  # a30, a31, b31


# -- Table 1: standard feed mechanism --------------------------------------------------------
# a1 = 0.965 in as printed; App. H was evidently computed with a1 = 0.955 in (derived: only
# 0.955 in reproduces its phi4 = 101.07 deg at phi1 = 255.645 deg and its a31, b31).
LINKAGE_TABLE1 = RSSRLinkage(
    a1=0.965 * IN, a3=32.523 * IN, a4=4.500 * IN, s1=1.156 * IN, s2=8.260 * IN, s3=31.410 * IN
)
LINKAGE_APP_H = replace(LINKAGE_TABLE1, a1=0.955 * IN)

# Table 3 (Part II mechanism, straight coupler): printed a2 is the coupler, a3 the rocker.
LINKAGE_TABLE3 = RSSRLinkage(
    a1=0.975 * IN, a3=32.078 * IN, a4=4.5 * IN, s1=2.25 * IN, s2=0.0, s3=31.325 * IN
)

COUPLER_STANDARD = BentCoupler(
    length=16.625 * IN,  # 16.625 in
    alpha=math.radians(12.0),  # 12.0 deg
    d_outer=1.00 * IN,  # 1.00 in
    d_inner=0.75 * IN,  # 0.75 in
    youngs=30.0e6 * PSI,  # 30e6 lbf/in^2
    density=7.3e-4 * RHO_UNIT,  # 7.3e-4 lbf.s^2/in^4
    c_co=0.06 * LBF / IN**2,  # 0.06 lbf.s/in^2 (per unit length)
    p1=2.65 * IN,  # 2.65 in, regime-2 average of P1 (App. C b)
    gauge_x1=11.0 * IN,  # 11 in from A
)
# App. G: about 9.1 lb clamped at B for Run 3.
COUPLER_RUN3 = replace(COUPLER_STANDARD, lumped_mass=9.1 * LBF / G_STD)

# Coupler damping: the thesis rounds 3 - 8/pi = 0.4535 to 0.45 (18.e) and fitted C_co to Run 1
# with 0.45, so the fitted product 0.45 L C_co is what the data carry.
COUPLER_DAMPING_FACTOR = 0.45
# App. G (G.9): rho_M = 0.05 M / A, the 0.05 per inch.
LUMPED_MASS_FACTOR = 0.05 / IN

# Rocker + clutch input shaft (Table 1): 0.1286 lbf.in.s^2.
J_O4 = 0.1286 * LBF_IN
# Clutch output shaft + roller without strip (Table 1): 0.114 lbf.in.s^2.
J_O5_SHAFT = 0.114 * LBF_IN
# Feed roller radius implied by the referred strip inertias of Part I §7e (derived: m r^2 of
# the steel strips gives 0.298 and 0.703 lbf.in.s^2 with r = 2.5 in).
ROLLER_RADIUS = 2.5 * IN

# -- clutch (Part I eq. 1, Table 1, Part II) -------------------------------------------------
K_SP = 2.0e5 * LBF_IN  # 2e5 lbf.in.rad^-3/2
C_SP = 11.0 * LBF_IN  # 11.0 lbf.in.s, Part I linear damping fitted to Run 1
C_NL = 62.6 * LBF_IN  # 62.6 lbf.in.s.rad^-5/4 (101)
N_DAMP = 0.25  # damping exponent n = (beta - 1)/2 (91)
DECAY_RATIO = 0.669  # Table 2 overall average
J_PART2 = 0.815 * LBF_IN  # 0.815 lbf.in.s^2 (printed SI 0.092 N.m.s^2)


@dataclass(frozen=True)
class FeedRun:
    """One run of Part I §7e, pp. 37-46 (referred strip inertia from the printed values)."""

    name: str
    rpm: float
    brake_torque: float  # T_b [N.m]
    j_strip: float  # referred strip inertia [kg.m^2]
    coupler: BentCoupler


RUNS: dict[int, FeedRun] = {
    1: FeedRun("run1", 200.0, 160.0 * LBF_IN, 0.298 * LBF_IN, COUPLER_STANDARD),
    2: FeedRun("run2", 300.0, 300.0 * LBF_IN, 0.703 * LBF_IN, COUPLER_STANDARD),
    3: FeedRun("run3", 200.0, 260.0 * LBF_IN, 0.298 * LBF_IN, COUPLER_RUN3),
}

# -- Appendix H (Run 1, linearized model) ----------------------------------------------------
APP_H_FOURIER = FourierForcing(
    # a10, a11, b11 printed without unit: rhoA F1 is a force, so F1/phi1dot^2 is in in^2.
    f1=(-0.03798 * IN**2, 7.2439 * IN**2, -12.2350 * IN**2),
    phi4=(1.5431, -0.0563, -0.2132),  # a30, a31, b31 [rad]
)
APP_H_J_O5 = 0.41 * LBF_IN  # Table H-1: 0.41 lbf.in.s^2
APP_H_M_E = 0.00632 * LB_PER_IN  # 0.00632 lbf.s^2/in
APP_H_K_E = 1333.78 * LB_PER_IN  # 1333.78 lbf/in
APP_H_F2 = 0.098 / IN  # 0.098 rad/in
APP_H_ZETA_CO = 0.0773
APP_H_OMEGA_CO_HZ = 73.1
APP_H_OMEGA_SP_HZ = 41.5
APP_H_ZETA_SP = 0.0515
APP_H_K_L1 = 18566.36 * LBF_IN  # lbf.in/rad (C.8)
APP_H_K_L2 = 27849.5 * LBF_IN  # lbf.in/rad (C.3)
APP_H_SYSTEM = {"f1_hz": 36.765, "f2_hz": 82.166, "alpha1": 12.245, "alpha2": 36.681}
APP_H_PHI1_START_DEG = 255.645  # Table H-2

# Table H end values (thesis sign, phi1 absolute, q in inch, q' in in/rad, windup in rad).
# H-3 and H-9 q' read 0.0710 / 0.0721 (printed 0.710 / 0.721; the printed Regime 1 solution
# gives 0.0713 there).
APP_H_END_VALUES = {
    "R1_startup": {"phi1_deg": 271.114, "phi5_deg": 101.07, "q_in": 0.0105, "dq_in": 0.0710},
    "R2_startup": {
        "phi1_deg": 434.694,
        "phi5_deg": 76.203,
        "q_in": 0.00608,
        "dq_in": 0.02323,
        "windup": 0.0069,
    },
    "R3_startup": {"phi1_deg": 450.450, "q_in": -0.00172, "dq_in": -0.0483},
    "R4_startup": {"phi1_deg": 615.642, "phi5_deg": 101.057, "q_in": 0.00174, "dq_in": 0.00048},
    "R1_normal": {
        "phi1_deg": 271.687 + 360.0,
        "phi5_deg": 101.062,
        "q_in": 0.0122,
        "dq_in": 0.0721,
    },
    "R2_normal": {
        "phi1_deg": 434.694 + 360.0,
        "phi5_deg": 76.203,
        "q_in": 0.00593,
        "dq_in": 0.02276,
        "windup": 0.0068,
    },
    "R3_normal": {"phi1_deg": 450.450 + 360.0, "q_in": -0.00172, "dq_in": -0.0483},
    "R4_normal": {
        "phi1_deg": 615.642 + 360.0,
        "phi5_deg": 101.057,
        "q_in": 0.00174,
        "dq_in": 0.00048,
    },
}


# -- Table 4: Formsprag HPI-500 clutch (Part III) ---------------------------------------------
@dataclass(frozen=True)
class SpragGeometry:
    r_outer: float  # R_o [m]
    r_inner: float  # R_i [m]
    r_sprag: float  # R_s, contact-profile radius [m]
    offset: float  # a = C_i C_o [m]
    n_sprags: int  # Z
    strut_inner: float  # alpha [rad]
    strut_outer: float  # beta [rad]
    youngs: float  # E_i = E_o = E_s [Pa]
    poisson: float  # nu
    m_sprag: float  # m_s [kg]
    j_sprag: float  # J_s [kg.m^2]
    j_inner: float  # J_i, inner race assembly [kg.m^2]


TABLE4 = SpragGeometry(
    r_outer=1.349 * IN,
    r_inner=0.9735 * IN,
    r_sprag=0.1878 * IN,
    offset=0.0224 * IN,
    n_sprags=24,
    strut_inner=0.07,
    strut_outer=0.05,
    youngs=30.0e6 * PSI,
    poisson=0.3,
    m_sprag=5.67e-5 * LB_PER_IN,  # 5.67e-5 lbf.s^2/in
    j_sprag=8.71e-7 * LBF_IN,  # 8.71e-7 lbf.in.s^2 (Table 4 prints lb.s^2/in)
    j_inner=34.7e-4 * LBF_IN,  # Table 5: 34.7e-4 lbf.in.s^2
)

# -- Part II experiment (Part II §4, eqs. 92-104, Figs. 21-22, pp. 75-87) --------------------
PART2_BRAKE_TORQUES = {
    72.0: tuple(v * LBF_IN for v in (52.0, 250.0, 370.0, 470.0)),
    197.0: tuple(v * LBF_IN for v in (85.0, 370.0, 600.0)),
}
