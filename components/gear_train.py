"""M739 gear train: eccentric rotor, gear/pinion set 2, escape wheel/pinion 3 (1 DOF).

Physics of Lowen & Tepper (1982), *Computer Simulation of Artillery S&A Mechanism (Involute
Gear Train and Straight-Sided Verge Runaway Escapement)*: the spin drive, the moment
equations B96, B144, B171 and their reduction B193, and the mesh roll angles of ALFA.
The generalized coordinate is the cumulative escape-wheel angle phi (= phi_T, radians,
0 at the start).  The rotor turns by n31*phi, gear 2 by n32*phi.

Train equation with the escapement load as an input torque.  Eliminating F12 and F23
from the rotor (B144), gear-2 (B171) and escape-wheel (B96) moment equations gives

    J_ref * phi_dd = T_ref + c_load * T_esc                                    (*)

    J_ref = I3 - A15 (I2 N32 - A42 I1R N31 / A31) / A44          (= A55, B193)
    T_ref = -A56 phi_d^2 - A57 phi_d + A58 - A59 sin(Phi)         (B193 right side)
    c_load = 1

where ``T_esc`` is the effective moment of the escapement on the escape-wheel shaft,
including the escape-wheel pivot friction caused by the tooth force: T_esc = -A17 Pn
(entrance; -AA17 Pn on the exit face).  The conservative |Fx|+|Fy| pivot model is a sum
of one term per load, so that share is exactly separable; it depends on the direction of
the tooth force (verge state), so the escapement side computes it.  With that split the
dependence on T_esc is exactly affine with unit factor.  It is only piecewise in the
*state*: the pieces are selected by sgn(phi_d) (friction reversal, eq. 7), by the
approach/recess signs s1, s2 of both meshes and the current tooth pair, and by the
branch of I1R (sign of phi_d times the acceleration, a located event).  The outputs
J_ref, T_ref are those of the piece in force at the current state.

Mesh position (subroutine ALFA for the contact range, the main program for the rest):
alpha_i = alpha_in + mod(k_i phi + J_i range_i, span_i), range_i = alpha_fin - alpha_in.
Physical indexing (default): the driver rolls with its own rotation, k1 = |N31| = 1/32
and k2 = |N32| = 8/36 (the tooth ratios; the rounded base radii give r_b3/R_b2 = 0.22223,
the same ratio to 4 digits), and the next tooth pair takes over once per tooth pitch of
the driven pinion, so span_i = 2 pi/N_Gi is one base pitch of the driver (Tepper 1981,
ARLCD-TR-81020, eq. 24: "one base pitch.  After this, the computations begin
repeating").  Mesh 2 hands over every 45 deg of phi and mesh 1 every 180 deg.  As-run
indexing reproduces SANDA2V's listing (IN2: IF (ALPHA2.GT.AL2FIN) ALPHA2=AL2IN): k2 = 32
r_b3/R_b2, k1 = k2 r_b2/R_b1 and span_i = range_i, a hand-over every contact range, which
with contact ratios of 0.9990 and 0.9993 runs ahead of the teeth.  Tooth changes and
pitch-point crossings are located as events.

"""

from __future__ import annotations

import math
from typing import Any

from .base import Variable, common_outputs
from .design_rules import raise_first
from .escape_wheel import (
    ESCAPE_WHEEL_PORT,
    ESCAPE_WHEEL_VARIABLES,
    IMPACT_INPUTS,
    MESH_FORCE_VARIABLES,
    WHEEL_INPUTS,
    response_slope_outputs,
)
from .event_integration import INTEGRATION_VARIABLES
from .kernels import load_kernel
from .m739_data import M739, M739Data
from .sanda2v_deck import TRAIN, deck_variables, design_of, train_violations
from .train_component import (
    SLOPE_STEP_ANGLE,
    SLOPE_STEP_SPEED,
    TrainComponent,
    TrainLoadModel,
)
from .verge_geometry import train_angles

INDEXING_PHYSICAL = 0
INDEXING_AS_RUN = 1

# Train regime codes.
TRAIN_STUCK = 0
TRAIN_FORWARD = 1
TRAIN_BACKWARD = 2
TRAIN_REGIME_NAMES = {TRAIN_STUCK: "stuck", TRAIN_FORWARD: "forward", TRAIN_BACKWARD: "backward"}


# ---------------------------------------------------------------------------------------
# Train physics (IN2 coefficients, B144, B171, B193)
# ---------------------------------------------------------------------------------------
def mesh_limits(
    rb_drv: float, rb_dvn: float, theta: float, ro_drv: float, ro_dvn: float
) -> tuple[float, float]:
    """Driver roll angle at start and end of contact (subroutine ALFA)."""
    al_in = ((rb_drv + rb_dvn) * math.tan(theta) - math.sqrt(ro_dvn**2 - rb_dvn**2)) / rb_drv
    al_fin = math.sqrt(ro_drv**2 - rb_drv**2) / rb_drv
    return al_in, al_fin


class TrainPhysics:
    """Coefficients and affine response of the train, with its discrete mode.

    Mode: direction (sign of mu, eq. 7), tooth pair index n_i and approach/recess sign
    s_i of each mesh, and the I1R branch.  All are frozen inside an integrator stage.
    """

    def __init__(
        self,
        data: M739Data = M739,
        mu: float | None = None,
        omega: float | None = None,
        indexing: int = INDEXING_PHYSICAL,
    ) -> None:
        d = data
        self.d = d
        self.mu_abs = abs(d.mu if mu is None else mu)
        self.omega = d.omega if omega is None else omega
        ang = train_angles(d)
        self.angles = ang
        om2 = self.omega**2
        self.om2 = om2
        self.om_abs = abs(self.omega)
        self.n31 = d.n31
        self.n32 = d.n32
        self.t2 = d.m2 * d.r2 * om2  # centrifugal pivot loads
        self.t3 = d.m3 * d.r3 * om2
        self.a35 = d.m1 * d.r1 * d.rc1 * om2
        self.tan1 = math.tan(d.theta1)
        self.tan2 = math.tan(d.theta2)
        self.d1 = (d.rb1_cap + d.rb2) * self.tan1
        self.d2 = (d.rb2_cap + d.rb3) * self.tan2
        self.al1_in, self.al1_fin = mesh_limits(d.rb1_cap, d.rb2, d.theta1, d.ro1_cap, d.ro2)
        self.al2_in, self.al2_fin = mesh_limits(d.rb2_cap, d.rb3, d.theta2, d.ro2_cap, d.ro3)
        self.range1 = self.al1_fin - self.al1_in
        self.range2 = self.al2_fin - self.al2_in
        self.indexing = int(indexing)
        if self.indexing == INDEXING_AS_RUN:
            # SANDA2V's listing (IN2): alpha_2 advances at 32 r_b3/R_b2 per radian of phi
            # and is reset to alpha_in when it passes alpha_fin, so a cycle spans the
            # roll-angle range of contact.
            self.k2 = 32.0 * d.rb3 / d.rb2_cap
            self.k1 = self.k2 * d.rb2 / d.rb1_cap
            self.span1, self.span2 = self.range1, self.range2
        else:
            # Each driver rolls with its own rotation (tooth ratios, B122 and B159) and the
            # next tooth pair takes over once per tooth pitch of the driven pinion: every
            # 2 pi/N_P3 of phi in mesh 2 and 2 pi/(N_P2 |N32|) in mesh 1.  A cycle then
            # spans one base pitch of the driver, 2 pi/N_G, as Tepper (1981, eq. 24)
            # states it; the contact ranges of the rounded data fall short of that by
            # their contact ratios, 0.9993 and 0.9990 (the design intends unity).
            self.k1 = abs(d.n31)
            self.k2 = abs(d.n32)
            self.span1 = 2.0 * math.pi / d.ng1
            self.span2 = 2.0 * math.pi / d.ng2
        # Mesh phases in units of one cycle: u = k phi / span + J range / span.
        self.du1 = self.k1 / self.span1
        self.du2 = self.k2 / self.span2
        self.u1_start = d.j1 * self.range1 / self.span1
        self.u2_start = d.j2 * self.range2 / self.span2
        self.p1 = (self.tan1 - self.al1_in) / self.span1  # pitch point, fraction of a cycle
        self.p2 = (self.tan2 - self.al2_in) / self.span2
        self.i_stot = d.i_stot
        self._cache: dict[tuple[int, int, int], tuple[float, ...]] = {}
        # Mode.
        self.direction = 1
        self.i1r_sign = 1
        self.n1 = self.n2 = 0
        self.s1 = self.s2 = 1
        self.phi_lo = -math.inf
        self.phi_hi = math.inf
        self._k: tuple[float, ...] = ()
        self.set_mode(0.0, 1)

    # -- mode ---------------------------------------------------------------------------
    def _piece(self, u: float, p: float, direction: int) -> tuple[int, int, float, float]:
        """Tooth index, sign and the u-interval of the smooth piece containing u."""
        n = math.floor(u)
        fr = u - n
        if direction < 0 and fr == 0.0:
            n -= 1
            fr = 1.0
        if fr < p or (fr == p and direction < 0):
            return n, 1, n, n + p  # approach: s = +1
        return n, -1, n + p, n + 1.0  # recess: s = -1

    def set_mode(self, phi: float, direction: int) -> None:
        """Set the mesh pieces from the position phi and the direction of motion."""
        self.direction = 1 if direction >= 0 else -1
        u1 = self.du1 * phi + self.u1_start
        u2 = self.du2 * phi + self.u2_start
        self.n1, self.s1, lo1, hi1 = self._piece(u1, self.p1, self.direction)
        self.n2, self.s2, lo2, hi2 = self._piece(u2, self.p2, self.direction)
        self.phi_lo = max((lo1 - self.u1_start) / self.du1, (lo2 - self.u2_start) / self.du2)
        self.phi_hi = min((hi1 - self.u1_start) / self.du1, (hi2 - self.u2_start) / self.du2)
        self._k = self._constants(self.direction, self.s1, self.s2)

    def _constants(self, direction: int, s1: int, s2: int) -> tuple[float, ...]:
        """Coefficients that depend only on the mode (IN2: A10-A14, A16, A23, A27, A36-A43)."""
        key = (direction, s1, s2)
        hit = self._cache.get(key)
        if hit is not None:
            return hit
        d, ang = self.d, self.angles
        mu = self.mu_abs * direction
        dn = 1.0 + mu * mu
        sb2, cb2 = math.sin(ang.beta2 + d.theta2), math.cos(ang.beta2 + d.theta2)
        sb1, cb1 = math.sin(ang.beta1 - d.theta1), math.cos(ang.beta1 - d.theta1)
        sg3, cg3 = math.sin(ang.gamma3), math.cos(ang.gamma3)
        sg2, cg2 = math.sin(ang.gamma2), math.cos(ang.gamma2)
        a10 = abs(-mu * (1 - s2) * sb2 - (1 + mu * mu * s2) * cb2) / dn
        a13 = abs(-(1 + mu * mu * s2) * sb2 + mu * (1 - s2) * cb2) / dn
        a11 = abs(sg3 - mu * cg3) / dn
        a14 = abs(cg3 + mu * sg3) / dn
        a16 = mu * d.rho3 * (a11 + a14)
        a23 = abs((1 - mu * mu * s1) * sb1 - mu * (1 + s1) * cb1) / dn
        a27 = abs(mu * (1 + s1) * sb1 + (1 - mu * mu * s1) * cb1) / dn
        a36 = abs((1 - mu * mu * s2) * sb2 + mu * (1 + s2) * cb2) / dn
        a39 = abs(mu * (1 + s2) * sb2 - (1 - mu * mu * s2) * cb2) / dn
        a37 = abs((1 + mu * mu * s1) * sb1 + mu * (1 - s1) * cb1) / dn
        a40 = abs(mu * (1 - s1) * sb1 - (1 + mu * mu * s1) * cb1) / dn
        a38 = abs(cg2 - mu * sg2) / dn
        a41 = abs(mu * cg2 + sg2) / dn
        a43 = mu * d.rho2 * (a38 + a41)
        out = (
            mu,
            dn,
            # A15 = rb3 - mu s2 (d2 - a2) - mu rho3 (A10 + A13)
            d.rb3 - mu * d.rho3 * (a10 + a13),
            a16,
            # A31 = Rb1 - mu s1 a1 + mu rho1 (A23 + A27)
            d.rb1_cap + mu * d.rho1 * (a23 + a27),
            # A42 = rb2 - mu s1 (d1 - a1) - mu rho2 (A37 + A40)
            d.rb2 - mu * d.rho2 * (a37 + a40),
            a43,
            # A44 = Rb2 - mu s2 a2 + mu rho2 (A36 + A39)
            d.rb2_cap + mu * d.rho2 * (a36 + a39),
            a10,
            a13,
            a23,
            a27,
        )
        self._cache[key] = out
        return out

    def mode_key(self) -> tuple[int, ...]:
        """Everything discrete the response depends on (for memoisation by callers)."""
        return (self.direction, self.i1r_sign, self.n1, self.n2, self.s1, self.s2)

    def mesh_alphas(self, phi: float) -> tuple[float, float]:
        """Driver roll angles of both meshes on the current tooth pairs."""
        al1 = self.al1_in + self.span1 * (self.du1 * phi + self.u1_start - self.n1)
        al2 = self.al2_in + self.span2 * (self.du2 * phi + self.u2_start - self.n2)
        return al1, al2

    # -- coefficients -------------------------------------------------------------------
    def coefficients(self, phi: float) -> dict[str, float]:
        """The A-coefficients of IN2 that belong to the train, at phi (for checks)."""
        d = self.d
        mu, dn, a15c, a16, a31c, a42c, a43, a44c, a10, a13, a23, a27 = self._k
        al1, al2 = self.mesh_alphas(phi)
        a1 = al1 * d.rb1_cap
        a2 = al2 * d.rb2_cap
        big_phi = d.phi1c + self.n31 * phi
        sp, cp = math.sin(big_phi), math.cos(big_phi)
        m1r = d.m1 * d.rc1
        a24 = abs(d.m1 * (d.r1 + d.rc1 * (cp + mu * sp))) / dn
        a28 = abs(mu * d.m1 * d.r1 + m1r * (mu * cp - sp)) / dn
        a25 = abs(m1r * (cp + mu * sp)) / dn
        a29 = abs(m1r * (mu * cp - sp)) / dn
        a26 = abs(m1r * (sp - mu * cp)) / dn
        a30 = abs(m1r * (mu * sp + cp)) / dn
        return {
            "mu": mu,
            "A10": a10,
            "A13": a13,
            "A15": a15c - mu * self.s2 * (self.d2 - a2),
            "A16": a16,
            "A23": a23,
            "A27": a27,
            "A24": a24,
            "A25": a25,
            "A26": a26,
            "A28": a28,
            "A29": a29,
            "A30": a30,
            "A31": a31c - mu * self.s1 * a1,
            "A32": mu * d.rho1 * self.om2 * (a24 + a28),
            "A33": 2.0 * abs(mu) * d.rho1 * self.om_abs * (a25 + a29),
            "A34": mu * d.rho1 * (a25 + a29),
            "A35": self.a35,
            "A42": a42c - mu * self.s1 * (self.d1 - a1),
            "A43": a43,
            "A44": a44c - mu * self.s2 * a2,
            "I1R": self.i1r(a26, a30),
            "sinPhi": sp,
        }

    def i1r(self, a26: float, a30: float) -> float:
        """Rotor inertia with the acceleration-proportional pivot friction (clamped >= 0)."""
        v = self.d.i1 + self.i1r_sign * self.mu_abs * self.d.rho1 * (a26 + a30)
        return v if v > 0.0 else 0.0

    def memos(self) -> Any:
        """What it remembers of its last point (its response parts)."""
        return self.__dict__.get("_memo")

    def restore_memos(self, memos: Any) -> None:
        """Remember that point again (after evaluations at a slope's neighbours)."""
        self._memo = memos

    def parts(self, phi: float, phi_dot: float) -> tuple[float, ...]:
        """(J_ref, T_ref, F0, K, A42, A43, A44): the response (*), F23 = F0 + K phi_dd
        (B175) and the gear-2 coefficients needed for F12 (B184)."""
        # Memo of the last point (integrator, accept and outputs ask for it repeatedly).
        key = (phi, phi_dot, self.direction, self.i1r_sign, self.n1, self.n2, self.s1, self.s2)
        memo = self.__dict__.get("_memo")
        if memo is not None and memo[0] == key:
            return memo[1]
        out = self._parts(phi, phi_dot)
        self._memo = (key, out)
        return out

    def _parts(self, phi: float, phi_dot: float) -> tuple[float, ...]:
        d = self.d
        mu, dn, a15c, a16, a31c, a42c, a43, a44c, _, _, _, _ = self._k
        al1, al2 = self.mesh_alphas(phi)
        a1 = al1 * d.rb1_cap
        a2 = al2 * d.rb2_cap
        a15 = a15c - mu * self.s2 * (self.d2 - a2)
        a31 = a31c - mu * self.s1 * a1
        a42 = a42c - mu * self.s1 * (self.d1 - a1)
        a44 = a44c - mu * self.s2 * a2
        big_phi = d.phi1c + self.n31 * phi
        sp, cp = math.sin(big_phi), math.cos(big_phi)
        m1r = d.m1 * d.rc1
        x = m1r * (mu * cp - sp)
        a24 = abs(d.m1 * d.r1 + m1r * (cp + mu * sp)) / dn
        a28 = abs(mu * d.m1 * d.r1 + x) / dn
        a25 = abs(m1r * (cp + mu * sp)) / dn
        a29 = abs(x) / dn
        a2526 = a25 + a29
        a32 = mu * d.rho1 * self.om2 * (a24 + a28)
        a33 = 2.0 * self.mu_abs * d.rho1 * self.om_abs * a2526
        a34 = mu * d.rho1 * a2526
        i1r = self.d.i1 + self.i1r_sign * self.mu_abs * d.rho1 * (
            abs(m1r * (sp - mu * cp)) / dn + abs(m1r * (mu * sp + cp)) / dn
        )
        if i1r < 0.0:
            i1r = 0.0
        w1 = self.n31 * phi_dot
        k = (d.i2 * self.n32 - a42 * i1r * self.n31 / a31) / a44
        f0 = (a42 * (-a32 - a33 * w1 - a34 * w1 * w1 - self.a35 * sp) / a31 - self.t2 * a43) / a44
        j_ref = d.i3 - a15 * k
        t_ref = a15 * f0 - self.t3 * a16
        return j_ref, t_ref, f0, k, a42, a43, a44

    def impact_inertia(self, phi: float) -> float:
        """The train's inertia at the wheel for an impact of the verge at phi (B213)."""
        return self.i_stot

    def response(self, phi: float, phi_dot: float) -> tuple[float, float, float]:
        """(J_ref, T_ref, c_load) of (*) in the current mode."""
        r = self.parts(phi, phi_dot)
        return r[0], r[1], 1.0

    def forces(self, phi: float, phi_dot: float, phi_ddot: float) -> tuple[float, float]:
        """Mesh forces (F12, F23) [N] for a given acceleration (B144/B171 = B183/B184)."""
        _, _, f0, k, a42, a43, a44 = self.parts(phi, phi_dot)
        f23 = f0 + k * phi_ddot
        f12 = (f23 * a44 + self.t2 * a43 - self.d.i2 * self.n32 * phi_ddot) / a42
        return f12, f23

    def drive_torque(self, phi: float) -> float:
        """Spin moment on the rotor -A35 sin(Phi) referred to the escape wheel [N.m]."""
        return -self.n31 * self.a35 * math.sin(self.d.phi1c + self.n31 * phi)

    def mesh_indicators(self, phi: float) -> tuple[float, float]:
        """Distances to the ends of the current smooth piece (tooth change, pitch point)."""
        return self.phi_hi - phi, phi - self.phi_lo

    def on_mesh_event(self, phi: float) -> None:
        """Move to the piece beyond a located tooth-change or pitch-point crossing."""
        self.set_mode(phi, self.direction)
        # The crossing is located in phi but the pieces are cut in the mesh phases: at a
        # rounding tie phi can sit past the boundary while its phase does not, and the
        # piece would not move (its indicator then stays negative and the next crossing is
        # never seen).  Probe just beyond the boundary instead.
        for _ in range(3):
            hi, lo = self.mesh_indicators(phi)
            ahead = hi if self.direction > 0 else lo
            if ahead > 0.0:
                return
            edge = self.phi_hi if self.direction > 0 else self.phi_lo
            self.set_mode(edge + self.direction * 1e-12 * max(1.0, abs(edge)), self.direction)

    def set_direction(self, direction: int, phi: float) -> None:
        """Friction reversal (eq. 7); the pieces are re-derived for the new direction."""
        self.set_mode(phi, direction)

    def update_i1r(self, phi_dot: float, phi_ddot: float) -> None:
        """I1R branch from the acceleration: the sign of the rotor's pivot friction moment
        that grows with its acceleration (Lowen & Tepper 1982, B144 and its I1R term).  The
        report takes it from the last accepted step; here it switches at the located
        instant where velocity times acceleration changes sign (``branch_indicators``), the
        limit of the report's rule as its step goes to zero.  The direction of motion stands
        for the sign of the speed, as in the indicator, so the two never disagree."""
        self.i1r_sign = 1 if self.direction * phi_ddot >= 0.0 else -1

    def branch_indicators(self, phi: float, phi_dot: float, phi_ddot: float) -> tuple[float]:
        """Negative where the I1R branch no longer matches the motion (see update_i1r).

        The direction of motion stands for the sign of the speed: a reversal is an event of
        its own (which settles the branch), so this one crosses only where the acceleration
        does and never races the speed indicator at a wheel stop."""
        return (self.i1r_sign * self.direction * phi_ddot,)


class _TrainModel(TrainLoadModel):
    """The train with a held escapement torque, as an EventModel; y = [phi, phi_d, W].

    Indicators: mesh piece ends ahead and behind, speed (reversal/stick), I1R branch.
    """

    def deriv(self, y: list[float]) -> list[float]:
        if self.stuck:
            return [0.0, 0.0, 0.0]
        phi, w = y[0], y[1]
        a = self.accel(phi, w)
        # Dissipated power: input power minus rate of stored energy.
        p_loss = w * (self.load(a) + self.p.drive_torque(phi) - self.p.i_stot * a)
        return [w, a, p_loss]

    def indicators(self, y: list[float]) -> tuple[float, ...]:
        hi, lo = self.p.mesh_indicators(y[0])
        if self.stuck:
            return (hi, lo, 0.0, 0.0)
        phi, w = y[0], y[1]
        return (hi, lo, self.p.direction * w, *self.p.branch_indicators(phi, w, self.accel(phi, w)))

    def event(self, y: list[float], index: int, t: float) -> list[float]:
        p = self.p
        if index < 2:
            p.on_mesh_event(y[0])
        elif index == 2:
            if self.t_first_event < 0.0:
                self.t_first_event = t
            y = self.reverse_or_stick(y)
        if not self.stuck:  # the branch follows the acceleration of the new piece at once
            p.update_i1r(y[1], self.accel(y[0], y[1]))
        return y


class GearTrain(TrainComponent):
    """M739 train, 1 DOF (cumulative escape-wheel angle), escapement torque as input.

    Regime codes: 0 stuck (static friction), 1 moving forward, 2 moving backward.
    A master applies an impact by setting ``phi_dot_impact`` and incrementing
    ``impact_count``; the new speed is taken at once (update_outputs) or at the latest at
    the start of the next step.  Energy: stored = 1/2 I_STOT phi_dot^2 (B213), external
    = work of the spin field on the eccentric rotor, A35 (cos Phi - cos Phi_0).

    Port ``escape_wheel``: angle, speed, torque (T_esc in) and the affine response
    (inertia J_ref, drive T_ref, load_factor c_load, impact_inertia J_stot).
    """

    REGIME_NAMES = TRAIN_REGIME_NAMES
    _PHYSICS = TrainPhysics
    _MODEL = _TrainModel
    PORTS = {"escape_wheel": ESCAPE_WHEEL_PORT}

    VARIABLES = (
        # The SANDA2V deck's train quantities (cards 3-15): the bodies, pivots and meshes.
        *deck_variables(TRAIN),
        Variable(
            "indexing",
            "parameter",
            "1",
            INDEXING_PHYSICAL,
            "0 physical, 1 as-run",
            min=INDEXING_PHYSICAL,
            max=INDEXING_AS_RUN,
        ),
        Variable("phi_start", "parameter", "rad", 0.0, "initial cumulative escape-wheel angle"),
        Variable("phi_dot_start", "parameter", "rad/s", 0.0, "initial escape-wheel speed"),
        *INTEGRATION_VARIABLES,
        *ESCAPE_WHEEL_VARIABLES,
        *response_slope_outputs(WHEEL_INPUTS),
        *MESH_FORCE_VARIABLES,
        Variable("rotor_angle", "output", "rad", M739.phi1c, "rotor angle Phi"),
        # The mesh signs follow the direction of motion where the wheel rests on a tooth
        # change or pitch point, as at the M739 start (J1 = J2 = 0 at phi = 0).
        Variable(
            "s1",
            "output",
            "1",
            1,
            "mesh-1 sign, +1 approach, -1 recess",
            "Integer",
            depends_on=WHEEL_INPUTS,
        ),
        Variable(
            "s2",
            "output",
            "1",
            1,
            "mesh-2 sign, +1 approach, -1 recess",
            "Integer",
            depends_on=WHEEL_INPUTS,
        ),
        Variable(
            "indicator_mesh",
            "output",
            "rad",
            0.0,
            "distance to the next mesh event",
            depends_on=WHEEL_INPUTS,
        ),
        Variable("t_event", "output", "s", -1.0, "time of the last reversal or stick"),
        Variable("external_work", "output", "J", 0.0, "work of the spin on the rotor"),
        *common_outputs(regime=WHEEL_INPUTS, stored_energy=IMPACT_INPUTS),
    )

    def initialize(self, t0: float) -> None:
        self._start_integration()
        self.check_parameters()
        data = design_of(self, TRAIN)
        if self.check_design:
            raise_first(train_violations(data))  # a broken design is refused, not run
        self._data = data
        self._phys = TrainPhysics(data, mu=self.mu, omega=self.spin, indexing=int(self.indexing))
        self._y = [self.phi_start, self.phi_dot_start, 0.0]
        direction = -1 if self.phi_dot_start < 0.0 else 1
        self._phys.set_mode(self.phi_start, direction)
        self._model = _TrainModel(self._phys)
        self._take_loads()
        self._seen_impacts = int(self.impact_count)
        self._cos0 = math.cos(data.phi1c + self._phys.n31 * self.phi_start)
        self.t_event = -1.0
        if self.phi_dot_start == 0.0:
            self._model.try_unstick(self.phi_start)
        self._outputs()

    def _outputs(self) -> None:
        p, m = self._phys, self._model
        phi, w, wd = self._y
        self._send_response(phi, w)
        acc = 0.0 if m.stuck else m.accel(phi, w)
        self.phi, self.phi_dot, self.phi_ddot = phi, w, acc
        f12, f23 = p.forces(phi, w, acc)
        self.F12, self.F23 = f12, f23
        unloaded = self.T_esc == 0.0
        self.FF12 = f12 if unloaded else 0.0
        self.FF23 = f23 if unloaded else 0.0
        self.rotor_angle = self._data.phi1c + p.n31 * phi
        self.s1, self.s2 = p.s1, p.s2
        hi, lo = p.mesh_indicators(phi)
        self.indicator_mesh = hi if p.direction > 0 else lo
        if m.stuck:
            self.regime = TRAIN_STUCK
        else:
            self.regime = TRAIN_FORWARD if p.direction > 0 else TRAIN_BACKWARD
        self.stored_energy = 0.5 * p.i_stot * w * w
        # Work of the spin (centrifugal moment on the eccentric rotor) since the start.
        self.external_work = p.a35 * (math.cos(self._data.phi1c + p.n31 * phi) - self._cos0)
        self.dissipated_work = wd


_KERNEL = load_kernel("m739_kernel")
if _KERNEL is not None:  # the compiled twin (components.kernels): the same results
    TrainPhysics._parts = _KERNEL.train_parts
    _KERNEL.use_classes(live_train=TrainPhysics, train_model=_TrainModel)
    _KERNEL.use_python_train(
        GearTrain._outputs,
        (SLOPE_STEP_ANGLE, SLOPE_STEP_SPEED),
        (TRAIN_STUCK, TRAIN_FORWARD, TRAIN_BACKWARD),
    )
    GearTrain._outputs = _KERNEL.train_outputs  # type: ignore[method-assign]
