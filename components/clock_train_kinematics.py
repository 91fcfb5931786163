"""Kinematics of both meshes of a two-pass clock gear train.

Source: the US Army fuze report of about 1980 (cover page lost) whose Task 1 gives test plans
for the M577 SSD and M739 S&A escapement centre distance and whose Task 2 gives the forward and
inverse kinematics of a two-pass clock train (eqs. 1–126, Figs. 1–4), after Lowen & Tepper,
*Fuze Gear Train Analysis* (1979), App. G; "the clock train report" below.

Rotor (gear 1) -> mesh 1 -> pinion 2 / gear 2 (one cluster) -> mesh 2 -> pinion 3 / escape wheel.
Each mesh passes through two contact phases (Task 2, Figs. 1–4): round-on-round (RoR, the gear
tip round on the pinion leaf round: a four-bar O_G-C_G-C_P-O_P, eqs. 8–22) and round-on-flank
(RoF, the gear tip round on the radial pinion flank, eqs. 23–33), switching at the transition
angle (eqs. 34–40).  Every position equation has the form A sin x + B cos x = C (eqs. 15, 30, 38,
57, 70, ...); the root is taken as atan2(A, B) +- acos(C / sqrt(A^2 + B^2)), the sign fixed once
by continuity with the transition.

Mesh 2 is the mirror image of mesh 1 (the sense of rotation is reversed; eqs. 46–87 carry the
mirrored signs): with phi1 = -phi2G, phi2P = -psi and beta1 = -beta2 the mesh-2 equations
(53–82, 107–126) become the mesh-1 equations, so one set of formulas serves both.  The pinion
tooth form obeys the consistency relation a_P = sqrt(f_P^2 + rho_P^2),
delta_P = atan(rho_P / f_P) - alpha_P (derived here, not in the report: the tip-round centre
lies on the flank normal at f_P), which makes angle and speed ratio continuous at the
RoR -> RoF change.  Successive tooth pairs hand over where the sensing equation (41–45, 83–87)
finds the next pair touching; angles are then carried over by the tooth spacings.

Representative M739-like geometry (the clock train report gives none): the tooth counts and
centre distances of the M739 train in Lowen & Tepper (1982, ARLCD-TR-82013, Input Data,
pp. 7-11): rotor gear 64 teeth on 0.4701 in to pinion 2 of 9 leaves, gear 2 of 36 teeth on
0.2327 in to pinion 3 of 8 leaves, 32:1 overall.  The clock tooth form is chosen: gear tip-round
centres on the pitch circles (a_G = R_G, so the mean ratio is -N_G/N_P), radial pinion flanks
meeting the tip round at the pinion pitch radius (f_P = r_P), tip rounds rho_G = rho_P = 0.2 f_P,
offsets delta_G = 0.1 and alpha_P = 0.3 rad (phasing only), frame directions +-0.2 rad.  This
keeps the shape of a synthetic check geometry verified here against finite differences: each
pair first touches round-on-round, passes to the flank, and hands over while on the flank, with
the speed ratio within about 5 % of its mean.

Task 1 of the report (Test Plans 1 and 2) is given as data: ``TEST_PLANS`` and the escapement
C.D. sweep ``M739_CD_SWEEP`` (nominal from the M739 input data of Lowen & Tepper 1982; the
tolerance band is in neither source and is assumed).  Angles in rad, lengths in m.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .units import INCH

_TWO_PI = 2.0 * math.pi
PHASES = ("auto", "ror", "rof")


def _solve(a: float, b: float, c: float, sign: float) -> float:
    """Root of a sin x + b cos x = c (eq. 15 and its twins, in atan2 form), branch sign +-1."""
    r = math.hypot(a, b)
    if abs(c) > r:
        raise ValueError("no contact: A^2 + B^2 < C^2 (the pair cannot be assembled here)")
    return math.atan2(a, b) + sign * math.acos(c / r)


def _near(x: float, ref: float) -> float:
    return ref + math.remainder(x - ref, _TWO_PI)


def _derivatives(c: tuple[float, ...], x: float) -> tuple[float, float]:
    """dx/du and d^2x/du^2 of the root x(u) of G = A sin x + B cos x - C(u) = 0 (implicit
    differentiation as in eqs. 94–97)."""
    a, b, _, da, db, dc, dda, ddb, ddc = c
    sx, cx = math.sin(x), math.cos(x)
    g_x = a * cx - b * sx
    d1 = -(da * sx + db * cx - dc) / g_x
    g_uu = dda * sx + ddb * cx - ddc
    g_ux = da * cx - db * sx
    g_xx = -(a * sx + b * cx)
    return d1, -(g_uu + 2.0 * g_ux * d1 + g_xx * d1 * d1) / g_x


@dataclass(frozen=True)
class ClockMesh:
    """One clock mesh, in the mesh-1 convention of eqs. 1–45 (mirrored=True for mesh 2).

    b, beta: centre distance and direction of O_gear -> O_pinion; a_g, delta_g, rho_g: gear
    tip-round centre distance, angular offset (direction phi - delta_g) and radius; alpha_p:
    flank direction offset (flank along phi_P + alpha_p); f_p: flank length to the tip round;
    rho_p: pinion tip round.  n_gear, n_pinion set the tooth spacings (eqs. 41–45).
    """

    b: float
    beta: float
    a_g: float
    delta_g: float
    rho_g: float
    alpha_p: float
    f_p: float
    rho_p: float
    n_gear: int
    n_pinion: int
    mirrored: bool = False
    _cache: dict = field(default_factory=dict, compare=False, repr=False)

    # -- derived pinion form (consistency relation derived here) ---------------------------
    @property
    def a_p(self) -> float:
        return math.hypot(self.f_p, self.rho_p)

    @property
    def delta_p(self) -> float:
        return math.atan2(self.rho_p, self.f_p) - self.alpha_p

    @property
    def beta1(self) -> float:
        """Frame direction in the mesh-1 convention."""
        return -self.beta if self.mirrored else self.beta

    # -- position equations in the mesh-1 convention ---------------------------------------
    def _forward_abc(self, phi1: float, phase: str) -> tuple[float, ...]:
        """A, B, C of A sin phi2P + B cos phi2P = C (eqs. 11–14, 29) and their first and second
        derivatives in phi1 (true derivatives, unlike the report's "D" names in eqs. 18–21)."""
        ag, b, be, dg, dp = self.a_g, self.b, self.beta1, self.delta_g, self.delta_p
        if phase == "ror":
            ap, ll = self.a_p, self.rho_g + self.rho_p
            sq, cq = math.sin(phi1 - dg + dp), math.cos(phi1 - dg + dp)
            sw, cw = math.sin(phi1 - dg - be), math.cos(phi1 - dg - be)
            k = ag * b / ap
            return (
                b * math.sin(be + dp) - ag * sq,
                b * math.cos(be + dp) - ag * cq,
                (ll**2 - ag**2 - ap**2 - b**2) / (2 * ap) + k * cw,
                -ag * cq, ag * sq, -k * sw,
                ag * sq, ag * cq, -k * cw,
            )  # fmt: skip
        ap_ = self.alpha_p
        sq, cq = math.sin(phi1 - dg - ap_), math.cos(phi1 - dg - ap_)
        return (
            b * math.cos(ap_ - be) - ag * cq,
            ag * sq + b * math.sin(ap_ - be),
            self.rho_g,
            ag * sq, ag * cq, 0.0,
            ag * cq, -ag * sq, 0.0,
        )  # fmt: skip

    def _inverse_def(self, phi2p: float, phase: str) -> tuple[float, ...]:
        """D, E, F of D sin phi1 + E cos phi1 = F (eqs. 91, 100) with first and second
        derivatives in phi2P (eqs. 93, 96, 102, 105)."""
        ag, b, be, dg, dp = self.a_g, self.b, self.beta1, self.delta_g, self.delta_p
        if phase == "ror":
            ap, ll = self.a_p, self.rho_g + self.rho_p
            sq, cq = math.sin(phi2p - dp + dg), math.cos(phi2p - dp + dg)
            sr, cr = math.sin(phi2p - dp - be), math.cos(phi2p - dp - be)
            k = 2 * ag * ap
            return (
                -k * sq - 2 * ag * b * math.sin(be + dg),
                -k * cq - 2 * ag * b * math.cos(be + dg),
                ll**2 - ag**2 - ap**2 - b**2 - 2 * ap * b * cr,
                -k * cq, k * sq, 2 * ap * b * sr,
                k * sq, k * cq, 2 * ap * b * cr,
            )  # fmt: skip
        sq, cq = math.sin(phi2p + self.alpha_p + dg), math.cos(phi2p + self.alpha_p + dg)
        sr, cr = math.sin(phi2p + self.alpha_p - be), math.cos(phi2p + self.alpha_p - be)
        return (
            ag * cq, -ag * sq, self.rho_g - b * sr,
            -ag * sq, -ag * cq, -b * cr,
            -ag * cq, ag * sq, b * sr,
        )  # fmt: skip

    # -- transition and branch choice -------------------------------------------------------
    def transition(self) -> tuple[float, float]:
        """(phi1T, phi2PT) in the mesh-1 convention: the flank meets the tip round (eqs. 37–40).

        Of the two roots (entry onto the flank, exit from it) the entry is the one reached
        first as the gear turns forward (smaller phi1).
        """
        if "transition" not in self._cache:
            ag, b, be, dg, rg, fp = self.a_g, self.b, self.beta1, self.delta_g, self.rho_g, self.f_p
            ap_ = self.alpha_p
            a = rg * math.cos(ap_ - be) + fp * math.sin(ap_ - be)
            bb = rg * math.sin(ap_ - be) - fp * math.cos(ap_ - be)
            c = (rg**2 + b**2 + fp**2 - ag**2) / (2 * b)
            roots = []
            for sign in (1.0, -1.0):
                x = _solve(a, bb, c, sign)
                cos1 = (-rg * math.sin(x + ap_) + b * math.cos(be) + fp * math.cos(x + ap_)) / ag
                sin1 = (rg * math.cos(x + ap_) + b * math.sin(be) + fp * math.sin(x + ap_)) / ag
                phi1 = math.atan2(sin1, cos1) + dg
                # leaf must face the gear: the flank points back towards O_gear
                if math.cos(x + ap_ - be) < 0.0:
                    roots.append((phi1, _near(x, math.pi + be)))
            self._cache["transition"] = min(roots)
        return self._cache["transition"]

    def _sign(self, kind: str, phase: str) -> float:
        """Root sign giving the transition configuration (by continuity; the report leaves it to
        "geometric considerations")."""
        key = (kind, phase)
        if key not in self._cache:
            p1, p2 = self.transition()
            best = None
            for sign in (1.0, -1.0):
                if kind == "fwd":
                    a, b, c = self._forward_abc(p1, phase)[:3]
                    err = abs(math.remainder(_solve(a, b, c, sign) - p2, _TWO_PI))
                else:
                    a, b, c = self._inverse_def(p2, phase)[:3]
                    err = abs(math.remainder(_solve(a, b, c, sign) - p1, _TWO_PI))
                if best is None or err < best[0]:
                    best = (err, sign)
            self._cache[key] = best[1]
        return self._cache[key]

    # -- single-pair kinematics, mesh-1 convention -----------------------------------------
    def _phase_fwd(self, phi1: float, phase: str) -> str:
        if phase != "auto":
            return phase
        return "ror" if phi1 < self.transition()[0] else "rof"

    def _phase_inv(self, phi2p: float, phase: str) -> str:
        if phase != "auto":
            return phase
        return "ror" if phi2p > self.transition()[1] else "rof"

    def _pair_forward(self, phi1: float, phase: str) -> tuple[float, float, float]:
        ph = self._phase_fwd(phi1, phase)
        coeffs = self._forward_abc(phi1, ph)
        x = _near(_solve(*coeffs[:3], self._sign("fwd", ph)), self.transition()[1])
        return (x, *_derivatives(coeffs, x))

    def _pair_inverse(self, phi2p: float, phase: str) -> tuple[float, float, float]:
        ph = self._phase_inv(phi2p, phase)
        coeffs = self._inverse_def(phi2p, ph)
        v = _near(_solve(*coeffs[:3], self._sign("inv", ph)), self.transition()[0])
        return (v, *_derivatives(coeffs, v))  # DER = X Y and X Z (eqs. 95-97)

    # -- sensing and handover (eqs. 41–45) ---------------------------------------------------
    def sensing_gap(self, phi1: float) -> float:
        """|C_G' C_P'| - (rho_G + rho_P) of the next pair, current pair in RoF (eq. 45)."""
        phi2p = self._pair_forward(phi1, "rof")[0]
        d1, d2 = -_TWO_PI / self.n_gear, _TWO_PI / self.n_pinion
        ag, ap, b, be = self.a_g, self.a_p, self.b, self.beta1
        lx = (
            b * math.cos(be)
            + ap * math.cos(phi2p + d2 - self.delta_p)
            - ag * math.cos(phi1 + d1 - self.delta_g)
        )
        ly = (
            b * math.sin(be)
            + ap * math.sin(phi2p + d2 - self.delta_p)
            - ag * math.sin(phi1 + d1 - self.delta_g)
        )
        return math.hypot(lx, ly) - (self.rho_g + self.rho_p)

    def handover(self) -> float:
        """Gear angle phi1 (mesh-1 convention) where the next pair touches."""
        if "handover" not in self._cache:
            t = self.transition()[0]
            p = _TWO_PI / self.n_gear
            grid = t + p * np.linspace(0.0, 1.5, 61)
            gaps = [self.sensing_gap(x) for x in grid]
            k = next(i for i in range(60) if gaps[i] > 0.0 >= gaps[i + 1])
            from scipy.optimize import brentq  # here: scipy.optimize costs 0.3-0.6 s to import

            self._cache["handover"] = brentq(self.sensing_gap, grid[k], grid[k + 1], xtol=1e-15)
        return self._cache["handover"]

    # -- public kinematics (the mesh's own convention, all tooth pairs) ------------------------
    def driven_angle(self, phi_in: float, phase: str = "auto") -> float:
        """Output (pinion) angle from the input (gear) angle [rad]."""
        return self._forward(phi_in, phase)[0]

    def speed_ratio(self, phi_in: float, phase: str = "auto") -> float:
        """d(output)/d(input) (negative for these external meshes)."""
        return self._forward(phi_in, phase)[1]

    def ratio_derivative(self, phi_in: float, phase: str = "auto") -> float:
        """d^2(output)/d(input)^2 [1/rad], for the acceleration terms (eqs. 97, 106, 116, 126)."""
        return self._forward(phi_in, phase)[2]

    def driver_angle(self, phi_out: float, phase: str = "auto") -> float:
        """Inverse kinematics: input (gear) angle from the output (pinion) angle [rad]."""
        return self._inverse(phi_out, phase)[0]

    def inverse_speed_ratio(self, phi_out: float, phase: str = "auto") -> float:
        """d(input)/d(output), the report's DER (eqs. 95, 104, 114, 124)."""
        return self._inverse(phi_out, phase)[1]

    def inverse_ratio_derivative(self, phi_out: float, phase: str = "auto") -> float:
        """d^2(input)/d(output)^2 [1/rad], the report's X Z (eqs. 97, 106, 116, 126)."""
        return self._inverse(phi_out, phase)[2]

    # -- smooth pieces, for dynamics with the output (pinion) angle as the coordinate ----------
    # A piece is one tooth pair k in one phase; on it the kinematics is analytic.  In the local
    # pinion angle x = s phi_out - k q (mesh-1 convention, q the pinion pitch) the pair's window
    # is (end, end + q]: RoR on (x_T, end + q], RoF on (end, x_T]; the gear turning forward
    # moves x down.  A dynamic model freezes the piece inside an integrator stage and moves to
    # the next one at a located crossing of its bounds (RoR -> RoF -> handover; the report models
    # only entry onto the flank, not a return to RoR).
    @property
    def window_end(self) -> float:
        """Local pinion angle x (mesh-1 convention) at which the pair hands over."""
        if "window_end" not in self._cache:
            self._cache["window_end"] = self._pair_forward(self.handover(), "rof")[0]
        return self._cache["window_end"]

    @property
    def pinion_pitch(self) -> float:
        return _TWO_PI / self.n_pinion

    @property
    def gear_pitch(self) -> float:
        return _TWO_PI / self.n_gear

    @property
    def sign(self) -> float:
        """Own convention = sign * mesh-1 convention (-1 for the mirrored mesh)."""
        return -1.0 if self.mirrored else 1.0

    def inverse_piece(self, phi_out: float, direction: int = 1) -> tuple[int, str]:
        """(k, phase) of the piece holding the output angle phi_out [rad, own convention].

        direction +1: the gear turns forward (x falling), -1 backward; on a bound, the piece
        being entered is returned (windows (end, end + q] forward, [end, end + q) backward).
        """
        q, end, xt = self.pinion_pitch, self.window_end, self.transition()[1]
        y = self.sign * phi_out
        if direction >= 0:
            k = math.ceil((y - end) / q) - 1
            x = y - k * q
            return k, ("ror" if x > xt else "rof")
        k = math.floor((y - end) / q)
        x = y - k * q
        return k, ("ror" if x >= xt else "rof")

    def piece_bounds(self, phase: str) -> tuple[float, float]:
        """(lower, upper) local pinion angle x of a phase's piece (mesh-1 convention)."""
        end, xt = self.window_end, self.transition()[1]
        return (xt, end + self.pinion_pitch) if phase == "ror" else (end, xt)

    def local_output(self, phi_out: float, k: int) -> float:
        """Local pinion angle x (mesh-1 convention) of pair k."""
        return self.sign * phi_out - k * self.pinion_pitch

    def inverse_on_piece(self, phi_out: float, k: int, phase: str) -> tuple[float, float, float]:
        """Inverse kinematics on a given piece (continued analytically past its bounds):
        (driver angle, d driver/d output, d^2 driver/d output^2), own convention."""
        s = self.sign
        v, der, second = self._pair_inverse(s * phi_out - k * self.pinion_pitch, phase)
        return s * (v - k * self.gear_pitch), der, s * second

    def contact(self, x: float, v: float, phase: str) -> tuple[float, float, float, float]:
        """Contact point (cx, cy) and unit normal (nx, ny) of the force on the pinion.

        Mesh-1 convention, gear pivot at the origin, pinion pivot at b (cos beta1, sin beta1);
        x, v are the local pinion and gear angles of the pair (``_pair_inverse``).  RoR: the
        normal joins the two round centres; RoF: it is square to the radial flank, from the
        gear round's centre towards the flank.
        """
        cgx = self.a_g * math.cos(v - self.delta_g)
        cgy = self.a_g * math.sin(v - self.delta_g)
        opx, opy = self.b * math.cos(self.beta1), self.b * math.sin(self.beta1)
        if phase == "ror":
            nx = opx + self.a_p * math.cos(x - self.delta_p) - cgx
            ny = opy + self.a_p * math.sin(x - self.delta_p) - cgy
            r = math.hypot(nx, ny)
            nx, ny = nx / r, ny / r
        else:
            ex, ey = math.cos(x + self.alpha_p), math.sin(x + self.alpha_p)
            side = ex * (cgy - opy) - ey * (cgx - opx)  # C_G's side of the flank line
            nx, ny = (ey, -ex) if side >= 0.0 else (-ey, ex)
        return cgx + self.rho_g * nx, cgy + self.rho_g * ny, nx, ny

    def _forward(self, phi_in: float, phase: str) -> tuple[float, float, float]:
        s = -1.0 if self.mirrored else 1.0
        phi1 = s * phi_in
        k = 0
        if phase == "auto":  # k teeth on: tooth-local angle in [handover - pitch, handover)
            p = _TWO_PI / self.n_gear
            k = math.floor((phi1 - self.handover()) / p) + 1
            phi1 -= k * p
        x, ratio, second = self._pair_forward(phi1, phase)
        return s * (x - k * _TWO_PI / self.n_pinion), ratio, s * second

    def _inverse(self, phi_out: float, phase: str) -> tuple[float, float, float]:
        s = -1.0 if self.mirrored else 1.0
        phi2p = s * phi_out
        k = 0
        if phase == "auto":  # pinion window (end, end + pitch] of one pair's contact
            q = _TWO_PI / self.n_pinion
            end = self._pair_forward(self.handover(), "rof")[0]
            k = math.ceil((phi2p - end) / q) - 1
            phi2p -= k * q
        v, der, second = self._pair_inverse(phi2p, phase)
        return s * (v - k * _TWO_PI / self.n_gear), der, s * second


@dataclass(frozen=True)
class ClockTrain:
    """Both meshes; gear 2 and pinion 2 share a shaft with phasing phi2G = phi2P + kappa2."""

    mesh1: ClockMesh
    mesh2: ClockMesh
    kappa2: float = 0.0

    def escape_angle(self, phi1: float) -> float:
        return self.mesh2.driven_angle(self.mesh1.driven_angle(phi1) + self.kappa2)

    def rotor_angle(self, psi: float) -> float:
        return self.mesh1.driver_angle(self.mesh2.driver_angle(psi) - self.kappa2)

    def speed_ratio(self, phi1: float) -> float:
        """d psi / d phi1 = R1 R2 (chain rule over the cluster, phi2G' = phi2P', eq. 61)."""
        phi2p, r1, _ = self.mesh1._forward(phi1, "auto")
        return r1 * self.mesh2.speed_ratio(phi2p + self.kappa2)

    def ratio_derivative(self, phi1: float) -> float:
        """d^2 psi / d phi1^2 = R2' R1^2 + R2 R1' (chain rule, derived here)."""
        phi2p, r1, d1 = self.mesh1._forward(phi1, "auto")
        _, r2, d2 = self.mesh2._forward(phi2p + self.kappa2, "auto")
        return d2 * r1 * r1 + r2 * d1


def _m739_mesh(center_distance_in: float, n_gear: int, n_pinion: int, mirrored: bool) -> ClockMesh:
    b = center_distance_in * INCH
    f_p = b * n_pinion / (n_gear + n_pinion)  # pinion pitch radius
    rho = 0.2 * f_p
    beta = -0.2 if mirrored else 0.2
    return ClockMesh(b, beta, b - f_p, 0.1, rho, 0.3, f_p, rho, n_gear, n_pinion, mirrored)


#: Representative M739-like train (see module docstring): mesh 1 and the mirrored mesh 2.
M739_MESH1 = _m739_mesh(0.4701, 64, 9, mirrored=False)
M739_MESH2 = _m739_mesh(0.2327, 36, 8, mirrored=True)
M739_TRAIN = ClockTrain(M739_MESH1, M739_MESH2)


# ------------------------------------------------------------------------------------------
# Task 1: Test Plans 1 (M577) and 2 (M739) of the clock train report, as data
# ------------------------------------------------------------------------------------------
TEST_PLANS: dict[str, dict] = {
    "M577": {
        "response": "turns to arm",
        "factor": "escapement centre distance (pallet/lever pivot to escape-wheel pivot)",
        "phases": ("measure units", "selective assembly, only escapement C.D. varies",
                   "spin tests"),
        "spin_conditions": ("spin axis on the SSD axis", "eccentric spin axis"),
        "drawings": {"spacer and plate assy": 9236552, "top plate": 9236553,
                     "escape wheel assy": 9236537, "lever assy": 9236540, "rotor assy": 9236528},
        "measurements": ("over-wire C.D. both plate sides", "pivot diameters", "star wheel OD",
                         "thickness and mass", "tooth angle from 'd' at 4 places",
                         "lever A, B, C and pin diameters", "rotor mass and c.g."),
    },
    "M739": {
        "response": "turns to arm",
        "factor": "escapement centre distance (pallet shaft to escape-wheel pivot, upper plate)",
        "phases": ("measure units", "selective assembly, only escapement C.D. varies",
                   "spin tests"),
        "spin_conditions": ("spin axis on the S&A axis", "eccentric spin axis"),
        "drawings": {"bottom plate": 9258644, "gear plate spacer": 9258646,
                     "lower plate and shaft assy": 9258650, "upper plate": 9258632,
                     "escape wheel and pinion assy": 9258655, "pallet": 9258631,
                     "rotor assy": 9258639},
        "pallet": {"angle_rad": math.radians(17.0 + 10.0 / 60.0),
                   "corner_dimension_m": 0.1905 * INCH, "dimension_0905_m": 0.0905 * INCH},
    },
}  # fmt: skip


def escapement_cd_sweep(nominal: float, tolerance: float, n: int = 9) -> np.ndarray:
    """Escapement centre distances [m] across nominal +- tolerance, for the test plans' sweeps."""
    return nominal + tolerance * np.linspace(-1.0, 1.0, n)


#: M739 escapement centre distance O_p-O_s, 0.226 in (Lowen & Tepper 1982 input data; the test
#: plan's own source gives no value).
M739_ESCAPEMENT_CD = 0.226 * INCH
#: Tolerance band of the sweep: +-0.001 in is assumed (a usual drawing tolerance for fine-pitch
#: centre distances); neither source states it.  Replace with the drawing value.
M739_ESCAPEMENT_CD_TOLERANCE = 0.001 * INCH
M739_CD_SWEEP = escapement_cd_sweep(M739_ESCAPEMENT_CD, M739_ESCAPEMENT_CD_TOLERANCE)
