"""Input data of the M739 S&A mechanism (Lowen & Tepper 1982, ARLCD-TR-82013), in SI.

The report's data are in inch, lbf, second, lb.s^2/in and degrees; the US values are
authoritative (the report's own SI conversions are about 0.16 % high).  Every number is
written here once, in the source unit, and converted once with the factors below.
Where the input echo of the App. A listing disagrees with the Input Data section (pp. 7-11) and
the sample output, the latter win: PHID 139 deg, M1 0.3165e-4, RP2 0.05796 in, PHI1CD -120.134.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from .units import DEG, INCH, LBF, rpm_to_rad_s

MASS_US = LBF / INCH  # kg per lb.s^2/in
INERTIA_US = LBF * INCH  # kg.m^2 per in.lb.s^2
TORQUE_US = LBF * INCH  # N.m per in.lb


@dataclass(frozen=True)
class M739Data:
    """Geometry, masses and friction of the M739 S&A (configuration 2), SI units."""

    # Escapement (App C-F); source: inch and degrees.
    a: float = 0.226 * INCH  # pivot distance O_p-O_s
    b: float = 0.168 * INCH  # escape-wheel tip radius
    c: float = 0.13138 * INCH  # pallet radius
    alpha_en: float = 43.5352 * DEG  # entrance working-face angle
    alpha_ex: float = 29.2981 * DEG  # exit working-face angle
    nt: int = 4  # escape-wheel teeth spanned by the verge
    config: int = 2  # fuze-body configuration (s6 = -1)
    e_rest: float = 0.0  # coefficient of restitution
    lam: float = 92.93 * DEG  # angle between entrance and exit pallet radii
    n_teeth: int = 22  # escape-wheel teeth
    # Masses; source lb.s^2/in (M1 = 0.3165e-4, the echo's .31850E-04 is an OCR typo).
    m1: float = 0.3165e-4 * MASS_US
    m2: float = 0.3275e-5 * MASS_US
    m3: float = 0.2631e-5 * MASS_US
    mp: float = 0.1640e-5 * MASS_US
    # Moments of inertia about the pivots; source in.lb.s^2.
    i1: float = 0.1967e-5 * INERTIA_US
    i2: float = 0.4026e-7 * INERTIA_US
    i3: float = 0.2125e-7 * INERTIA_US
    ip: float = 0.1950e-7 * INERTIA_US
    # Eccentricities and pivot radii; source inch.
    rc1: float = 0.0576 * INCH  # rotor c.m. offset
    rcp: float = 0.0 * INCH  # pallet c.m. offset
    rho_p: float = 0.0227 * INCH  # pallet pivot radius
    rho1: float = 0.03075 * INCH
    rho2: float = 0.015 * INCH
    rho3: float = 0.015 * INCH
    # Angles; source degrees (PHI1CD sign restored, PHID = 139 not the echo's 138).
    phi1c: float = -120.134 * DEG  # rotor start angle
    psic: float = 0.0 * DEG  # pallet eccentricity angle
    phi_start: float = 139.0 * DEG  # escape-wheel start angle (entrance face)
    phi_cut: float = 1485.0 * DEG  # cumulative escape-wheel angle at arming
    # Friction (Coulomb); mu: gear train and escape-wheel pivot, mu1: verge.
    mu: float = 0.10
    mu1: float = 0.10
    # Spin; source rev/min.
    rpm: float = 30000.0
    # Gear train (diametral pitch, teeth, pitch radii, pressure angles); source 1/in, inch
    # and degrees.  The diametral pitches are read but enter no equation.
    psubd1: float = 80.0 / INCH
    psubd2: float = 100.0 / INCH
    ng1: int = 64
    ng2: int = 36
    np2: int = 9
    np3: int = 8
    rp1_cap: float = 0.41214 * INCH  # pitch radius gear 1
    rp2_cap: float = 0.19039 * INCH  # pitch radius gear 2
    rp2: float = 0.05796 * INCH  # pitch radius pinion 2 (echo .05706 is an OCR typo)
    rp3: float = 0.04231 * INCH  # pitch radius pinion 3
    theta1: float = 24.215 * DEG  # operating pressure angle, mesh 1
    theta2: float = 27.326 * DEG  # operating pressure angle, mesh 2
    r1: float = 0.250 * INCH  # pivot distances from the spin axis
    r2: float = 0.317 * INCH
    r3: float = 0.309 * INCH
    r4: float = 0.304 * INCH
    rb1_cap: float = 0.37588 * INCH  # base radii
    rb2_cap: float = 0.16915 * INCH
    rb2: float = 0.05286 * INCH
    rb3: float = 0.03759 * INCH
    ro1_cap: float = 0.41425 * INCH  # outside radii
    ro2_cap: float = 0.19404 * INCH
    ro2: float = 0.07670 * INCH
    ro3: float = 0.05580 * INCH
    j1: float = 0.0  # mesh initialisation (0 = earliest contact)
    j2: float = 0.0

    @property
    def omega(self) -> float:
        """Spin rate [rad/s]."""
        return rpm_to_rad_s(self.rpm)

    @property
    def n31(self) -> float:
        """Rotor-to-escape-wheel ratio (B122): phi1_dot = n31 * phi_dot."""
        return (self.np2 * self.np3) / (self.ng1 * self.ng2)

    @property
    def n32(self) -> float:
        """Gear-2-to-escape-wheel ratio (B159): phi2_dot = n32 * phi_dot."""
        return -self.np3 / self.ng2

    @property
    def i_stot(self) -> float:
        """Frictionless inertia referred to the escape-wheel shaft (B213)."""
        return self.i3 + self.i2 * self.n32**2 + self.i1 * self.n31**2

    @property
    def tooth_angle(self) -> float:
        """Escape-wheel tooth pitch, Delta = 2 pi / N."""
        return 2.0 * math.pi / self.n_teeth

    def with_(self, **changes: float) -> M739Data:
        """A copy with some values replaced (e.g. mu, mu1, rpm, e_rest)."""
        return replace(self, **changes)


M739 = M739Data()
