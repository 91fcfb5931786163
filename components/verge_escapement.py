"""M739 straight-sided verge escapement: verge (1 DOF psi) and tooth-face contact.

Physics of Lowen & Tepper (1982) (title in ``components.gear_train``): verge and face
kinematics (App. C-E), verge geometry (App. F), the main program's regime logic and the
impact map (B205, B210-B212).
The train enters only through its affine response at the escape-wheel shaft,

    J_ref phi_dd = T_ref + c_load T_esc,      T_esc = -A17 Pn   (-AA17 Pn on the exit face)

(see ``components.gear_train``).  T_esc includes the escape-wheel pivot friction caused by
the tooth force (the mu rho3 (A9 + A12) term of A17), because it depends on the direction
of that force, i.e. on the verge state.

Regimes (``regime`` codes):
  0  FREE             no tooth-face contact: verge alone (B187), wheel driven by the train
  1  COUPLED_ENTRANCE tooth tip sliding on the entrance face (B100 via the split, = B176)
  2  COUPLED_EXIT     tooth tip sliding on the exit face (B119 via the split, = B176)
``face`` is +1 when the entrance face is the active one, -1 for the exit face (in free
motion: the face the next contact is expected on).

Coupled motion: psi = psi(phi) (C18), psi_d = U phi_d, psi_dd = U phi_dd + V phi_d^2; the
verge moment equation (B76) and the train response give

    phi_dd = (A18 T_ref - c A17 N) / (J_ref A18 + c A17 I_PR U),
    N = I_PR V phi_d^2 + A21 U^2 phi_d^2 + A52 U phi_d + A53 - A54 sin(gp' - psi - psic).

Events (indicator >= 0 while the regime holds, located where it turns negative):
  coupled: sigma g (face end, then re-index and free), Pn (separation, free on the same
  face), s4 V_S/T and s5 psi_d (friction reversal), direction * phi_d (train reversal);
  free: sigma f (face plane reached: contact test), sigma g' (tip passed the face end:
  re-index), s5 psi_d (verge stops; it sticks if the pivot friction holds it).
Here sigma = +1 on the entrance face and -1 on the exit face.  A contact with closing
speed v_c = sigma (V_SN - V_TN) > v_capture is an impact (B205, B210-B212, inertia I_STOT
on the wheel side); after it the tooth stays on the face (e = 0) or separates.

Per-tooth bookkeeping (main program, labels 3 and 4): phi_local = phi_T + phi_off;
entrance -> exit adds NT Delta to
phi_local, 2 pi - lambda to psi and lambda to psic; exit -> entrance subtracts (NT + 1) Delta,
2 pi - lambda and lambda.  The output ``psi`` is the verge angle in entrance-face
coordinates (psi + psic - psic0, wrapped), so it is continuous across re-indexing.

The escapement centre distance a = |O_p O_s| is the parameter ``center_distance`` (default the
M739's 0.226 in): it enters the face kinematics and contact sensing and the fuze-body angles of
the pallet pivot (``escapement_data``), the parts themselves unchanged, as in the selective
assembly of the M577/M739 escapement centre-distance test plans (US Army fuze report,
about 1980, Task 1).  ``J_load`` = I_p U^2
is the verge inertia riding on the wheel while coupled (0 when free), for a train whose own
impacts (clock-train tooth handover) must include it.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

from .base import Component, ComponentError, Role, SnapshotPlan, Variable, common_outputs
from .design_rules import raise_first
from .early_return import EARLY_RETURN_VARIABLES, UntilFirstEvent, reached
from .escape_wheel import ESCAPE_WHEEL_PORT
from .event_integration import INTEGRATION_VARIABLES, advance, integration_step_control
from .kernels import load_kernel
from .m739_data import M739, M739Data
from .sanda2v_deck import VERGE, deck_variables, design_of, verge_violations
from .step_moments import WithMoments
from .verge_geometry import (
    TWO_PI,
    face_arms,
    fuze_angles,
    impact_map,
    kinem,
    sliding_velocity,
)

FREE = 0
COUPLED_ENTRANCE = 1
COUPLED_EXIT = 2
ENTRANCE = 1
EXIT = -1

#: Magnitudes below which the integration controls the state [phi, phi_d, psi, psi_d, W]
#: absolutely: rad, rad/s, rad, rad/s, J.
STATE_SCALES = (1.0, 10.0, 0.1, 10.0, 1.0e-3)

REGIME_NAMES = {FREE: "free", COUPLED_ENTRANCE: "coupled-entrance", COUPLED_EXIT: "coupled-exit"}

# Indicator slots.
IND_FACE_END = 0
IND_CONTACT = 1  # Pn (coupled) or sigma f (free)
IND_SLIDE = 2
IND_VERGE_SPEED = 3
IND_WHEEL_SPEED = 4
IND_MESH_HI = 5
IND_MESH_LO = 6
IND_STOP = 7
IND_IPR = 8  # branch of the verge's acceleration-dependent pivot friction
IND_TRAIN_BRANCH = 9  # and on: the train's branch indicators (none for a held train)
# Direct feedthrough of the verge: the wheel state, and with it the train's response.
_WHEEL_STATE = ("phi", "phi_dot")
_WHEEL_AND_TRAIN = (*_WHEEL_STATE, "J_ref", "T_ref", "c_load")
# Wheel speed [rad/s] below which a located verge-speed zero in coupled motion is the
# wheel's (psi_d = U phi_d with U of order 1; the event is located to about 1e-14 s).
WHEEL_AT_REST = 1e-6


def _vertex(a: tuple[float, float], b: tuple[float, float], c: tuple[float, float]) -> float:
    """The top of the parabola through three points (t, value) whose middle one is the
    highest; -inf where it is not, or the points do not span time."""
    (t0, p0), (t1, p1), (t2, p2) = a, b, c
    if not (t0 < t1 < t2 and p1 >= p0 and p1 >= p2):
        return -math.inf
    d01, d12 = (p1 - p0) / (t1 - t0), (p2 - p1) / (t2 - t1)
    curvature = (d12 - d01) / (t2 - t0)
    if curvature >= 0.0:
        return -math.inf
    top = 0.5 * (t0 + t1) - d01 / (2.0 * curvature)
    return p0 + (top - t0) * (d01 + curvature * (top - t1))


def _sgn(x: float) -> int:
    return -1 if x < 0.0 else 1


def escapement_data(
    center_distance: float,
    phi_local_start: float = M739.phi_start,
    pallet_inertia: float = M739.ip,
) -> M739Data:
    """The M739 data with the escapement centre distance a = |O_p O_s| [m] and the pallet
    inertia I_p [kg.m2] set (I_p scaled against the train gives the inertia-ratio cases).

    a is the one length of the loop C10 (App C) that is not a part dimension: the face
    kinematics (C17, C15), the contact sensing (E4, E5), and the fuze-body angles of the
    pallet pivot (B7, B12: O_p stays at R_4 from the spin axis, so delta_4, gamma_4', beta_3
    and gamma_p' follow a) all take it from here; the default reproduces the M739 exactly.
    """
    d = M739
    a = float(center_distance)
    if not abs(d.r3 - d.r4) < a < d.r3 + d.r4:
        raise ComponentError(
            f"VergeEscapement: center_distance {a:.6g} m outside ({abs(d.r3 - d.r4):.6g}, "
            f"{d.r3 + d.r4:.6g}) m: the pallet pivot cannot sit at R4 from the spin axis"
        )
    if not abs(d.b - d.c) < a < d.b + d.c:
        raise ComponentError(
            f"VergeEscapement: center_distance {a:.6g} m outside ({abs(d.b - d.c):.6g}, "
            f"{d.b + d.c:.6g}) m: the tooth-tip circle (b) never meets the pallet corners (c), "
            "so no tooth could leave a face"
        )
    # The start configuration must have the tooth tip on the entrance face (C17 solvable, g > 0).
    alpha = d.alpha_en
    cap_a = a * math.cos(alpha) + d.b * math.cos(phi_local_start - alpha)
    cap_b = a * math.sin(alpha) - d.b * math.sin(phi_local_start - alpha)
    cap_c = d.c * math.sin(alpha)
    if (
        cap_a * cap_a + cap_b * cap_b < cap_c * cap_c
        or kinem(phi_local_start, alpha, a, d.b, d.c)[1] <= 0.0
    ):
        raise ComponentError(
            f"VergeEscapement: center_distance {a:.6g} m leaves the escape-wheel tooth off the "
            f"entrance face at phi_local_start = {phi_local_start:.6g} rad"
        )
    if not pallet_inertia > 0.0:
        raise ComponentError(
            f"VergeEscapement: pallet_inertia {pallet_inertia:.6g} kg.m2 must be positive"
        )
    changes = {n: v for n, v, v0 in (("a", a, d.a), ("ip", pallet_inertia, d.ip)) if v != v0}
    return d.with_(**changes) if changes else d


class VergeConstants:
    """Spin- and friction-dependent constants of the verge side."""

    def __init__(self, data: M739Data, mu1: float, mu: float, omega: float, e_rest: float) -> None:
        d = data
        ang = fuze_angles(d)
        self.d = d
        self.a, self.b, self.c = d.a, d.b, d.c
        self.mu1 = mu1
        self.mu_abs = abs(mu)
        self.omega = omega
        self.om2 = omega * omega
        self.om_abs = abs(omega)
        self.e_rest = e_rest
        self.beta3 = ang.beta3
        self.gamma_pp = ang.gamma_pp
        self.dn1 = 1.0 + mu1 * mu1
        self.ip = d.ip
        self.a54 = self.om2 * d.mp * d.rcp * d.r4
        self.delta = d.tooth_angle
        self.c1 = {ENTRANCE: -d.c * math.sin(d.alpha_en), EXIT: -d.c * math.sin(d.alpha_ex)}
        self.alpha = {ENTRANCE: d.alpha_en, EXIT: d.alpha_ex}
        # Memo of the pivot coefficients per s5 (they depend on psi only if r_cp != 0).
        self._pivot: dict[tuple[int, float], tuple[float, float, float]] = {}

    def pivot(self, s5: int, psi_c: float) -> tuple[float, float, float]:
        """(A19, A20, A22) of the verge pivot (B70-B75 via IN2), A21 = s5 A20."""
        d = self.d
        if d.rcp == 0.0:
            key = (s5, 0.0)
            hit = self._pivot.get(key)
            if hit is not None:
                return hit
        mu1, dn1, g = self.mu1, self.dn1, self.gamma_pp
        sp, cp = math.sin(psi_c), math.cos(psi_c)
        a2 = abs(
            d.mp * (d.r4 * (math.sin(g) - mu1 * s5 * math.cos(g)) + d.rcp * (sp - mu1 * s5 * cp))
        )
        a6 = abs(
            d.mp * (-d.r4 * (math.cos(g) + mu1 * s5 * math.sin(g)) - d.rcp * (cp + mu1 * s5 * sp))
        )
        a3 = abs(d.mp * d.rcp * (sp - mu1 * s5 * cp)) / dn1
        a4 = abs(d.mp * d.rcp * (cp + mu1 * s5 * sp)) / dn1
        out = (
            d.rho_p * mu1 * s5 * (a2 + a6) / dn1,
            d.rho_p * mu1 * (a3 + a4),
            d.rho_p * mu1 * (a4 + a3),
        )
        if d.rcp == 0.0:
            self._pivot[(s5, 0.0)] = out
        return out


def contact_coefficients(
    k: VergeConstants,
    face: int,
    psi: float,
    s4: int,
    s5: int,
    direction: int,
    a1p: float,
    b1p: float,
    d1p: float,
) -> tuple[float, float]:
    """(A17, A18) for the entrance face or (AA17, AA18) for the exit face (IN2, B99-B108).

    ``direction`` is the sign of the train's friction coefficient (eq. 7).
    """
    mu1 = k.mu1
    mu = k.mu_abs * direction
    alpha = k.alpha[face]
    spa, cpa = math.sin(psi + alpha), math.cos(psi + alpha)
    chi = psi + alpha + k.beta3
    sc, cc = math.sin(chi), math.cos(chi)
    dn = 1.0 + mu * mu
    rho3 = k.d.rho3
    c1p = k.c1[face]
    if face == ENTRANCE:
        a1 = abs(-mu1 * (s4 + s5) * spa - (1.0 - s4 * s5 * mu1 * mu1) * cpa) / k.dn1
        a5 = abs(mu1 * (s4 + s5) * cpa + (1.0 - s4 * s5 * mu1 * mu1) * spa) / k.dn1
        a9 = abs((mu1 * s4 + mu) * sc + (1.0 - mu * mu1 * s4) * cc) / dn
        a12 = abs((1.0 - mu * mu1 * s4) * sc - (s4 * mu1 + mu) * cc) / dn
        a17 = a1p - mu1 * s4 * b1p + mu * rho3 * (a9 + a12)
        a18 = d1p - c1p * mu1 * s4 - k.d.rho_p * mu1 * s5 * (a1 + a5)
    else:
        a1 = abs(mu1 * (s5 - s4) * spa + (1.0 + mu1 * mu1 * s4 * s5) * cpa) / k.dn1
        a5 = abs(mu1 * (s5 - s4) * cpa - (1.0 + mu1 * mu1 * s4 * s5) * spa) / k.dn1
        a9 = abs((mu1 * s4 - mu) * sc - (1.0 + s4 * mu * mu1) * cc) / dn
        a12 = abs(-(1.0 + mu * mu1 * s4) * sc + (mu - mu1 * s4) * cc) / dn
        a17 = -a1p - mu1 * s4 * b1p + mu * rho3 * (a9 + a12)
        a18 = -(d1p + c1p * mu1 * s4 + k.d.rho_p * mu1 * s5 * (a1 + a5))
    return a17, a18


def coupled_phi_ddot_b176(
    tc: dict[str, float],
    a17: float,
    a18: float,
    ipr: float,
    a20: float,
    a21: float,
    a19: float,
    u: float,
    v: float,
    phi_dot: float,
    psi: float,
    psi_c: float,
    k: VergeConstants,
    t2: float,
    t3: float,
    i2: float,
    i3: float,
    n31: float,
    n32: float,
) -> float:
    """Monolithic coupled acceleration, B176 with A45-A50 as in subroutine FCT.

    ``tc`` holds the train coefficients (``TrainPhysics.coefficients``).  Used to check
    that the split (train response + verge) is exact.
    """
    a15, a16, a31, a32, a33, a34, a35 = (
        tc[n] for n in ("A15", "A16", "A31", "A32", "A33", "A34", "A35")
    )
    a42, a43, a44, i1r = tc["A42"], tc["A43"], tc["A44"], tc["I1R"]
    w = 2.0 * k.om2 / k.om_abs
    r = a15 * a18 / a44
    a45 = i3 * a18 + ipr * a17 * u - (i2 * n32 - a42 * i1r * n31 / a31) * r
    a46 = ipr * a17 * v + a17 * a21 * u * u + r * a34 * a42 * n31 * n31 / a31
    a47 = w * a17 * a20 * u + r * a33 * a42 * n31 / a31
    a48 = -r * a32 * a42 / a31 - r * a43 * t2 - a16 * a18 * t3 - k.om2 * a17 * a19
    a49 = r * a35 * a42 / a31
    a50 = k.d.mp * k.d.rcp * k.d.r4 * a17 * k.om2
    rhs = (
        -a46 * phi_dot * phi_dot
        - a47 * phi_dot
        + a48
        - a49 * tc["sinPhi"]
        + a50 * math.sin(k.gamma_pp - psi - psi_c)
    )
    return rhs / a45


class HeldTrain:
    """The train seen by the verge component: a reduced model of it over a step, its affine
    response at the wheel state it sent, (phi0, w0), continued by its slopes there (J_ref
    and J_stot in phi, T_ref in phi and phi_dot; zero slopes hold the response).  Peiret et
    al., "Co-Simulation of Multibody Systems With Contact Using Reduced Interface Models",
    J. Comput. Nonlinear Dyn. 15(4) 041001 (2020)."""

    def __init__(self, j_ref: float, t_ref: float, c_load: float, i_stot: float) -> None:
        self.j_ref, self.t_ref, self.c_load, self.i_stot = j_ref, t_ref, c_load, i_stot
        self.direction = 1
        # Slopes of J_ref, T_ref and J_stot in the wheel state about (phi0, w0), where the
        # train sent them: its reduced model over the step (all 0: the response held).
        self.j_phi = self.t_phi = self.t_w = self.i_phi = 0.0
        self.phi0 = self.w0 = 0.0

    def response(self, phi: float, phi_dot: float) -> tuple[float, float, float]:
        dp = phi - self.phi0
        return (
            self.j_ref + self.j_phi * dp,
            self.t_ref + self.t_phi * dp + self.t_w * (phi_dot - self.w0),
            self.c_load,
        )

    def impact_inertia(self, phi: float) -> float:
        return self.i_stot + self.i_phi * (phi - self.phi0)

    def mode_key(self) -> tuple[float, ...]:
        return (
            self.j_ref,
            self.t_ref,
            self.c_load,
            self.direction,
            self.j_phi,
            self.t_phi,
            self.t_w,
            self.phi0,
            self.w0,
        )

    def set_direction(self, direction: int, phi: float) -> None:
        self.direction = direction

    def mesh_indicators(self, phi: float) -> tuple[float, float]:
        return 1.0, 1.0

    def on_mesh_event(self, phi: float) -> None:
        pass

    def update_i1r(self, phi_dot: float, phi_ddot: float) -> None:
        pass

    def branch_indicators(self, phi: float, phi_dot: float, phi_ddot: float) -> tuple[()]:
        return ()


DEFAULT_STEP_BUDGET = 100_000  # internal steps of one doStep: about 10 s of work here


class StepBudgetSpent(ComponentError):
    """A doStep used up its internal step budget (VergeEscapement.max_internal_steps)."""


class VergeCore:
    """Regime machine and right-hand sides; y = [phi_T, phi_d, psi, psi_d, W_verge].

    ``train`` supplies response(phi, phi_d) -> (J_ref, T_ref, c_load), direction,
    set_direction, mesh_indicators, on_mesh_event, update_i1r and impact_inertia: either the
    held response (co-simulation component) or the live train physics (monolithic
    reference).
    """

    def __init__(
        self,
        k: VergeConstants,
        train: Any,
        phi_off: float,
        face: int = ENTRANCE,
        coupled: bool = True,
        v_capture: float = 1.0e-3,
        phi_stop: float = math.inf,
        log: Callable[[float, int, int, str], None] | None = None,
    ) -> None:
        self.k = k
        self.train = train
        self.phi_off = phi_off
        self.budget: int | None = None  # indicator evaluations left in this doStep
        self.face = face
        self.coupled = coupled
        self.psic = k.d.psic
        self.s4 = 1
        self.s5 = 1
        self.ipr_sign = 1
        self.train_stuck = False
        self.verge_stuck = False
        self.v_capture = v_capture
        self.phi_stop = phi_stop
        self.halted = False
        self.impacts = 0
        self.pn_peak = 0.0  # largest normal force so far (accepted points, their vertices)
        self.pn_points: tuple[tuple[float, float], ...] = ()  # last two (t, PN) in contact
        self.last_impact: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
        self.stall_reason = ""
        self.fault = ""
        # Whether the tooth has touched the active face since it became active (it starts
        # on the entrance face): a face passed in free flight untouched is a skipped tooth.
        self.engaged = True
        self.log = log
        self.t_base = 0.0
        self.t_mark = -1.0  # offset of the first regime change or impact (set by the caller)

    # -- helpers ------------------------------------------------------------------------
    @property
    def regime(self) -> int:
        if not self.coupled:
            return FREE
        return COUPLED_ENTRANCE if self.face == ENTRANCE else COUPLED_EXIT

    @property
    def alpha(self) -> float:
        return self.k.alpha[self.face]

    def _ipr(self, psi: float) -> float:
        # I_PR = I_p +/- A22 (clamped >= 0); A22 does not depend on s5.
        _, _, a22 = self.k.pivot(1, psi + self.psic)
        v = self.k.ip + self.ipr_sign * a22
        return v if v > 0.0 else 0.0

    def _mode_key(self) -> tuple[Any, ...]:
        return (
            self.face,
            self.s4,
            self.s5,
            self.ipr_sign,
            self.train_stuck,
            self.phi_off,
            self.psic,
            self.train.mode_key(),
        )

    def coupled_terms(self, y: list[float]) -> tuple[float, ...]:
        """Coupled regime at y: (phi_dd, psi, psi_d, psi_dd, Pn, T_esc, g, U, V_S/T, J_eff,
        centrifugal verge moment, T_esc at zero wheel acceleration, J_esc) with
        T_esc = T_esc_static - J_esc phi_dd (the escapement as an affine load on the wheel)."""
        # Memo of the last evaluation: indicators, accept and the next stage-1 derivative
        # all ask for the same point; the key covers everything the result depends on.
        key = (y[0], y[1], self._mode_key())
        memo = self.__dict__.get("_memo")
        if memo is not None and memo[0] == key:
            return memo[1]
        out = self._coupled_terms(y)
        self._memo = (key, out)
        return out

    def _coupled_terms(self, y: list[float]) -> tuple[float, ...]:
        k = self.k
        phi_l = y[0] + self.phi_off
        w = y[1]
        face = self.face
        alpha = k.alpha[face]
        psi, g, u, v, a1p, b1p, d1p = kinem(phi_l, alpha, k.a, k.b, k.c)
        s4, s5 = self.s4, self.s5
        a19, a20, _ = k.pivot(s5, psi + self.psic)
        a21 = s5 * a20
        a17, a18 = contact_coefficients(k, face, psi, s4, s5, self.train.direction, a1p, b1p, d1p)
        ipr = self._ipr(psi)
        j, t, c = self.train.response(y[0], w)
        a52 = 2.0 * k.om_abs * a20
        cent = k.a54 * math.sin(k.gamma_pp - psi - self.psic)
        psi_d = u * w
        n = (ipr * v + a21 * u * u) * w * w + a52 * psi_d + k.om2 * a19 - cent
        den = j * a18 + c * a17 * ipr * u
        if self.train_stuck:
            acc = 0.0
        else:
            acc = (a18 * t - c * a17 * n) / den
        psi_dd = u * acc + v * w * w
        pn = (ipr * psi_dd + a21 * psi_d * psi_d + a52 * psi_d + k.om2 * a19 - cent) / a18
        vst = sliding_velocity(phi_l, psi, w, psi_d, alpha, k.b, k.c)
        # den / a18: effective inertia at the wheel, must stay positive (else self-locking).
        # T_esc = -A17 Pn is affine in acc: -A17 n / A18 at acc = 0, slope -A17 I_PR U / A18.
        t_static, j_esc = -a17 * n / a18, a17 * ipr * u / a18
        return acc, psi, psi_d, psi_dd, pn, -a17 * pn, g, u, vst, den / a18, cent, t_static, j_esc

    def free_terms(self, y: list[float]) -> tuple[float, float, float]:
        """(phi_dd, psi_dd, centrifugal verge moment) in free motion (B187, B193)."""
        k = self.k
        psi, psi_d = y[2], y[3]
        cent = k.a54 * math.sin(k.gamma_pp - psi - self.psic)
        if self.verge_stuck:
            psi_dd = 0.0
        else:
            a19, a20, _ = k.pivot(self.s5, psi + self.psic)
            a52 = 2.0 * k.om_abs * a20
            psi_dd = (
                -self.s5 * a20 * psi_d * psi_d - a52 * psi_d - k.om2 * a19 + cent
            ) / self._ipr(psi)
        if self.train_stuck:
            acc = 0.0
        else:
            j, t, _ = self.train.response(y[0], y[1])
            acc = t / j
        return acc, psi_dd, cent

    # -- EventModel ---------------------------------------------------------------------
    def accept(self, y: list[float], t: float) -> None:
        """An accepted internal point: the normal force's peak between communication
        points, which the outputs at step ends miss when steps are long.  Where the force
        rose to the point before and falls after it, the peak is the vertex of the parabola
        through the three: the accepted points' own maximum falls short of it by the
        square of the step (M739 at tolerance 5e-4 and steps bounded only by switches:
        4.4e-4 off the monolithic model's peak at tolerance 1e-10)."""
        if not self.coupled:
            self.pn_points = ()
            return
        pn = self.coupled_terms(y)[4]
        t += self.t_base
        points = self.pn_points
        peak = max(pn, _vertex(*points, (t, pn))) if len(points) == 2 else pn
        self.pn_peak = max(self.pn_peak, peak)
        self.pn_points = (points[-1], (t, pn)) if points else ((t, pn),)

    def deriv(self, y: list[float]) -> list[float]:
        w = y[1]
        if self.coupled:
            acc, _, psi_d, psi_dd, _, t_esc, *_, cent, _, _ = self.coupled_terms(y)
            # Power balance of the verge side: input -T_esc phi_d minus d/dt(stored).
            p = -t_esc * w - self.k.ip * psi_d * psi_dd + cent * psi_d
            return [w, acc, psi_d, psi_dd, p]
        acc, psi_dd, cent = self.free_terms(y)
        psi_d = y[3]
        return [w, acc, psi_d, psi_dd, -self.k.ip * psi_d * psi_dd + cent * psi_d]

    def indicators(self, y: list[float]) -> tuple[float, ...]:
        # Evaluated once per internal step tried and per event-location iteration: the
        # count a doStep's budget is spent in.
        if self.budget is not None:
            self.budget -= 1
            if self.budget < 0:
                raise StepBudgetSpent("internal step budget spent")
        k = self.k
        sigma = self.face
        hi, lo = self.train.mesh_indicators(y[0])
        wheel = 1.0 if self.train_stuck else self.train.direction * y[1]
        stop = self.phi_stop - y[0]
        if self.coupled:
            _, _, psi_d, _, pn, _, g, _, vst, *_ = self.coupled_terms(y)
            return (
                sigma * g,
                pn,
                self.s4 * vst,
                self.s5 * psi_d,
                wheel,
                hi,
                lo,
                stop,
                *self._branch_indicators(y),
            )
        phi_l = y[0] + self.phi_off
        psi = y[2]
        alpha = k.alpha[sigma]
        arg = phi_l - psi - alpha
        f = k.a * math.sin(psi + alpha) - k.b * math.sin(arg) - k.c * math.sin(alpha)
        gp = k.a * math.cos(psi + alpha) + k.b * math.cos(arg) - k.c * math.cos(alpha)
        verge = 1.0 if self.verge_stuck else self.s5 * y[3]
        return (sigma * gp, sigma * f, 1.0, verge, wheel, hi, lo, stop, *self._branch_indicators(y))

    def _branch_indicators(self, y: list[float]) -> tuple[float, ...]:
        """Negative where an acceleration-dependent friction branch no longer matches the
        motion: the verge's I_PR (velocity times acceleration of the verge) and the
        train's own.  The report takes these signs from the last accepted step; switching
        them at the located instant is that rule's limit as the step goes to zero."""
        d = self.deriv(y)
        # s5 stands for the sign of psi_d (its zero is the verge-speed event), so this
        # crosses only where the verge acceleration does.
        return (self.ipr_sign * self.s5 * d[3], *self.train.branch_indicators(y[0], y[1], d[1]))

    def _switch_branch(self, y: list[float], index: int) -> list[float]:
        d = self.deriv(y)
        if index == IND_IPR:  # s5 for the sign of psi_d, as in the indicator
            self.ipr_sign = 1 if self.s5 * d[3] >= 0.0 else -1
        else:
            self.train.update_i1r(y[1], d[1])
        return y

    def event(self, y: list[float], index: int, t: float) -> list[float]:
        self.pn_points = ()  # the force may jump here: no parabola across it
        if index >= IND_IPR:
            return self._switch_branch(y, index)
        y = self._regime_event(y, index, t)
        if not (self.halted or self.train_stuck):
            # A regime change can jump the accelerations: the branches follow at once.
            self._switch_branch(y, IND_IPR)
            self._switch_branch(y, IND_TRAIN_BRANCH)
        return y

    def _regime_event(self, y: list[float], index: int, t: float) -> list[float]:
        if index == IND_STOP:
            self.halted = True
            return y
        if index in (IND_MESH_HI, IND_MESH_LO):
            self.train.on_mesh_event(y[0])
            return y
        if index == IND_WHEEL_SPEED:
            return self._wheel_reversal(y, t)
        if self.coupled:
            if index == IND_FACE_END:
                y = self._sync_kinematics(y)
                return self._reindex_and_free(y, t)
            if index == IND_CONTACT:
                y = self._sync_kinematics(y)
                self._switch(t, FREE, "separation Pn = 0")
                return y
            if index in (IND_SLIDE, IND_VERGE_SPEED) and abs(y[1]) < WHEEL_AT_REST:
                # psi_d = U phi_d and V_S/T ~ phi_d: at a wheel stop these indicators cross
                # with the wheel speed and fire first; the wheel's own crossing is then lost.
                return self._wheel_reversal(y, t)
            if index == IND_SLIDE:
                return self._slide_reversal(y, t)
            self.s5 = -self.s5
            return y
        if index == IND_FACE_END:
            return self._reindex_free(y, t)
        if index == IND_CONTACT:
            return self._contact(y, t)
        if index == IND_VERGE_SPEED:
            return self._verge_stop(y)
        return y

    # -- transitions --------------------------------------------------------------------
    def _mark(self, t: float) -> None:
        if self.t_mark < 0.0:
            self.t_mark = t

    def _switch(self, t: float, new: int, why: str) -> None:
        old = self.regime
        self.coupled = new != FREE
        self._mark(t)
        if self.log is not None:
            self.log(self.t_base + t, old, self.regime, why)

    def _sync_kinematics(self, y: list[float]) -> list[float]:
        """psi, psi_d from the coupled kinematics (C18, C19)."""
        k = self.k
        psi, _, u, *_ = kinem(y[0] + self.phi_off, self.alpha, k.a, k.b, k.c)
        return [y[0], y[1], psi, u * y[1], y[4]]

    def _reindex(self, y: list[float]) -> list[float]:
        """Per-tooth re-indexing (labels 3 and 4 of the main program, ALPHEX corrected)."""
        k = self.k
        lam = k.d.lam
        if self.face == ENTRANCE:
            self.phi_off += k.d.nt * k.delta
            psi = y[2] + TWO_PI - lam
            self.psic += lam
            self.face = EXIT
        else:
            self.phi_off -= (k.d.nt + 1) * k.delta
            psi = y[2] - TWO_PI + lam
            self.psic -= lam
            self.face = ENTRANCE
        self.engaged = False
        return [y[0], y[1], psi, y[3], y[4]]

    def _reindex_and_free(self, y: list[float], t: float) -> list[float]:
        self._switch(t, FREE, "tooth left the face end (g = 0)")
        y = self._reindex(y)
        self.s5 = _sgn(y[3])
        return self._free_entry(y, t)

    def _reindex_free(self, y: list[float], t: float) -> list[float]:
        if self.log is not None:
            self.log(self.t_base + t, FREE, FREE, "tip passed the face end in free flight")
        if not self.engaged:
            # The wheel ran past a face it never touched: the escapement does not escape,
            # it lets teeth through, and nothing after this instant is the design's motion.
            face = "entrance" if self.face == ENTRANCE else "exit"
            self.fault = (
                f"the escapement skips teeth: at t = {self.t_base + t:.6g} s a tooth passed "
                f"the {face} face in free flight without touching it: a design that does "
                "not escape (mechcosim check names the rule), or an integration that stepped "
                "over the contact (a tighter tolerance tells which)"
            )
            self.halted = True
            return y
        return self._free_entry(self._reindex(y), t)

    def _free_entry(self, y: list[float], t: float) -> list[float]:
        """After re-indexing the indicators of the new face may already be negative:
        tip behind the face plane (contact now) or past its end (re-index again).  Two
        passes in a row mean no face can catch the wheel: the verge is disengaged."""
        for _ in range(2):
            ind = self.indicators(y)
            if ind[IND_FACE_END] < 0.0:
                y = self._reindex(y)
                continue
            if ind[IND_CONTACT] < 0.0:
                return self._contact(y, t)
            return y
        self.fault = "verge disengaged: the wheel tooth passes both faces (runaway)"
        self.halted = True
        if self.log is not None:
            self.log(self.t_base + t, FREE, FREE, "runaway")
        return y

    def closing_speed(self, y: list[float]) -> tuple[float, float, float]:
        """(v_c, A1', D1') with v_c = sigma (V_SN - V_TN) (contact test, labels 8-11)."""
        k = self.k
        _, a1p, d1p = face_arms(y[0] + self.phi_off, y[2], self.alpha, k.b, k.c)
        return self.face * (a1p * y[1] - d1p * y[3]), a1p, d1p

    def _contact(self, y: list[float], t: float) -> list[float]:
        """Tip reached the face plane: impact, gentle contact or pass-by (labels 8-12)."""
        vc, a1p, d1p = self.closing_speed(y)
        if vc < -self.v_capture:
            return y  # separating: stays free (f turns positive again)
        self.engaged = True
        if vc > self.v_capture:
            phi_f, psi_f = impact_map(
                y[1], y[3], a1p, d1p, self.k.ip, self.train.impact_inertia(y[0]), self.k.e_rest
            )
            self.impacts += 1
            self._mark(t)
            self.last_impact = (y[1], y[3], phi_f, psi_f)
            if self.log is not None:
                self.log(self.t_base + t, FREE, FREE, "impact")
            y = [y[0], phi_f, y[2], psi_f, y[4]]
            y[4] += self._impact_loss(y, a1p, d1p)
            if phi_f * self.train.direction < 0.0:
                # A heavy verge throws the wheel back (recoil): the train's friction now
                # opposes the backward motion (eq. 7); the wheel-speed indicator jumped
                # through zero with the impact, so no crossing would flip it later.
                self.train.set_direction(_sgn(phi_f), y[0])
            if self.face * (a1p * phi_f - d1p * psi_f) < -self.v_capture:
                self.verge_stuck = False
                self.s5 = _sgn(psi_f)
                return y  # rebound (e > 0)
        return self._enter_coupled(y, t)

    def _impact_loss(self, y: list[float], a1p: float, d1p: float) -> float:
        phi_i, psi_i, phi_f, psi_f = self.last_impact
        j_stot = self.train.impact_inertia(y[0])
        return 0.5 * j_stot * (phi_i**2 - phi_f**2) + 0.5 * self.k.ip * (psi_i**2 - psi_f**2)

    def _enter_coupled(self, y: list[float], t: float) -> list[float]:
        new = COUPLED_ENTRANCE if self.face == ENTRANCE else COUPLED_EXIT
        self._switch(t, new, "contact")
        self.verge_stuck = False
        y = self._sync_kinematics(y)
        k = self.k
        vst = sliding_velocity(y[0] + self.phi_off, y[2], y[1], y[3], self.alpha, k.b, k.c)
        self.s4 = _sgn(vst)
        self.s5 = _sgn(y[3])
        pn = self.coupled_terms(y)[4]
        if pn < 0.0:
            self._switch(t, FREE, "separation at contact (Pn < 0)")
        return y

    def _verge_stop(self, y: list[float]) -> list[float]:
        """Free verge reached psi_d = 0: reverse if the moment beats pivot friction."""
        old = self.s5
        self.s5 = -old
        y0 = [y[0], y[1], y[2], 0.0, y[4]]
        if -old * self.free_terms(y0)[1] > 0.0:
            return y0
        self.s5 = old
        self.verge_stuck = True
        return y0

    def _wheel_reversal(self, y: list[float], t: float) -> list[float]:
        """Escape-wheel speed crossed zero: reverse (friction flips, eq. 7) or stick."""
        return self.decide_direction(y, t, -self.train.direction)

    def decide_direction(self, y: list[float], t: float, first: int) -> list[float]:
        """Wheel at rest: move in the direction whose friction signs give an acceleration
        in that same direction (mu, s4, s5 all follow the motion), else stick (stall)."""
        tr = self.train
        old = (tr.direction, self.s4, self.s5)
        y0 = [y[0], 0.0, y[2], 0.0 if self.coupled else y[3], y[4]]
        if self.coupled:
            y0 = self._sync_kinematics(y0)
        for d in (first, -first):
            tr.set_direction(d, y[0])
            if self.coupled:
                k = self.k
                phi_l = y[0] + self.phi_off
                _, _, u, *_ = kinem(phi_l, self.alpha, k.a, k.b, k.c)
                self.s4 = _sgn(sliding_velocity(phi_l, y0[2], d, u * d, self.alpha, k.b, k.c))
                self.s5 = _sgn(u * d)
            acc = self.coupled_terms(y0)[0] if self.coupled else self.free_terms(y0)[0]
            if d * acc > 0.0:
                # A start from rest: the lagged acceleration-dependent branches (I1R, I_PR)
                # take the new motion (velocity x acceleration > 0) at once, so the first
                # step after it does not depend on its length.
                tr.update_i1r(0.0, acc)
                if self.coupled:
                    self.ipr_sign = 1
                return y0
        tr.set_direction(old[0], y[0])
        self.s4, self.s5 = old[1], old[2]
        self.train_stuck = True
        self.stall_reason = "escape wheel stopped: drive cannot overcome friction"
        if self.log is not None:
            self.log(self.t_base + t, self.regime, self.regime, "stall")
        return y0

    def _slide_reversal(self, y: list[float], t: float) -> list[float]:
        """V_S/T crossed zero in coupled motion: flip s4, or decide anew if the wheel
        is at rest (start from rest, or the wheel stops)."""
        k = self.k
        phi_l = y[0] + self.phi_off
        vst = sliding_velocity(phi_l, y[2], y[1], y[3], self.alpha, k.b, k.c)
        if vst == 0.0 or y[1] == 0.0:
            return self.decide_direction(y, t, self.train.direction)
        self.s4 = _sgn(vst)
        return y


class VergeEscapement(Component):
    """Verge + tooth-face contact, driven by the escape wheel's state and affine response.

    Regime codes: 0 free, 1 coupled on the entrance face, 2 coupled on the exit face.
    At each step the internal copy of the escape-wheel state is taken from the sampled
    inputs (phi, phi_dot); within the step it follows J_ref phi_dd = T_ref + c_load T_esc
    with the response taken at that state and continued by its slopes (``J_ref_phi``,
    ``T_ref_phi``, ``T_ref_phi_dot``; an impact takes J_stot + ``J_stot_phi`` (phi - phi0)).
    The torque's impulse over the step and its first moment are integrated with it
    (``T_esc_mean``, ``T_esc_rate_mean``).  When ``impact_count`` increments,
    ``phi_dot_post`` is the escape-wheel speed after the impact, for the train
    (``GearTrain.phi_dot_impact``),
    which takes it at once so that the next phi_dot fed back is the post-impact speed.
    ``t_event`` is the time of the first regime change or impact of the last step that had
    one: a master that steps to events retakes the step with length t_event - t.
    t_event == t (the jump to the input state already crossed an indicator, so the event
    fired at the step start): keep the step, giving an impact to the train first.
    Energy: stored = 1/2 I_p psi_dot^2; the impact losses are booked here.

    Early return (``components.early_return``): with the input ``early_return`` = 1 a step
    ends just after its first event (regime change, impact, friction sign or branch: each
    jumps T_esc or the impact outputs) and ``t_reached`` says where.

    Port ``escape_wheel``: angle and speed (in), torque T_esc (out), and the train's
    affine response (inertia J_ref, drive T_ref, load_factor c_load, impact_inertia J_stot).
    The other way the escapement is an affine load: T_esc = T_esc_static - J_esc phi_ddot
    (static_torque, load_inertia out), so that a train holding these over a step follows
    the coupled acceleration even where drive and reaction nearly cancel (a heavy verge),
    and decides a start from rest on the static reaction.
    """

    # Cheap snapshot: the verge constants are immutable in use and shared; the regime
    # machine's mode, the held train response and the state vector are copied.
    SNAPSHOT = SnapshotPlan(lists=("_y",), objects={"_held": {}, "_core": {"train": "_held"}})
    STEP_TAKES_INPUTS = True  # step() starts with _take_inputs and ends with _outputs

    REGIME_NAMES = REGIME_NAMES
    PORTS = {"escape_wheel": ESCAPE_WHEEL_PORT}

    VARIABLES = (
        # The SANDA2V deck's escapement quantities (cards 1-2, the pallet's body) and the
        # train geometry that places the pallet pivot in the fuze body (B1-B31).
        *deck_variables(VERGE),
        Variable(
            "v_capture",
            "parameter",
            "m/s",
            1.0e-3,
            "closing speed below which contact is gentle (no impact)",
            min=0.0,
        ),
        *INTEGRATION_VARIABLES,
        Variable(
            "max_internal_steps",
            "parameter",
            "1",
            DEFAULT_STEP_BUDGET,
            "budget of one doStep: internal integration steps and event-location iterations "
            "(spent: the step is discarded, with a message)",
            "Integer",
            min=1.0,
        ),
        Variable("phi", "input", "rad", 0.0, "cumulative escape-wheel angle", sampled=True),
        Variable("phi_dot", "input", "rad/s", 0.0, "escape-wheel speed", sampled=True),
        # The train's response at the wheel state sent, with its slopes in that state: the
        # verge follows it along its own copy of the wheel, so it is taken at the step start.
        Variable(
            "J_ref", "input", "kg.m2", 2.8e-9, "train effective inertia at the wheel", sampled=True
        ),
        Variable("T_ref", "input", "N.m", 0.0, "train net torque at the wheel", sampled=True),
        Variable("J_ref_phi", "input", "kg.m2/rad", 0.0, "slope of J_ref in the wheel angle"),
        Variable("T_ref_phi", "input", "N.m/rad", 0.0, "slope of T_ref in the wheel angle"),
        Variable("T_ref_phi_dot", "input", "N.m.s/rad", 0.0, "slope of T_ref in the wheel speed"),
        Variable("c_load", "input", "1", 1.0, "train factor on T_esc"),
        Variable(
            "J_stot",
            "input",
            "kg.m2",
            M739.i_stot,
            "train inertia for impacts (B213)",
            sampled=True,
        ),
        Variable("J_stot_phi", "input", "kg.m2/rad", 0.0, "slope of J_stot in the wheel angle"),
        # Direct feedthrough: while coupled the verge follows the wheel angle and speed and
        # the contact force follows the train's response too; free, the gap and the wheel's
        # own acceleration follow the inputs.  J_stot acts only at an impact, in step().
        Variable(
            "psi",
            "output",
            "rad",
            0.0,
            "verge angle, entrance-face coordinates",
            depends_on=("phi",),
        ),
        Variable("psi_dot", "output", "rad/s", 0.0, "verge speed", depends_on=_WHEEL_STATE),
        Variable(
            "psi_local",
            "output",
            "rad",
            0.0,
            "verge angle in the active face's frame",
            depends_on=("phi",),
        ),
        Variable(
            "phi_local",
            "output",
            "rad",
            M739.phi_start,
            "wheel angle, active face frame",
            depends_on=("phi",),
        ),
        Variable(
            "T_esc",
            "output",
            "N.m",
            0.0,
            "escapement moment on the escape wheel",
            depends_on=_WHEEL_AND_TRAIN,
        ),
        Variable(
            "T_esc_static",
            "output",
            "N.m",
            0.0,
            "T_esc at zero wheel acceleration: T_esc = T_esc_static - J_esc phi_ddot",
            depends_on=_WHEEL_STATE,
        ),
        Variable(
            "J_esc",
            "output",
            "kg.m2",
            0.0,
            "escapement inertia felt at the wheel (coupled)",
            depends_on=_WHEEL_STATE,
        ),
        # Over the last step, for a train stepped after the verge over the same interval:
        # the escapement as the plain torque whose impulse the verge's wheel took (impacts
        # aside: they reach the train as phi_dot_post), exact with early return.
        Variable(
            "T_esc_mean",
            "output",
            "N.m",
            0.0,
            "T_esc over the last step, mean",
            role=Role("step_mean_of", "T_esc"),
        ),
        Variable(
            "T_esc_static_mean",
            "output",
            "N.m",
            0.0,
            "= T_esc_mean (with J_esc_mean = 0)",
            role=Role("step_mean_of", "T_esc_static"),
        ),
        Variable(
            "J_esc_mean",
            "output",
            "kg.m2",
            0.0,
            "0: the step mean is a plain torque",
            role=Role("step_mean_of", "J_esc"),
        ),
        # And its rate about the mean at the step's middle, from the torque's first moment:
        # 0 as a held signal, the step's as its mean.
        Variable("T_esc_rate", "output", "N.m/s", 0.0, "0: T_esc is held over a step"),
        Variable(
            "T_esc_rate_mean",
            "output",
            "N.m/s",
            0.0,
            "T_esc's rate over the last step",
            role=Role("step_mean_of", "T_esc_rate"),
        ),
        Variable(
            "phi_ddot",
            "output",
            "rad/s2",
            0.0,
            "escape-wheel acceleration (own)",
            depends_on=_WHEEL_AND_TRAIN,
        ),
        Variable(
            "phi_own",
            "output",
            "rad",
            0.0,
            "escape-wheel angle (own copy)",
            role=Role("own_copy_of", "phi"),
            depends_on=("phi",),
        ),
        Variable(
            "phi_dot_own",
            "output",
            "rad/s",
            0.0,
            "escape-wheel speed (own copy)",
            role=Role("own_copy_of", "phi_dot"),
            depends_on=("phi_dot",),
        ),
        Variable(
            "PN",
            "output",
            "N",
            0.0,
            "tooth-face normal force (coupled)",
            depends_on=_WHEEL_AND_TRAIN,
        ),
        Variable(
            "PN_peak",
            "output",
            "N",
            0.0,
            "largest normal force so far, at every internal step (peaks between steps)",
        ),
        Variable("face", "output", "1", ENTRANCE, "+1 entrance face active, -1 exit", "Integer"),
        Variable(
            "ind_face_end",
            "output",
            "m",
            0.0,
            "sigma g (coupled) / sigma g' (free)",
            depends_on=("phi",),
        ),
        Variable(
            "ind_gap",
            "output",
            "m",
            0.0,
            "sigma f, normal gap of the tip (free)",
            depends_on=("phi",),
        ),
        Variable(
            "ind_pn",
            "output",
            "N",
            0.0,
            "Pn (coupled), zero at separation",
            depends_on=_WHEEL_AND_TRAIN,
        ),
        Variable(
            "v_close",
            "output",
            "m/s",
            0.0,
            "closing speed sigma (V_SN - V_TN)",
            depends_on=_WHEEL_STATE,
        ),
        Variable("impact_count", "output", "1", 0, "impacts so far", "Integer"),
        Variable("phi_dot_post", "output", "rad/s", 0.0, "wheel speed after the last impact"),
        Variable("psi_dot_post", "output", "rad/s", 0.0, "verge speed after the last impact"),
        Variable(
            "t_event",
            "output",
            "s",
            -1.0,
            "first regime change or impact of the last step that had one",
        ),
        *EARLY_RETURN_VARIABLES,
        Variable(
            "J_load",
            "output",
            "kg.m2",
            0.0,
            "verge inertia at the wheel, I_p U^2 (0 when free)",
            depends_on=("phi",),
        ),
        # It would follow psi (coupled: phi) through A54 = m_p r_cp R4 omega^2, which is zero
        # for the M739 pallet (r_cp = 0): no feedthrough.
        Variable("external_work", "output", "J", 0.0, "work of the spin on the pallet"),
        *common_outputs(stored_energy=_WHEEL_STATE),
    )

    def initialize(self, t0: float) -> None:
        self.check_parameters()  # a NaN spin or restitution is named here, not met later
        # The train's inertias divide the wheel's motion: a host that starts every input
        # at 0 must be told which, not meet a division by zero.
        for name in ("J_ref", "J_stot"):
            value = getattr(self, name)
            if not value > 0.0:
                raise ComponentError(
                    f"VergeEscapement: input {name} = {value!r} kg.m2 at initialization; "
                    "expected more than 0 (an inertia of the train at the escape wheel: set it "
                    "from the train's output before initialization ends)"
                )
        self._control = integration_step_control(self, STATE_SCALES)
        self._h_next = 0.0
        data = design_of(self, VERGE)
        if self.check_design:
            raise_first(verge_violations(data))  # a broken design is refused, not run
        k = VergeConstants(data, self.mu1, self.mu, self.spin, self.e_rest)
        self._held = HeldTrain(self.J_ref, self.T_ref, self.c_load, self.J_stot)
        self._core = VergeCore(
            k, self._held, self.phi_local_start - self.phi, v_capture=self.v_capture
        )
        self._y = self._core._sync_kinematics([self.phi, self.phi_dot, 0.0, 0.0, 0.0])
        self._g_end = self._core.indicators(self._y)
        self._cos0 = math.cos(k.gamma_pp - self._y[2] - self._core.psic)
        self.t_event = -1.0
        self.t_reached = t0
        self._outputs(self._y)

    def _take_inputs(self) -> list[float]:
        """The state at the step start: the wheel from the (sampled) inputs, the verge own."""
        core, held = self._core, self._held
        held.j_ref, held.t_ref, held.c_load, held.i_stot = (
            self.J_ref,
            self.T_ref,
            self.c_load,
            self.J_stot,
        )
        held.j_phi, held.t_phi, held.t_w = self.J_ref_phi, self.T_ref_phi, self.T_ref_phi_dot
        held.phi0, held.w0 = self.phi, self.phi_dot
        held.i_phi = self.J_stot_phi
        if self.phi_dot != 0.0:
            held.direction = _sgn(self.phi_dot)
        y = [self.phi, self.phi_dot, self._y[2], self._y[3], self._y[4]]
        return core._sync_kinematics(y) if core.coupled else y

    def update_outputs(self) -> None:
        # Direct feedthrough: T_esc, PN and phi_ddot depend on the train's response and
        # on the wheel state; the internal state itself moves only in step().
        self._outputs(self._take_inputs())

    def step(self, t: float, h: float) -> None:
        core = self._core
        self.t_reached = t + h
        y = self._take_inputs()
        core.t_base = t
        core.t_mark = -1.0
        core.train_stuck = False
        if self.phi_dot == 0.0:
            # Wheel at rest: friction signs follow the motion that starts (or stick).
            y = core.decide_direction(y, 0.0, self._held.direction)
        y = self._resync_events(y)
        if core.train_stuck and core.coupled:
            # The wheel is held by static friction and the verge rides on it: at rest.
            self._y = y
            self._g_end = core.indicators(y)
            self._outputs(y)
            self.T_esc_mean = self.T_esc_static_mean = self.T_esc
            self.T_esc_rate_mean = 0.0
            return
        core.budget = int(self.max_internal_steps)
        # The escapement torque's integral and first moment over the step ride along as
        # quadratures: a train stepped after the verge takes that impulse and its spread.
        moments = WithMoments(core, self._torque_at, len(y))
        model = UntilFirstEvent(moments, t) if self.early_return else moments
        try:
            done = advance(model, moments.start(y), h, self._control, self._h_next)
        except StepBudgetSpent:
            raise ComponentError(
                f"VergeEscapement: doStep from t = {t:.9g} s over {h:.6g} s spent its budget of "
                f"{int(self.max_internal_steps)} internal steps (max_internal_steps) before its "
                "end; take shorter communication steps or give a larger budget"
            ) from None
        finally:
            core.budget = None
        y, self._h_next = done.y[: len(y)], done.h_next
        if core.halted:
            raise ComponentError(f"VergeEscapement: {core.fault}")
        if core.t_mark >= 0.0:
            self.t_event = t + core.t_mark
        self.t_reached = reached(t, h, model)
        # Impacts aside: they reach the train as phi_dot_post.
        mean, rate = moments.mean_and_rate(done.y)
        self._y = y
        self._g_end = core.indicators(y)
        if core.coupled:  # the step's end is a point of the motion too
            core.pn_peak = max(core.pn_peak, core.coupled_terms(y)[4])
        self._outputs(y)
        self.T_esc_mean = self.T_esc_static_mean = mean
        self.T_esc_rate_mean = rate

    def _torque_at(self, y: list[float]) -> float:
        """The escapement moment on the wheel at y (none while free)."""
        core = self._core
        if not core.coupled:
            return 0.0
        return core.coupled_terms(y)[5]

    def _resync_events(self, y: list[float]) -> list[float]:
        """Fire the events that the jump to the input state crossed (e.g. the tooth is
        already on the face plane because the train's phi is slightly ahead of the copy)."""
        core = self._core
        for _ in range(8):
            g_now = core.indicators(y)
            hit = [
                i for i, (a, b) in enumerate(zip(self._g_end, g_now, strict=True)) if a >= 0.0 > b
            ]
            if not hit:
                break
            y = core.event(y, hit[0], 0.0)
            self._g_end = core.indicators(y)
        return y

    def _outputs(self, y: list[float]) -> None:
        core = self._core
        k = core.k
        if core.coupled:
            acc, psi, psi_d, _, pn, t_esc, g, u, *_, t_static, j_esc = core.coupled_terms(y)
            self.PN, self.T_esc, self.ind_pn = pn, t_esc, pn
            self.T_esc_static, self.J_esc = t_static, j_esc
            self.J_load = k.ip * u * u
            self.ind_face_end = core.face * g
            self.ind_gap = 0.0
        else:
            acc = core.free_terms(y)[0]
            psi, psi_d = y[2], y[3]
            self.PN = self.T_esc = self.ind_pn = self.J_load = 0.0
            self.T_esc_static = self.J_esc = 0.0
            ind = core.indicators(y)
            self.ind_face_end, self.ind_gap = ind[IND_FACE_END], ind[IND_CONTACT]
        self.PN_peak = core.pn_peak
        self.v_close = core.closing_speed(y)[0]
        self.phi_ddot = acc
        self.phi_own, self.phi_dot_own = y[0], y[1]
        self.psi_local = psi
        self.psi_dot = psi_d
        body = psi + core.psic - k.d.psic
        self.psi = math.atan2(math.sin(body), math.cos(body))
        self.phi_local = y[0] + core.phi_off
        self.face = core.face
        self.regime = core.regime
        self.impact_count = core.impacts
        self.phi_dot_post, self.psi_dot_post = core.last_impact[2], core.last_impact[3]
        self.stored_energy = 0.5 * k.ip * psi_d * psi_d
        # Work of the spin on an eccentric pallet (zero for r_cp = 0).
        self.external_work = k.a54 * (math.cos(k.gamma_pp - psi - core.psic) - self._cos0)
        self.dissipated_work = y[4]


_KERNEL = load_kernel("m739_kernel")
if _KERNEL is not None:  # the compiled twins (components.kernels): the same results
    contact_coefficients = _KERNEL.contact_coefficients
    VergeCore._coupled_terms = _KERNEL.coupled_terms
    # the loop between events in C for these (event_integration.advance)
    _KERNEL.use_classes(
        verge_core=VergeCore,
        held_train=HeldTrain,
        moments=WithMoments,
        until_first_event=UntilFirstEvent,
        torque_at=VergeEscapement._torque_at,
        verge_budget_spent=StepBudgetSpent,
    )
    _KERNEL.use_python_verge(indicators=VergeCore.indicators, deriv=VergeCore.deriv)
    VergeCore.indicators = _KERNEL.verge_indicators  # type: ignore[method-assign]
    VergeCore.deriv = _KERNEL.verge_deriv  # type: ignore[method-assign]
    # and the component's own Python around the loop
    _KERNEL.use_python_component(
        take_inputs=VergeEscapement._take_inputs,
        resync_events=VergeEscapement._resync_events,
        outputs=VergeEscapement._outputs,
    )
    VergeEscapement._take_inputs = _KERNEL.component_take_inputs  # type: ignore[method-assign]
    VergeEscapement._resync_events = _KERNEL.component_resync_events  # type: ignore[method-assign]
    VergeEscapement._outputs = _KERNEL.component_outputs  # type: ignore[method-assign]
