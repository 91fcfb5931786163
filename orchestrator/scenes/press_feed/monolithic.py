"""Monolithic reference of the press roll feed (Xu 1993, Part I, Apps. A-H, Part II §4).

The drive (crank + RSSR + elastic coupler), the sprag clutch and the brake/strip shaft are
assembled into one ODE from the components' own physics functions and integrated with
solve_ivp at tight tolerances; every regime change is a terminal event located exactly:

* clutch engagement (relative speed of the races turns positive, F.3) and disengagement
  (windup back to zero, E.3),
* brake break-away (clutch torque reaches T_b, D.3) and stop (shaft speed reaches zero),
* rocker reversal (theta4' = 0, eq. 62), which only changes the reported regime.

Regimes of the thesis emerge from the discrete states: 1 windup (engaged, shaft stuck,
rocker forward), 2 forward feed (shaft slipping), 3 unwinding (engaged, stuck, rocker
returning), 4 overrun (clutch disengaged).

``model="linearized"`` is the App. C/H analytic model integrated numerically: secant and
tangent clutch stiffnesses switched per regime (K_l1, K_l2 with -T_b/2, K_l3, 0), the App. H
constants (M_e, K_e, zeta_co, F2 = 0.098 rad/in, J_o5 = 0.41) and the App. H Fourier rocker
in the forcing.  By default the regime ends (D.3, 62, E.3, F.3) use the same Fourier rocker;
``event_kinematics="exact"`` uses the exact rocker instead.  The printed end of Regime 2
(434.694 deg) is only met with the Fourier rocker (exact: 434.18 deg), the printed end of
Regime 4 (615.642 deg) only with the exact one (Fourier: 615.22 deg); both stay within the
0.5 deg (Tables H-6, H-8) with the Fourier default.  Its clutch law has an offset (-T_b/2), so its
"energy" figures are not a balance.

Options: clutch "hertz" takes K = alpha R_i Z G from the two-point contact (Part III) and
adds the sprags' share of A1 (119) to the shaft inertia; damping "linear" is Part I's C_sp.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

from components.brake_load import (
    REGIME_SLIP_BACKWARD,
    REGIME_SLIP_FORWARD,
    REGIME_STICK,
    shaft_acceleration,
    slip_direction,
)
from components.crank_coupler_drive import (
    DriveModel,
    build_drive_model,
    coupler_derivatives,
    coupler_energy,
    rocker_motion,
    strain_factors,
)
from components.kernels import load_kernel
from components.press_feed_data import (
    APP_H_F2,
    APP_H_FOURIER,
    APP_H_J_O5,
    APP_H_K_E,
    APP_H_M_E,
    APP_H_PHI1_START_DEG,
    APP_H_ZETA_CO,
    C_NL,
    C_SP,
    COUPLER_STANDARD,
    IN,
    J_O5_SHAFT,
    J_PART2,
    K_SP,
    LINKAGE_APP_H,
    LINKAGE_TABLE1,
    LINKAGE_TABLE3,
    N_DAMP,
    ROLLER_RADIUS,
    RUNS,
    BentCoupler,
    RSSRLinkage,
)
from components.rssr_kinematics import ExactRSSR, rocker_extremes
from components.sprag_clutch import (
    clutch_dissipation_rate,
    clutch_energy,
    clutch_torque,
    linearized_torque,
    secant_stiffness,
    sprag_inertia_terms,
    tangent_stiffness,
    two_point_hertz,
    unwinding_stiffness,
)
from components.units import rpm_to_rad_s

WINDUP, FEED, UNWIND, OVERRUN = 1, 2, 3, 4
# state vector: q, q', theta5, theta5', W_in, D_coupler, D_clutch, D_brake, and, while the
# shaft slips: int w dt, int T dt, slip time
NY = 11


@dataclass(frozen=True)
class FeedOptions:
    """What to simulate; None picks the value of the run (RUNS) or of App. H."""

    run: int = 1
    model: str = "nonlinear"  # "nonlinear" | "linearized" (App. C/H)
    clutch: str = "lumped"  # "lumped" | "hertz" (two-point Hertz stiffness, Part III)
    damping: str = "nonlinear"  # "nonlinear" (Part II) | "linear" (Part I C_sp)
    coupler: str = "elastic"  # "elastic" | "rigid"
    cycles: int = 3
    rpm: float | None = None
    brake_torque: float | None = None
    j5: float | None = None
    linkage: RSSRLinkage | None = None
    bent_coupler: BentCoupler | None = None  # None: the run's coupler
    f1: tuple[float, float, float] | None = None  # None: App. H's F1 coefficients
    event_kinematics: str = "fourier"  # linearized model: "exact" | "fourier" rocker for events
    rtol: float = 1e-10
    atol: float = 1e-14
    max_step: float = 2.0e-3
    samples_per_cycle: int = 1440
    # Right-hand-side evaluations the explicit reference may spend: the example runs need
    # 6,000-20,000 for three cycles; a very stiff variant (say a load inertia of 1e-9
    # kg.m2) would otherwise grind on for hours.
    max_evaluations: int = 2_000_000


@dataclass
class FeedResult:
    cycles: list[dict] = field(default_factory=list)
    regime_log: list[tuple[float, int, int]] = field(default_factory=list)
    energy: dict = field(default_factory=dict)
    series: dict = field(default_factory=dict)
    events: list[dict] = field(default_factory=list)  # state at every regime end
    period: float = 0.0
    phi1_0: float = 0.0


def feed_regime(brake: int, engaged: bool, rocker_forward: bool) -> int:
    """Thesis regime number from the subsystems' discrete states."""
    if not engaged:
        return OVERRUN
    if brake != REGIME_STICK:
        return FEED
    return WINDUP if rocker_forward else UNWIND


# -- the assembled nonlinear model ----------------------------------------------------------
class _Nonlinear:
    """Drive + clutch + brake with their own laws; discrete state = (brake, engaged, lock)."""

    # The subsystem each event function of ``events`` belongs to, in order.
    EVENT_SOURCES = ("clutch", "brake", "rocker")

    def __init__(
        self,
        drive: DriveModel,
        k: float,
        c_lin: float,
        c_nl: float,
        t_b: float,
        j5: float,
        phi1_0: float,
    ) -> None:
        self.m, self.k, self.c_lin, self.c_nl = drive, k, c_lin, c_nl
        self.t_b, self.j5, self.phi1_0 = t_b, j5, phi1_0
        self.brake, self.engaged, self.lock, self.forward = REGIME_STICK, True, 0.0, True

    def signals(self, t: float, y: np.ndarray) -> tuple:
        phi1 = self.phi1_0 + self.m.omega * t
        kin = self.m.kin(phi1)
        th4, th4d = rocker_motion(self.m, phi1, y[0], y[1], kin)
        rel = th4d - y[3]
        w = th4 - y[2] - self.lock if self.engaged else 0.0
        trq = clutch_torque(w, rel, self.k, self.c_lin, self.c_nl, N_DAMP) if self.engaged else 0.0
        return phi1, kin, th4, th4d, w, rel, trq

    def rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        phi1, kin, _, _, w, rel, trq = self.signals(t, y)
        qdd, _, _, p_in, p_co = coupler_derivatives(self.m, phi1, y[0], y[1], trq, kin)
        slipping = self.brake != REGIME_STICK
        th5d = y[3] if slipping else 0.0
        return np.array(
            [
                y[1],
                qdd,
                th5d,
                shaft_acceleration(self.brake, trq, self.t_b, self.j5),
                p_in,
                p_co,
                clutch_dissipation_rate(w, rel, trq, self.k) if self.engaged else 0.0,
                self.t_b * abs(th5d),
                w if slipping else 0.0,
                trq if slipping else 0.0,
                1.0 if slipping else 0.0,
            ]
        )

    def events(self) -> list:
        def clutch(t, y):
            _, _, _, _, w, rel, _ = self.signals(t, y)
            return w if self.engaged else rel

        clutch.terminal, clutch.direction = True, (-1.0 if self.engaged else 1.0)

        def brake(t, y):
            if self.brake == REGIME_STICK:
                return self.signals(t, y)[6] - self.t_b
            return y[3]

        brake.terminal = True
        brake.direction = {REGIME_STICK: 1.0, REGIME_SLIP_FORWARD: -1.0}.get(self.brake, 1.0)

        def rocker(t, y):
            return self.signals(t, y)[3]

        rocker.terminal, rocker.direction = True, (-1.0 if self.forward else 1.0)
        return [clutch, brake, rocker]

    def handle(self, which: int, t: float, y: np.ndarray) -> None:
        if which == 0:
            if self.engaged:
                self.engaged = False
            else:
                self.engaged = True
                _, _, th4, _, _, _, _ = self.signals(t, y)
                self.lock = th4 - y[2]
        elif which == 1:
            if self.brake == REGIME_STICK:
                trq = self.signals(t, y)[6]
                self.brake = slip_direction(trq * (1 + 1e-12) + 1e-300, self.t_b)
                if self.brake == REGIME_STICK:
                    self.brake = REGIME_SLIP_FORWARD if trq > 0 else REGIME_SLIP_BACKWARD
            else:
                y[3] = 0.0  # exact stop
                self.brake = slip_direction(self.signals(t, y)[6], self.t_b)
        else:
            pass
        self.forward = self._rocker_forward(t, y)

    def _rocker_forward(self, t: float, y: np.ndarray) -> bool:
        """Rocker direction after an event; at a reversal, the sign of its acceleration."""
        th4d = self.signals(t, y)[3]
        if abs(th4d) > 1e-9:
            return th4d > 0.0
        dt = 1e-7
        y2 = y.copy()
        y2[0] += y[1] * dt
        y2[1] += self.rhs(t, y)[1] * dt
        return self.signals(t + dt, y2)[3] > th4d

    def regime(self) -> int:
        return feed_regime(self.brake, self.engaged, self.forward)

    def observe(self, t: float, y: np.ndarray) -> tuple[float, float]:
        """(windup, clutch torque) for the recorder."""
        sig = self.signals(t, y)
        return sig[4], sig[6]

    def stored(self, t: float, y: np.ndarray) -> tuple[float, float, float]:
        _, _, _, th4d, w, _, _ = self.signals(t, y)
        return (
            coupler_energy(self.m, y[0], y[1], th4d),
            clutch_energy(w, self.k),
            0.5 * self.j5 * y[3] ** 2,
        )


_KERNEL = load_kernel("press_feed_kernel")
if _KERNEL is not None:  # its right-hand side and signals run compiled (components.kernels)
    _KERNEL.use_reference(N_DAMP, REGIME_STICK, REGIME_SLIP_FORWARD, REGIME_SLIP_BACKWARD)
    _KERNEL.use_python(signals=_Nonlinear.signals, rhs=_Nonlinear.rhs, observe=_Nonlinear.observe)
    _Nonlinear.signals = _KERNEL.nonlinear_signals  # type: ignore[method-assign]
    _Nonlinear.rhs = _KERNEL.nonlinear_rhs  # type: ignore[method-assign]
    _Nonlinear.observe = _KERNEL.nonlinear_observe  # type: ignore[method-assign]


# -- the linearized App. C/H model ----------------------------------------------------------
class _Linearized:
    """Thesis regimes imposed: K_l1 / K_l2 - T_b/2 / K_l3 / 0, events D.3, 62, E.3, F.3."""

    def __init__(
        self, force: DriveModel, event: DriveModel, t_b: float, j5: float, phi1_0: float
    ) -> None:
        self.m, self.me, self.t_b, self.j5, self.phi1_0 = force, event, t_b, j5, phi1_0
        self.k_l1, self.k_l2 = secant_stiffness(K_SP, t_b), tangent_stiffness(K_SP, t_b)
        self.k_l3 = self.k_l1
        self.r = WINDUP
        self.brake = REGIME_STICK
        self.engaged, self.forward = True, True

    def signals(self, t: float, y: np.ndarray) -> tuple:
        phi1 = self.phi1_0 + self.m.omega * t
        kin = self.m.kin(phi1)
        th4, th4d = rocker_motion(self.m, phi1, y[0], y[1], kin)
        w, wd = th4 - y[2], th4d - y[3]
        if self.r == WINDUP:
            spring = linearized_torque(w, 0.0, self.k_l1, 0.0, 0.0)
        elif self.r == FEED:
            spring = linearized_torque(w, 0.0, self.k_l2, -0.5 * self.t_b, 0.0)
        elif self.r == UNWIND:
            spring = linearized_torque(w, 0.0, self.k_l3, 0.0, 0.0)
        else:
            spring = 0.0
        # C_sp acts in the shaft equation and in D.3, not on the coupler (linearized (12), App. C).
        return phi1, kin, w, wd, spring, spring + C_SP * wd if self.r != OVERRUN else 0.0

    def exact(self, t: float, y: np.ndarray) -> tuple[float, float]:
        phi1 = self.phi1_0 + self.me.omega * t
        return rocker_motion(self.me, phi1, y[0], y[1])

    def rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        phi1, kin, w, wd, spring, total = self.signals(t, y)
        qdd, _, _, p_in, p_co = coupler_derivatives(self.m, phi1, y[0], y[1], spring, kin)
        feed = self.r == FEED
        return np.array(
            [
                y[1],
                qdd,
                y[3] if feed else 0.0,
                shaft_acceleration(REGIME_SLIP_FORWARD, total, self.t_b, self.j5) if feed else 0.0,
                p_in,
                p_co,
                0.0,
                self.t_b * abs(y[3]) if feed else 0.0,
                w if feed else 0.0,
                total if feed else 0.0,
                1.0 if feed else 0.0,
            ]
        )

    def events(self) -> list:
        def ev(t, y):
            if self.r == WINDUP:
                return self.signals(t, y)[5] - self.t_b  # (D.3)
            if self.r in (FEED, OVERRUN):
                return self.exact(t, y)[1]  # rocker reversal (62), (F.3)
            return self.exact(t, y)[0] - y[2]  # windup back to zero (E.3)

        ev.terminal = True
        ev.direction = {WINDUP: 1.0, FEED: -1.0, UNWIND: -1.0, OVERRUN: 1.0}[self.r]
        return [ev]

    def handle(self, which: int, t: float, y: np.ndarray) -> None:
        if self.r == WINDUP:
            self.r, self.brake = FEED, REGIME_SLIP_FORWARD
        elif self.r == FEED:
            y[3] = 0.0  # the thesis stops the shaft at the rocker reversal
            self.k_l3 = unwinding_stiffness(K_SP, self.exact(t, y)[0] - y[2])  # (C.10)
            self.r, self.brake, self.forward = UNWIND, REGIME_STICK, False
        elif self.r == UNWIND:
            self.r, self.engaged = OVERRUN, False
        else:
            y[2] = self.exact(t, y)[0]  # phi5 = phi4e,max at the start of Regime 1
            self.r, self.engaged, self.forward = WINDUP, True, True

    def regime(self) -> int:
        return self.r

    def observe(self, t: float, y: np.ndarray) -> tuple[float, float]:
        """(windup phi5 - phi4e with the exact rocker, spring torque) for the recorder."""
        if self.r == OVERRUN:
            return 0.0, 0.0
        return self.exact(t, y)[0] - y[2], self.signals(t, y)[4]

    def stored(self, t: float, y: np.ndarray) -> tuple[float, float, float]:
        th4d = self.signals(t, y)[3] + y[3]
        return coupler_energy(self.m, y[0], y[1], th4d), 0.0, 0.5 * self.j5 * y[3] ** 2


# -- set-up ---------------------------------------------------------------------------------
def _setup(o: FeedOptions):
    run = RUNS[o.run]
    rpm = o.rpm if o.rpm is not None else run.rpm
    t_b = o.brake_torque if o.brake_torque is not None else run.brake_torque
    if o.model == "linearized":
        j5 = o.j5 if o.j5 is not None else APP_H_J_O5
        lk = o.linkage or LINKAGE_APP_H
        phi4_max = rocker_extremes(ExactRSSR(lk, COUPLER_STANDARD.alpha))[0]
        c_e = APP_H_ZETA_CO * 2.0 * math.sqrt(APP_H_K_E * APP_H_M_E)  # (18.f)
        common = dict(f2_const=APP_H_F2, m_e=APP_H_M_E, k_e=APP_H_K_E, c_e=c_e, phi4_max=phi4_max)
        force = build_drive_model(rpm, lk, run.coupler, fourier_phi4=APP_H_FOURIER.phi4, **common)
        if o.event_kinematics == "exact":
            event = build_drive_model(rpm, lk, run.coupler, **common)
        else:
            event = force
        phi1_0 = math.radians(APP_H_PHI1_START_DEG)
        mach = _Linearized(force, event, t_b, j5, phi1_0)
        y0 = np.zeros(NY)
        y0[2] = phi4_max - math.radians(101.07)  # Table H-2: phi5 = 101.07 deg
        return mach, y0, rpm
    j5 = o.j5 if o.j5 is not None else J_O5_SHAFT + run.j_strip
    lk = o.linkage or LINKAGE_TABLE1
    coupler = o.bent_coupler or run.coupler
    f1 = APP_H_FOURIER.f1 if o.f1 is None else o.f1
    drive = build_drive_model(rpm, lk, coupler, f1=f1, rigid=o.coupler == "rigid")
    phi1_0 = rocker_extremes(ExactRSSR(lk, coupler.alpha))[1]
    k = K_SP
    if o.clutch == "hertz":
        # Part III: geometric stiffness; the sprags' share of A1 (119) rides on the inner race.
        # The A2 phi4'' coupling (120) is below 0.03 lbf.in here and is left out.
        k = two_point_hertz().k
        j5 += sum(sprag_inertia_terms()[:2])
    c_lin, c_nl = (C_SP, 0.0) if o.damping == "linear" else (0.0, C_NL)
    return _Nonlinear(drive, k, c_lin, c_nl, t_b, j5, phi1_0), np.zeros(NY), rpm


class _BudgetSpent(Exception):
    """The reference spent FeedOptions.max_evaluations (raised through solve_ivp)."""


def _integrate(mach, y0: np.ndarray, t_end: float, o: FeedOptions, grid: np.ndarray):
    """Integrate with exact event handling; returns samples, step points and the event log."""
    t, y = 0.0, y0.copy()
    log: list[tuple[float, int, int]] = []
    events: list[dict] = []
    ts, ys = [t], [y.copy()]
    gt, gy, gw = [], [], []
    recent: list[float] = []
    spent = [0]

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        spent[0] += 1
        if spent[0] > o.max_evaluations:
            raise _BudgetSpent
        return mach.rhs(t, y)

    while t < t_end:
        try:
            sol = solve_ivp(
                rhs,
                (t, t_end),
                y,
                method="DOP853",
                rtol=o.rtol,
                atol=o.atol,
                events=mach.events(),
                dense_output=True,
                max_step=o.max_step,
            )
        except _BudgetSpent:
            raise RuntimeError(
                f"press feed reference: {o.max_evaluations} evaluations spent by t = {t:.6g} s "
                "of its explicit integration (the model is too stiff for it: a very small "
                "inertia or a very stiff coupler or clutch)"
            ) from None
        if sol.status == -1:
            raise RuntimeError(f"press feed reference: {sol.message}")
        t_stop = sol.t[-1]
        mask = (grid >= t) & (grid < t_stop) if sol.status == 1 else (grid >= t) & (grid <= t_stop)
        if mask.any():
            gt.append(grid[mask])
            gy.append(sol.sol(grid[mask]).T)
            gw.append(_observed(mach, gt[-1], gy[-1]))
        ts.extend(sol.t[1:])
        ys.extend(sol.y[:, 1:].T)
        t, y = t_stop, sol.y[:, -1].copy()
        if sol.status == 1:
            which = next(i for i, te in enumerate(sol.t_events) if len(te))
            before = mach.regime()
            brake_before = getattr(mach, "brake", None)
            left = y.copy()
            w_left = mach.observe(t, y)[0]
            mach.handle(which, t, y)
            events.append(
                {
                    "t": t,
                    "regime": before,
                    "after": mach.regime(),
                    "y": left,
                    "y_right": y.copy(),
                    "windup": w_left,
                    # which subsystem switched (None: the thesis's one-event machine)
                    "source": getattr(mach, "EVENT_SOURCES", (None,) * (which + 1))[which],
                    "brake_before": brake_before,
                }
            )
            after = mach.regime()
            if after != before:
                log.append((t, before, after))
            ts.append(t)
            ys.append(y.copy())  # right value at the switching instant
            recent = [r for r in recent if r > t - 1e-6] + [t]
            if len(recent) > 50:
                raise RuntimeError(f"press feed reference: event chattering near t = {t}")
    series_t = np.concatenate(gt) if gt else np.empty(0)
    series_y = np.vstack(gy) if gy else np.empty((0, NY))
    series_w = np.vstack(gw) if gw else np.empty((0, 2))
    return series_t, series_y, series_w, np.array(ts), np.array(ys), log, events


def _observed(mach, times: np.ndarray, states: np.ndarray) -> list[tuple[float, float]]:
    """(windup, clutch torque) at each sample."""
    return [mach.observe(tk, yk) for tk, yk in zip(times, states, strict=True)]


if _KERNEL is not None:  # the samples of the nonlinear model taken in C
    _KERNEL.use_python(observed=_observed)
    _KERNEL.use_classes(nonlinear=_Nonlinear)
    _observed = _KERNEL.nonlinear_observed  # noqa: F811


def simulate_feed(o: FeedOptions = FeedOptions()) -> FeedResult:
    """Run the press feed for o.cycles crank revolutions from the rocker's extreme."""
    mach, y0, rpm = _setup(o)
    omega = rpm_to_rad_s(rpm)
    period = 2.0 * math.pi / omega
    t_end = o.cycles * period
    grid = np.linspace(0.0, t_end, o.cycles * o.samples_per_cycle + 1)
    e0 = sum(mach.stored(0.0, y0))
    st, sy, sw, tt, yy, log, events = _integrate(mach, y0, t_end, o, grid)
    res = FeedResult(regime_log=log, events=events, period=period, phi1_0=mach.phi1_0)

    # Signals on the sample grid (the machine's discrete state is replayed from the log).
    gauge, at_b = strain_factors(o.bent_coupler or RUNS[o.run].coupler)
    w_series, trq_series = sw[:, 0], sw[:, 1]
    res.series = {
        "t": st,
        "phi1": mach.phi1_0 + omega * st,
        "q": sy[:, 0],
        "theta5": sy[:, 2],
        "speed5": sy[:, 3],
        "windup": w_series,
        "torque": trq_series,
        "strain": gauge * sy[:, 0],
    }
    e_end = sum(mach.stored(tt[-1], yy[-1]))
    y_end = yy[-1]
    diss = y_end[5] + y_end[6] + y_end[7]
    res.energy = {
        "input_work": y_end[4],
        "stored_change": e_end - e0,
        "dissipated": diss,
        "coupler_damping": y_end[5],
        "clutch_damping": y_end[6],
        "brake": y_end[7],
        "residual": y_end[4] - (e_end - e0) - diss,
    }
    # Per-cycle quantities.
    for c in range(o.cycles):
        t0, t1 = c * period, (c + 1) * period
        sel = (st >= t0) & (st <= t1)
        y_a = _state_at(tt, yy, t0)
        y_b = _state_at(tt, yy, t1)
        slip_time = y_b[10] - y_a[10]
        cyc = {
            "feed_length": ROLLER_RADIUS * _feed_angle(events, t0, t1),
            "feed_angle": _feed_angle(events, t0, t1),
            "peak_windup": float(np.max(w_series[sel])),
            "peak_q": float(np.max(np.abs(sy[sel, 0]))),
            "peak_strain": float(gauge * np.max(np.abs(sy[sel, 0]))),
            "peak_strain_b": float(at_b * np.max(np.abs(sy[sel, 0]))),
            "feed_time": slip_time,
            "mean_windup_feed": (y_b[8] - y_a[8]) / slip_time if slip_time > 0 else math.nan,
            "mean_torque_feed": (y_b[9] - y_a[9]) / slip_time if slip_time > 0 else math.nan,
            "regimes": [
                (te, fr, to, math.degrees(mach.phi1_0 + omega * te))
                for te, fr, to in log
                if t0 <= te < t1
            ],
            "q_end": y_b[0],
            "qd_end": y_b[1],
        }
        res.cycles.append(cyc)
    return res


def _feed_angle(events: list[dict], t0: float, t1: float) -> float:
    """Shaft advance over the feeds that start in [t0, t1) (robust to the App. H reset)."""
    total, start = 0.0, None
    for ev in events:
        if ev["regime"] != FEED and ev["after"] == FEED and t0 <= ev["t"] < t1:
            start = ev["y_right"][2]
        elif ev["regime"] == FEED and ev["after"] != FEED and start is not None:
            total += ev["y"][2] - start
            start = None
    return total


def _state_at(tt: np.ndarray, yy: np.ndarray, t: float) -> np.ndarray:
    """State at t from the step points (last one at or before t, then linear in between)."""
    i = int(np.searchsorted(tt, t, side="right")) - 1
    i = min(max(i, 0), len(tt) - 1)
    if i + 1 < len(tt) and tt[i + 1] > tt[i] and t > tt[i]:
        a = (t - tt[i]) / (tt[i + 1] - tt[i])
        return yy[i] + a * (yy[i + 1] - yy[i])
    return yy[i]


# -- linear analysis (eq. 27) ---------------------------------------------------------------
def _regime2_linear(o: FeedOptions) -> tuple[_Linearized, np.ndarray]:
    """The linearized machine put in Regime 2 and the Jacobian of its right-hand side."""
    mach, y0, _ = _setup(o)
    if not isinstance(mach, _Linearized):
        raise ValueError("the Regime-2 linear analysis needs the linearized model")
    mach.r, mach.brake = FEED, REGIME_SLIP_FORWARD
    y = y0.copy()
    y[2] = 0.1
    jac = np.zeros((4, 4))
    for j in range(4):
        h = 1e-7 * max(1.0, abs(y[j]))
        yp, ym = y.copy(), y.copy()
        yp[j] += h
        ym[j] -= h
        jac[:, j] = (mach.rhs(0.3, yp)[:4] - mach.rhs(0.3, ym)[:4]) / (2 * h)
    return mach, jac


def regime2_modes(o: FeedOptions = FeedOptions(model="linearized")) -> dict:
    """System frequencies [Hz] and decay rates [1/s] of the Regime-2 linear model (27).

    The constant-coefficient matrix is the Jacobian of the same right-hand side the
    simulation integrates, taken in Regime 2 (forcing terms drop out of the Jacobian).
    """
    _, jac = _regime2_linear(o)
    lam = np.linalg.eigvals(jac)
    lam = sorted(lam[lam.imag > 0], key=lambda z: z.imag)
    return {
        "f1_hz": lam[0].imag / (2 * math.pi),
        "f2_hz": lam[1].imag / (2 * math.pi),
        "alpha1": -lam[0].real,
        "alpha2": -lam[1].real,
    }


def regime2_mean_windup(o: FeedOptions = FeedOptions(model="linearized")) -> float:
    """Constant term of the Regime-2 particular solution's windup, (42)-(43), (54).

    Mean forcing over one crank revolution (exact for the first-harmonic forcing), static
    solution of the Jacobian system, windup = mean(theta4) - mean(theta5).
    """
    mach, jac = _regime2_linear(o)
    period = 2.0 * math.pi / mach.m.omega
    ts = np.arange(64) * period / 64
    g = np.mean([mach.rhs(t, np.zeros(NY))[:4] for t in ts], axis=0)
    mean = np.linalg.solve(jac, -g)
    th4 = np.mean(
        [rocker_motion(mach.m, mach.phi1_0 + mach.m.omega * t, mean[0], 0.0)[0] for t in ts]
    )
    return float(th4 - mean[2])


def app_h_end_values(res: FeedResult) -> list[dict]:
    """Regime-end values of a linearized run in thesis units (phi1 absolute deg, inch)."""
    out = []
    omega = 2.0 * math.pi / res.period
    for ev in res.events:
        y = ev["y_right"] if ev["regime"] == OVERRUN else ev["y"]
        out.append(
            {
                "regime": ev["regime"],
                "phi1_deg": math.degrees(res.phi1_0 + omega * ev["t"]),
                "q_in": y[0] / IN,
                "dq_in": y[1] / omega / IN,
                "theta5": y[2],
                "windup": ev["windup"],
            }
        )
    return out


# -- Part II: sprag clutch decay --------------------------------------------------------------
def free_decay_ratios(
    brake_torque: float,
    x0_over_delta: float = 0.3,
    j: float = J_PART2,
    k: float = K_SP,
    c_nl: float = C_NL,
    peaks: int = 6,
    outer_speed: float = 7.5,
) -> list[float]:
    """Peak-to-trough decay ratios (K.2) of (95) with phi4'' = 0.

    The outer race turns at a constant speed and the shaft slips forward throughout, so the
    windup obeys J w'' + C_nl w^n w' + K w^{3/2} = T_b; it starts at (1 + x0/delta) delta.
    """
    delta = (brake_torque / k) ** (2.0 / 3.0)

    def rhs(t, y):  # y = theta4 - theta5 - lock (windup), theta5'
        trq = clutch_torque(y[0], outer_speed - y[1], k, 0.0, c_nl, N_DAMP)
        return [outer_speed - y[1], shaft_acceleration(REGIME_SLIP_FORWARD, trq, brake_torque, j)]

    f_loc = math.sqrt(1.5 * k * math.sqrt(delta) / j) / (2 * math.pi)
    t_end = (peaks + 2) / f_loc
    sol = solve_ivp(
        rhs,
        (0, t_end),
        [delta * (1 + x0_over_delta), outer_speed],
        method="DOP853",
        rtol=1e-11,
        atol=1e-14,
        dense_output=True,
        max_step=0.02 / f_loc,
    )
    ts = np.linspace(0, t_end, 20000)
    w = sol.sol(ts)[0]
    ext = _extrema(ts, w, sol)
    maxima = [v for v, kind in ext if kind > 0]
    minima = [v for v, kind in ext if kind < 0]
    ranges = [maxima[i] - minima[i] for i in range(min(len(maxima), len(minima)))]
    return [ranges[i + 1] / ranges[i] for i in range(len(ranges) - 1)][:peaks]


def _extrema(ts, w, sol) -> list[tuple[float, int]]:
    """Refined local extrema (value, +1 max / -1 min) of a dense solution, in time order."""
    out = []
    d = np.diff(w)
    for i in range(1, len(d)):
        if d[i - 1] > 0 >= d[i] or d[i - 1] < 0 <= d[i]:
            a, b = ts[i - 1], ts[i + 1]
            fine = np.linspace(a, b, 201)
            v = sol.sol(fine)[0]
            kind = 1 if d[i - 1] > 0 else -1
            out.append((float(v.max() if kind > 0 else v.min()), kind))
    return out


def simulate_decay_experiment(
    rpm: float, brake_torque: float, cycles: int = 1, j: float = J_PART2
) -> FeedResult:
    """Part II experiment (Part II §4): rigid Table 3 linkage, lumped clutch with (92) damping."""
    o = FeedOptions(
        run=1,
        rpm=rpm,
        brake_torque=brake_torque,
        j5=j,
        coupler="rigid",
        linkage=LINKAGE_TABLE3,
        cycles=cycles,
    )
    return simulate_feed(o)


def decay_ratios_from_series(res: FeedResult, cycle: int = 0) -> list[float]:
    """App. K peak-to-trough ratios of the windup during the first feed of a cycle."""
    s = res.series
    feed = [(te, to) for te, _, to, _ in res.cycles[cycle]["regimes"]]
    t_on = next(te for te, to in feed if to == FEED)
    t_off = next(te for te, to in feed if te > t_on)
    sel = (s["t"] > t_on) & (s["t"] < t_off)
    return peak_to_trough_ratios(s["windup"][sel])


def peak_to_trough_ratios(w: np.ndarray) -> list[float]:
    """Ratios of successive peak-to-trough ranges of a decaying oscillation (App. K)."""
    d = np.diff(w)
    ext = [
        (w[i], 1 if d[i - 1] > 0 else -1)
        for i in range(1, len(d))
        if (d[i - 1] > 0 >= d[i]) or (d[i - 1] < 0 <= d[i])
    ]
    maxima = [v for v, kind in ext if kind > 0]
    minima = [v for v, kind in ext if kind < 0]
    ranges = [maxima[i] - minima[i] for i in range(min(len(maxima), len(minima)))]
    return [ranges[i + 1] / ranges[i] for i in range(len(ranges) - 1)]
