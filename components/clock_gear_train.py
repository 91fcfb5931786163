"""M739 spin-driven rotor behind a two-pass clock gear train (1 DOF, escape-wheel angle).

The rotor, inertias, eccentricity and spin of the M739 S&A (Lowen & Tepper 1982, ARLCD-TR-82013,
App. B and Input Data, pp. 7-11; data ``components.m739_data``) drive the escape wheel through
two clock meshes (kinematics of the US Army fuze report of about 1980, Task 2, eqs. 1–126)
instead of the M739's involute train.  Every clock-tooth quantity of both meshes, the cluster
phasing kappa2 and the bodies (the SANDA2V deck's train entries) are design parameters
(``components.clock_train_design``, refused by its rules at initialization unless
``check_design = 0``); their defaults are ``components.clock_train_kinematics.M739_TRAIN`` and
the M739 deck.

Default geometry (neither source gives a clock tooth form for the M739; the choice is
the one documented in ``components.clock_train_kinematics``): the M739 tooth counts and centre
distances,
rotor gear 64 teeth on 0.4701 in to pinion 2 of 9 leaves, gear 2 of 36 teeth on 0.2327 in to
pinion 3 of 8 leaves (32:1 mean, as the involute train), gear tip-round centres on the pitch
circles, radial pinion flanks meeting the tip round at the pinion pitch radius, tip rounds
0.2 f_P, delta_G = 0.1 rad, alpha_P = 0.3 rad, frame directions +-0.2 rad, kappa2 = 0.  The
escape-wheel angle in the train's own frame at phi = 0 is the parameter ``mesh_phase``
(default 0: mesh 1 and mesh 2 both in round-on-round).  The escapement side (verge, escape-wheel
tooth geometry) is the M739's.

Coordinate: phi, the cumulative escape-wheel angle (0 at the start, forward positive as in
``components.gear_train``); psi = mesh_phase + phi is the escape-wheel angle of the train's
kinematics.  On a smooth piece (both meshes: one tooth pair k_i in one phase, RoR or RoF, one
sliding direction) the inverse kinematics (eqs. 88–126, chained over the cluster) give the
cluster and rotor angles
theta2(phi), theta1(phi) and the ratios r2 = d theta2/d phi, r1 = d theta1/d phi and their
derivatives r2', r1' = K1 r2^2 + DER1 r2'.

Equation (virtual work on the three bodies with the mesh normal forces N1, N2 eliminated):

    J_ref phi_dd = T_ref + c_load T_esc,   c_load = 1,
    J_ref = I3 + I2 r2 iq2 + I1 r1 iq1 iq2
    T_ref = iq1 iq2 (M1 - P1 - I1 r1' phi_d^2) + iq2 (P2 - I2 r2' phi_d^2) - P3

where M1 = -A35 sin(Phi) is the spin moment on the eccentric rotor (rotor angle Phi), and iq_i
is the ratio of the pinion moment to the gear moment per unit normal force in mesh i.  Without
friction iq2 = r2 and iq1 iq2 = r1, which gives J_ref = I3 + I2 r2^2 + I1 r1^2 and
T_ref = M1 r1 - (I1 r1 r1' + I2 r2 r2') phi_d^2 (Lagrange).  With friction (``loss_model``):

* 0 ``none``: lossless meshes and pivots.
* 1 ``point`` (default): the point efficiency of the clock-mesh contact statics of
  ``components.mesh_efficiency`` (the model behind ``ClockMeshModel``, derived there with the
  friction model of Tepper 1981, App. B): normal force N along the contact normal, Coulomb
  force mu |N| along the sliding direction, pivot friction mu rho |N| at both pivots, evaluated
  on the contact point and normal
  of this train's kinematics.  Per unit N the gear resists with m_g and the pinion is driven with
  m_p; iq = m_p / m_g and the point efficiency is e = iq / DER.  The sliding direction reverses
  at the pitch point (an event); the sign of N (sigma, the lagged sign of the computed mesh force)
  and the direction of motion choose driving (e < 1) or back-driving (e > 1).
* 2 ``cycle``: a constant efficiency per mesh and power-flow sense, the mean of the point
  efficiency over one tooth cycle of the gear (as ``ClockMeshModel.cycle``).

P1, P2, P3 are the Coulomb pivot moments mu rho_i m_i R_i omega^2 of the centrifugal pivot loads
of rotor, cluster 2 and escape wheel (M739 pivot radii), opposing the motion; ``pivot_loads = 0``
drops them.  The pivot reaction is taken as the centrifugal load plus |N| (an upper bound of
the vector sum, like the |Fx| + |Fy| model of ``gear_train``).  mu = 0 makes every loss vanish.

Handover: where a mesh's next tooth pair touches (sensing equation, eqs. 41–45, 83–87) the
ratios jump.
The new contact is taken as a perfectly inelastic impact: the generalized speed is projected
so that the momentum conjugate to the new constraint is kept,
phi_d+ = (I1 r1+ r1- + I2 r2+ r2- + I3 + J_load) phi_d- / (I1 r1+^2 + I2 r2+^2 + I3 + J_load),
J_load being the inertia rigidly riding on the escape wheel at that instant (the verge while
coupled, input ``J_load``).  The kinetic energy lost is booked as dissipated work.  RoR <-> RoF
changes are C1 (the derived pinion-form consistency relation) and need no jump.

Energy: stored = 1/2 J_stot phi_d^2 with J_stot = I3 + I2 r2^2 + I1 r1^2, external = work of
the spin on the rotor, A35 (cos Phi - cos Phi_0); dissipated = integral of the power balance
plus the handover losses.  Not modelled: backlash (the meshes are bilateral), a return to RoR
on exit (the report models only the entry onto the flank), friction during the handover impact,
the Coriolis pivot terms.
"""

from __future__ import annotations

import math
from typing import Any

from .base import ComponentError, Variable, common_outputs
from .clock_train_design import DESIGN_VARIABLES, body_data, clock_train, train_violations
from .clock_train_design import values_of as design_values
from .clock_train_kinematics import M739_TRAIN, ClockMesh, ClockTrain
from .design_rules import raise_first
from .early_return import UntilFirstEvent
from .escape_wheel import (
    ESCAPE_WHEEL_PORT,
    ESCAPE_WHEEL_VARIABLES,
    IMPACT_INPUTS,
    MESH_FORCE_VARIABLES,
    WHEEL_INPUTS,
    response_slope_outputs,
)
from .event_integration import INTEGRATION_VARIABLES, use_compiled_loop
from .kernels import load_kernel
from .m739_data import M739, M739Data
from .sanda2v_deck import CHECK_DESIGN
from .train_component import RampedLoad, TrainComponent, TrainLoadModel

LOSS_NONE = 0
LOSS_POINT = 1
LOSS_CYCLE = 2
LOSS_MODELS = {LOSS_NONE: "none", LOSS_POINT: "point", LOSS_CYCLE: "cycle"}

PHASE_CODE = {"ror": 0, "rof": 1}
STUCK = 0
#: Regime codes: 0 stuck, else 1 + 2 (mesh-1 phase) + (mesh-2 phase), phase 0 RoR, 1 RoF.
REGIME_NAMES = {
    STUCK: "stuck",
    1: "ror/ror",
    2: "ror/rof",
    3: "rof/ror",
    4: "rof/rof",
}


def _slide_sign(slide: float, sign: int, crossing: bool) -> int:
    """Sliding sign of a mesh from its sliding velocity; exactly at a pitch point +1, or at
    a crossing there the sign beyond it."""
    if slide != 0.0:
        return 1 if slide > 0.0 else -1
    return -sign if crossing else 1


class ClockTrainPhysics:
    """Kinematics, contact statics and affine response of the clock train; holds the mode.

    Mode (frozen inside an integrator stage): direction of motion, for each mesh the tooth pair
    k, phase and sliding sign, and the sign sigma of each mesh normal force.  The interface is
    the one ``components.verge_escapement.VergeCore`` expects of a live train (``response``,
    ``direction``, ``set_direction``, ``mesh_indicators``, ``on_mesh_event``, ``update_i1r``,
    ``impact_inertia``, ``mode_key``, ``forces``), so the monolithic reference reuses the
    verge.
    """

    def __init__(
        self,
        train: ClockTrain = M739_TRAIN,
        data: M739Data = M739,
        mu: float | None = None,
        omega: float | None = None,
        loss_model: int = LOSS_POINT,
        pivot_loads: bool = True,
        mesh_phase: float = 0.0,
    ) -> None:
        d = data
        if int(loss_model) not in LOSS_MODELS:
            raise ComponentError(
                f"ClockGearTrain: loss_model {loss_model!r} unknown; expected one of "
                + ", ".join(f"{k} ({v})" for k, v in LOSS_MODELS.items())
            )
        self.train = train
        self.meshes: tuple[ClockMesh, ClockMesh] = (train.mesh1, train.mesh2)
        self.kappa2 = train.kappa2
        self.loss_model = int(loss_model)
        self.mu = abs(d.mu if mu is None else mu)
        self.omega = d.omega if omega is None else omega
        om2 = self.omega * self.omega
        self.i1, self.i2, self.i3 = d.i1, d.i2, d.i3
        self.a35 = d.m1 * d.r1 * d.rc1 * om2
        self.phi1c = d.phi1c
        on = self.mu if pivot_loads else 0.0
        # Coulomb pivot moments of the centrifugal pivot loads m_i R_i omega^2.
        self.pivot = (
            on * d.rho1 * d.m1 * d.r1 * om2,
            on * d.rho2 * d.m2 * d.r2 * om2,
            on * d.rho3 * d.m3 * d.r3 * om2,
        )
        # (gear, pinion) pivot radii of each mesh: rotor/cluster, cluster/escape wheel.
        self.rho = ((d.rho1, d.rho2), (d.rho2, d.rho3))
        self.psi0 = mesh_phase
        self.pinion_pivot = tuple(
            (m.b * math.cos(m.beta1), m.b * math.sin(m.beta1)) for m in self.meshes
        )
        self.bounds = tuple({ph: m.piece_bounds(ph) for ph in ("ror", "rof")} for m in self.meshes)
        # Mode.
        self.direction = 1
        self.pieces: tuple[tuple[int, str, int], tuple[int, str, int]] = ((0, "ror", 1),) * 2
        self.sigma = (1, 1)
        self.handovers = 0
        self._memo: tuple[Any, Any] | None = None
        self._rmemo: tuple[Any, Any] | None = None
        self.eta_cycle = self._cycle_efficiencies() if self.loss_model == LOSS_CYCLE else None
        self.set_mode(0.0, 1)
        self.theta1_0 = self.evaluate(0.0)[0]

    # -- memos ------------------------------------------------------------------------------
    def memos(self) -> tuple[Any, Any]:
        """What it remembers of its last point (kinematics, response)."""
        return self._memo, self._rmemo

    def restore_memos(self, memos: tuple[Any, Any]) -> None:
        """Remember that point again (after evaluations at a slope's neighbours)."""
        self._memo, self._rmemo = memos

    # -- mode -------------------------------------------------------------------------------
    def mode_key(self) -> tuple[Any, ...]:
        """Everything discrete the response depends on (for memoisation by callers)."""
        return (self.direction, self.pieces, self.sigma)

    def set_mode(self, phi: float, direction: int) -> None:
        """Pieces of both meshes at phi for the given direction of motion (the one entered)."""
        self.direction = 1 if direction >= 0 else -1
        m1, m2 = self.meshes
        psi = self.psi0 + phi
        k2, ph2 = m2.inverse_piece(psi, self.direction)
        theta2 = m2.inverse_on_piece(psi, k2, ph2)[0] - self.kappa2
        k1, ph1 = m1.inverse_piece(theta2, self.direction)
        self.pieces = ((k1, ph1, 1), (k2, ph2, 1))
        self._settle(phi)

    def _settle(self, phi: float, crossing: bool = False) -> None:
        """Step each mesh to the piece ahead while phi is past the bound ahead, and set the
        sliding signs from phi.  Works on the indicators themselves, so a located crossing
        (indicator just below zero, however little) always moves on; so does one exactly
        on its surface when ``crossing`` (an event that fires at a step start), which would
        otherwise fire again at once, without end."""
        forward = self.direction > 0
        for _ in range(8):
            a1, b1, a2, b2 = self.piece_distances(phi)
            ahead = (a1, a2) if forward else (b1, b2)
            # mesh 2 first: mesh 1 follows it
            late = [i for i in (1, 0) if ahead[i] < 0.0 or (crossing and ahead[i] == 0.0)]
            if not late:
                break
            i = late[0]
            k, ph, sg = self.pieces[i]
            if forward:
                k, ph = (k, "rof") if ph == "ror" else (k - 1, "ror")
            else:
                k, ph = (k, "ror") if ph == "rof" else (k + 1, "rof")
            self.pieces = tuple((k, ph, sg) if j == i else self.pieces[j] for j in range(2))
        ev = self.evaluate(phi)
        self.pieces = tuple(
            (k, ph, _slide_sign(ev[8 + i][4], sg, crossing))
            for i, (k, ph, sg) in enumerate(self.pieces)
        )

    def set_direction(self, direction: int, phi: float) -> None:
        """Friction reversal: the pieces are re-derived for the new direction."""
        self.set_mode(phi, direction)

    # -- kinematics and statics on the current pieces -----------------------------------------
    def evaluate(self, phi: float) -> tuple[Any, ...]:
        """(theta1, theta2, r1, r1', r2, r2', x1, x2, statics1, statics2) at phi.

        statics_i = (cross(r_g, n), cross(r_p, n), r_g.n, r_p.n, slide, DER) in the mesh-1
        convention; slide is the sliding speed of the gear on the pinion per unit forward gear
        speed (its sign reverses at the pitch point).
        """
        key = (phi, self.pieces)
        memo = self._memo
        if memo is not None and memo[0] == key:
            return memo[1]
        m1, m2 = self.meshes
        (k1, ph1, _), (k2, ph2, _) = self.pieces
        psi = self.psi0 + phi
        x2 = m2.local_output(psi, k2)
        v2, der2, sec2 = m2._pair_inverse(x2, ph2)
        theta2 = m2.sign * (v2 - k2 * m2.gear_pitch) - self.kappa2
        r2, r2p = der2, m2.sign * sec2
        x1 = m1.local_output(theta2, k1)
        v1, der1, sec1 = m1._pair_inverse(x1, ph1)
        theta1 = m1.sign * (v1 - k1 * m1.gear_pitch)
        r1 = der1 * r2
        r1p = m1.sign * sec1 * r2 * r2 + der1 * r2p
        out = (
            theta1,
            theta2,
            r1,
            r1p,
            r2,
            r2p,
            x1,
            x2,
            self._statics(0, x1, v1, ph1, der1),
            self._statics(1, x2, v2, ph2, der2),
        )
        self._memo = (key, out)
        return out

    def _statics(
        self, i: int, x: float, v: float, phase: str, der: float
    ) -> tuple[float, float, float, float, float, float]:
        cx, cy, nx, ny = self.meshes[i].contact(x, v, phase)
        px, py = self.pinion_pivot[i]
        rpx, rpy = cx - px, cy - py
        gn, pn = cx * nx + cy * ny, rpx * nx + rpy * ny
        # v_rel . tangent of (omega_g k x r_g - omega_p k x r_p) = r_g.n - R r_p.n, R = 1/DER
        return cx * ny - cy * nx, rpx * ny - rpy * nx, gn, pn, gn - pn / der, der

    def moments(self, i: int, st: tuple[float, ...]) -> tuple[float, float, float]:
        """(m_g, m_p, iq) of mesh i: gear resisting and pinion driving moment per unit normal
        force, and iq = m_p / m_g (= DER without friction)."""
        cg, cp, gn, pn, _, der = st
        if self.loss_model == LOSS_NONE or self.mu == 0.0:
            return cg, cp, der
        s = self.sigma[i] * self.direction
        if self.loss_model == LOSS_CYCLE:
            iq = self.eta_cycle[i][0 if s > 0 else 1] * der
            return cp / iq, cp, iq
        sg = self.pieces[i][2]
        rg, rp = self.rho[i]
        mg = cg + s * self.mu * (sg * gn + rg)
        mp = cp + s * self.mu * (sg * pn + rp)
        return mg, mp, mp / mg

    def point_efficiency(self, i: int, st: tuple[float, ...]) -> float:
        """Power out / power in of mesh i in the current mode (e = iq / DER)."""
        return self.moments(i, st)[2] / st[5]

    def _cycle_efficiencies(self) -> tuple[tuple[float, float], ...]:
        """Mean point efficiency over one gear tooth cycle, driving and back-driving."""
        out = []
        saved = self.loss_model
        self.loss_model = LOSS_POINT
        for i, m in enumerate(self.meshes):
            end, q, xt = m.window_end, m.pinion_pitch, m.transition()[1]
            means = []
            for s in (1, -1):
                num = den = 0.0
                n = 400
                for j in range(n):
                    x = end + q * (j + 0.5) / n
                    ph = "ror" if x > xt else "rof"
                    v, der, _ = m._pair_inverse(x, ph)
                    st = self._statics(i, x, v, ph, der)
                    sg = 1 if st[4] >= 0.0 else -1
                    self.pieces = tuple(
                        (0, ph, sg) if j2 == i else (0, "ror", 1) for j2 in range(2)
                    )
                    self.direction, self.sigma = s, (1, 1)
                    w = abs(der)  # weight dv = |DER| dx: the mean over the gear angle
                    num += self.point_efficiency(i, st) * w
                    den += w
                means.append(num / den)
            out.append((means[0], means[1]))
        self.loss_model = saved
        self.direction, self.sigma = 1, (1, 1)
        return tuple(out)

    # -- response ----------------------------------------------------------------------------
    def rotor_angle(self, phi: float) -> float:
        """Rotor angle Phi (the M739's, phi1c at phi = 0) [rad]."""
        return self.phi1c + self.evaluate(phi)[0] - self.theta1_0

    def j_stot(self, phi: float) -> float:
        """Frictionless reflected inertia I3 + I2 r2^2 + I1 r1^2 [kg.m2]."""
        ev = self.evaluate(phi)
        return self.i3 + self.i2 * ev[4] * ev[4] + self.i1 * ev[2] * ev[2]

    def impact_inertia(self, phi: float) -> float:
        """The train's inertia at the wheel for an impact of the verge at phi (B213): the
        frictionless reflected inertia there, which ripples with the tooth ratio."""
        return self.j_stot(phi)

    def response(self, phi: float, phi_dot: float) -> tuple[float, float, float]:
        """(J_ref, T_ref, c_load) in the current mode."""
        key = (phi, phi_dot, self.mode_key())
        memo = self._rmemo
        if memo is not None and memo[0] == key:
            return memo[1]
        ev = self.evaluate(phi)
        r1, r1p, r2, r2p = ev[2], ev[3], ev[4], ev[5]
        iq1 = self.moments(0, ev[8])[2]
        iq2 = self.moments(1, ev[9])[2]
        p1, p2, p3 = (self.direction * p for p in self.pivot)
        w2 = phi_dot * phi_dot
        m1 = -self.a35 * math.sin(self.phi1c + ev[0] - self.theta1_0)
        j = self.i3 + self.i2 * r2 * iq2 + self.i1 * r1 * iq1 * iq2
        t = iq1 * iq2 * (m1 - p1 - self.i1 * r1p * w2) + iq2 * (p2 - self.i2 * r2p * w2) - p3
        out = (j, t, 1.0)
        self._rmemo = (key, out)
        return out

    def power_terms(self, phi: float) -> tuple[float, float, float]:
        """(M1 r1, J_stot, I1 r1 r1' + I2 r2 r2'): input power and d(stored)/dt per phi_d."""
        ev = self.evaluate(phi)
        m1 = -self.a35 * math.sin(self.phi1c + ev[0] - self.theta1_0)
        r1, r2 = ev[2], ev[4]
        j0 = self.i3 + self.i2 * r2 * r2 + self.i1 * r1 * r1
        return m1 * r1, j0, self.i1 * r1 * ev[3] + self.i2 * r2 * ev[5]

    def forces(self, phi: float, phi_dot: float, phi_ddot: float) -> tuple[float, float]:
        """Mesh normal forces (N1, N2) [N] at a given acceleration; T_esc follows from (*)."""
        j, t, _ = self.response(phi, phi_dot)
        t_esc = j * phi_ddot - t
        ev = self.evaluate(phi)
        mg1, mp1, _ = self.moments(0, ev[8])
        mg2, mp2, _ = self.moments(1, ev[9])
        p2, p3 = self.direction * self.pivot[1], self.direction * self.pivot[2]
        # escape wheel: I3 phi_dd = -N2 m_p2 + T_esc - P3 (mesh 2 is mirrored)
        n2 = (t_esc - p3 - self.i3 * phi_ddot) / mp2
        # cluster: I2 theta2_dd = N1 m_p1 + N2 m_g2 + P2
        th2_dd = ev[4] * phi_ddot + ev[5] * phi_dot * phi_dot
        n1 = (self.i2 * th2_dd - n2 * mg2 - p2) / mp1
        return n1, n2

    # -- events ------------------------------------------------------------------------------
    def piece_distances(self, phi: float) -> tuple[float, float, float, float]:
        """Distances (local pinion angle) to the lower and upper piece bounds of both meshes:
        (x1 - lo1, hi1 - x1, x2 - lo2, hi2 - x2); forward motion moves x down."""
        ev = self.evaluate(phi)
        (_, ph1, _), (_, ph2, _) = self.pieces
        lo1, hi1 = self.bounds[0][ph1]
        lo2, hi2 = self.bounds[1][ph2]
        x1, x2 = ev[6], ev[7]
        return x1 - lo1, hi1 - x1, x2 - lo2, hi2 - x2

    def slide_indicators(self, phi: float) -> tuple[float, float]:
        """sigma_slide * slide of both meshes: negative past a pitch point [m/rad]."""
        ev = self.evaluate(phi)
        return self.pieces[0][2] * ev[8][4], self.pieces[1][2] * ev[9][4]

    def mesh_indicators(self, phi: float) -> tuple[float, float]:
        """(ahead forward, ahead backward): each turns negative at a piece bound or pitch
        point (the form ``VergeCore`` watches)."""
        a1, b1, a2, b2 = self.piece_distances(phi)
        s1, s2 = self.slide_indicators(phi)
        if self.loss_model != LOSS_POINT or self.mu == 0.0:
            s1 = s2 = math.inf
        return min(a1, a2, s1, s2), min(b1, b2, s1, s2)

    def cross(self, phi: float, phi_dot: float, j_load: float = 0.0) -> tuple[float, float]:
        """Move to the pieces beyond a located crossing; at a handover apply the inelastic
        velocity projection.  Returns (new phi_dot, kinetic energy lost)."""
        old = self.evaluate(phi)
        pairs = (self.pieces[0][0], self.pieces[1][0])
        self._settle(phi, crossing=True)
        if (self.pieces[0][0], self.pieces[1][0]) == pairs:
            return phi_dot, 0.0
        self.handovers += 1
        new = self.evaluate(phi)
        r1m, r2m, r1p, r2p = old[2], old[4], new[2], new[4]
        j3 = self.i3 + j_load
        jm = j3 + self.i2 * r2m * r2m + self.i1 * r1m * r1m
        jp = j3 + self.i2 * r2p * r2p + self.i1 * r1p * r1p
        w = (j3 + self.i2 * r2p * r2m + self.i1 * r1p * r1m) * phi_dot / jp
        return w, 0.5 * (jm * phi_dot * phi_dot - jp * w * w)

    def on_mesh_event(self, phi: float) -> None:
        """Pieces beyond a located crossing (no speed change; see ``cross``)."""
        self.cross(phi, 0.0)

    def update_i1r(self, phi_dot: float, phi_ddot: float) -> None:
        """Normal-force signs from the acceleration, switched where a computed mesh force
        changes sign (``branch_indicators``).

        The name is the one ``VergeCore`` calls on a live train.
        """
        if self.loss_model == LOSS_NONE or self.mu == 0.0:
            return
        n1, n2 = self.forces(self.evaluate_phi, phi_dot, phi_ddot)
        self.sigma = (1 if n1 >= 0.0 else -1, 1 if n2 >= 0.0 else -1)

    def branch_indicators(self, phi: float, phi_dot: float, phi_ddot: float) -> tuple[float, float]:
        """sigma_i N_i of both meshes: negative where a normal force changes sign."""
        if self.loss_model == LOSS_NONE or self.mu == 0.0:
            return (1.0, 1.0)
        n1, n2 = self.forces(phi, phi_dot, phi_ddot)
        return (self.sigma[0] * n1, self.sigma[1] * n2)

    @property
    def evaluate_phi(self) -> float:
        """The position of the last kinematic evaluation."""
        return self._memo[0][0] if self._memo is not None else 0.0


# ------------------------------------------------------------------------------------------
# Component
# ------------------------------------------------------------------------------------------
class _ClockModel(TrainLoadModel):
    """The clock train with a held escapement torque, as an EventModel; y = [phi, phi_d, W].

    Indicators: piece bounds ahead (mesh 1, mesh 2), pitch points (mesh 1, mesh 2), speed,
    signs of the two mesh normal forces.
    """

    def __init__(self, phys: ClockTrainPhysics) -> None:
        super().__init__(phys)
        self.j_load = 0.0  # inertia riding on the wheel (handovers); from the inputs

    def deriv(self, y: list[float]) -> list[float]:
        if self.stuck:
            return [0.0, 0.0, 0.0]
        phi, w = y[0], y[1]
        a = self.accel(phi, w)
        p_in, j0, g = self.p.power_terms(phi)
        # Dissipated power: input power minus rate of stored energy.
        return [w, a, w * (self.load(a) + p_in - j0 * a - g * w * w)]

    def indicators(self, y: list[float]) -> tuple[float, ...]:
        p = self.p
        a1, b1, a2, b2 = p.piece_distances(y[0])
        if p.loss_model == LOSS_POINT and p.mu != 0.0:
            s1, s2 = p.slide_indicators(y[0])
        else:
            s1 = s2 = 1.0
        if p.direction > 0:
            m1, m2 = a1, a2
        else:
            m1, m2 = b1, b2
        if self.stuck:
            return (m1, m2, s1, s2, 0.0, 0.0, 0.0)
        w = y[1]
        return (m1, m2, s1, s2, p.direction * w, *p.branch_indicators(y[0], w, self.accel(y[0], w)))

    def event(self, y: list[float], index: int, t: float) -> list[float]:
        if index <= 4:
            if self.t_first_event < 0.0:
                self.t_first_event = t
            if index < 4:
                w, loss = self.p.cross(y[0], y[1], self.j_load)
                y = [y[0], w, y[2] + loss]
            else:
                y = self.reverse_or_stick(y)
        # Past 4 a normal force changed sign (friction branch, not a regime change); after
        # a regime change the branches follow the new acceleration at once.
        if not self.stuck:
            self.p.update_i1r(y[1], self.accel(y[0], y[1]))
        return y


class ClockGearTrain(TrainComponent):
    """M739 rotor behind the two-pass clock train, 1 DOF (cumulative escape-wheel angle).

    Regime codes: 0 stuck (static friction), 1..4 the mesh phases (mesh 1 / mesh 2):
    ror/ror, ror/rof, rof/ror, rof/rof.  ``t_event`` is the first internal switch of the last
    step that had one (phase change, handover, pitch point, reversal or stick).  Impacts of
    the verge arrive as in ``GearTrain`` (``impact_count``, ``phi_dot_impact``); ``J_load``
    is the verge inertia riding on the wheel for the handover impacts (0 when not connected).

    Port ``escape_wheel``: angle, speed, torque (T_esc in) and the affine response (inertia
    J_ref, drive T_ref, load_factor c_load, impact_inertia J_stot), as ``GearTrain``.
    """

    REGIME_NAMES = REGIME_NAMES
    _PHYSICS = ClockTrainPhysics
    _MODEL = _ClockModel
    PORTS = {"escape_wheel": ESCAPE_WHEEL_PORT}

    VARIABLES = (
        *DESIGN_VARIABLES,
        CHECK_DESIGN,
        Variable(
            "loss_model",
            "parameter",
            "1",
            LOSS_POINT,
            "mesh losses: 0 none, 1 point, 2 cycle",
            min=LOSS_NONE,
            max=LOSS_CYCLE,
        ),
        Variable(
            "pivot_loads",
            "parameter",
            "1",
            1,
            "1: pivot friction of the centrifugal loads",
            min=0.0,
            max=1.0,
        ),
        Variable(
            "mesh_phase", "parameter", "rad", 0.0, "escape-wheel angle of the train at phi = 0"
        ),
        Variable("phi_start", "parameter", "rad", 0.0, "initial cumulative escape-wheel angle"),
        Variable("phi_dot_start", "parameter", "rad/s", 0.0, "initial escape-wheel speed"),
        *INTEGRATION_VARIABLES,
        *ESCAPE_WHEEL_VARIABLES,
        *response_slope_outputs(IMPACT_INPUTS),
        Variable(
            "J_load", "input", "kg.m2", 0.0, "inertia riding on the wheel (handover)", sampled=True
        ),
        *MESH_FORCE_VARIABLES,
        Variable("rotor_angle", "output", "rad", M739.phi1c, "rotor angle Phi"),
        Variable("speed_ratio", "output", "1", 32.0, "escape-wheel speed per rotor speed"),
        Variable(
            "efficiency1",
            "output",
            "1",
            1.0,
            "mesh-1 point efficiency in force",
            depends_on=WHEEL_INPUTS,
        ),
        Variable(
            "efficiency2",
            "output",
            "1",
            1.0,
            "mesh-2 point efficiency in force",
            depends_on=WHEEL_INPUTS,
        ),
        Variable(
            "phase1", "output", "1", 0, "mesh-1 phase: 0 round-on-round, 1 on flank", "Integer"
        ),
        Variable(
            "phase2", "output", "1", 0, "mesh-2 phase: 0 round-on-round, 1 on flank", "Integer"
        ),
        Variable("pair1", "output", "1", 0, "mesh-1 tooth pair index", "Integer"),
        Variable("pair2", "output", "1", 0, "mesh-2 tooth pair index", "Integer"),
        Variable("handovers", "output", "1", 0, "tooth-pair handovers so far", "Integer"),
        Variable(
            "ind_mesh1",
            "output",
            "rad",
            0.0,
            "mesh 1: pinion angle to the next phase bound",
            depends_on=WHEEL_INPUTS,
        ),
        Variable(
            "ind_mesh2",
            "output",
            "rad",
            0.0,
            "mesh 2: pinion angle to the next phase bound",
            depends_on=WHEEL_INPUTS,
        ),
        Variable("t_event", "output", "s", -1.0, "first internal switch of the last such step"),
        Variable("external_work", "output", "J", 0.0, "work of the spin on the rotor"),
        *common_outputs(regime=WHEEL_INPUTS, stored_energy=IMPACT_INPUTS),
    )

    def initialize(self, t0: float) -> None:
        self._start_integration()
        if self.pivot_loads not in (0.0, 1.0):
            raise ComponentError("ClockGearTrain: pivot_loads must be 0 or 1")
        values = design_values(self)
        train = clock_train(values)
        if self.check_design:
            raise_first(train_violations(train))
        try:
            self._phys = ClockTrainPhysics(
                train,
                body_data(values),
                mu=self.mu,
                omega=self.spin,
                loss_model=int(self.loss_model),
                pivot_loads=self.pivot_loads == 1.0,
                mesh_phase=self.mesh_phase,
            )
        except (ValueError, StopIteration) as exc:  # check_design = 0 on a broken train
            raise ComponentError(
                f"ClockGearTrain: the clock train cannot be assembled at the start ({exc}); "
                "check_design = 1 names the broken rule"
            ) from None
        p = self._phys
        self._y = [self.phi_start, self.phi_dot_start, 0.0]
        p.set_mode(self.phi_start, -1 if self.phi_dot_start < 0.0 else 1)
        self._model = _ClockModel(p)
        self._take_loads()
        self._seen_impacts = int(self.impact_count)
        self._cos0 = math.cos(p.rotor_angle(self.phi_start))
        self.t_event = -1.0
        if self.phi_dot_start == 0.0:
            self._model.try_unstick(self.phi_start)
        self._outputs()

    def _take_loads(self) -> None:
        super()._take_loads()
        self._model.j_load = self.J_load

    def _outputs(self) -> None:
        p, m = self._phys, self._model
        phi, w, wd = self._y
        self._send_response(phi, w)
        acc = 0.0 if m.stuck else m.accel(phi, w)
        ev = p.evaluate(phi)
        self.phi, self.phi_dot, self.phi_ddot = phi, w, acc
        p_in, j0, _ = p.power_terms(phi)
        f12, f23 = p.forces(phi, w, acc)
        self.F12, self.F23 = f12, f23
        unloaded = self.T_esc == 0.0
        self.FF12 = f12 if unloaded else 0.0
        self.FF23 = f23 if unloaded else 0.0
        rotor = p.rotor_angle(phi)
        self.rotor_angle = rotor
        self.speed_ratio = 1.0 / ev[2]
        self.efficiency1 = p.point_efficiency(0, ev[8])
        self.efficiency2 = p.point_efficiency(1, ev[9])
        (k1, ph1, _), (k2, ph2, _) = p.pieces
        self.phase1, self.phase2 = PHASE_CODE[ph1], PHASE_CODE[ph2]
        self.pair1, self.pair2 = int(k1), int(k2)
        self.handovers = p.handovers
        a1, b1, a2, b2 = p.piece_distances(phi)
        self.ind_mesh1, self.ind_mesh2 = (a1, a2) if p.direction > 0 else (b1, b2)
        self.regime = STUCK if m.stuck else 1 + 2 * self.phase1 + self.phase2
        self.stored_energy = 0.5 * j0 * w * w
        self.external_work = p.a35 * (math.cos(rotor) - self._cos0)
        self.dissipated_work = wd


_KERNEL = load_kernel("clock_train_kernel")
if _KERNEL is not None:  # the compiled twins (components.kernels): the same results
    ClockTrainPhysics.evaluate = _KERNEL.evaluate  # type: ignore[method-assign]
    ClockTrainPhysics.moments = _KERNEL.moments  # type: ignore[method-assign]
    ClockTrainPhysics.response = _KERNEL.response  # type: ignore[method-assign]
    ClockTrainPhysics.power_terms = _KERNEL.power_terms  # type: ignore[method-assign]
    ClockTrainPhysics.forces = _KERNEL.forces  # type: ignore[method-assign]
    ClockTrainPhysics.piece_distances = _KERNEL.piece_distances  # type: ignore[method-assign]
    _KERNEL.use_classes(
        physics=ClockTrainPhysics,
        model=_ClockModel,
        ramped_load=RampedLoad,
        until_first_event=UntilFirstEvent,
    )
    use_compiled_loop(_KERNEL)  # the loop between events in C for the clock train's model
