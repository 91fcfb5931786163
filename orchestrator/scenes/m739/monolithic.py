"""Monolithic reference for the M739 S&A (Lowen & Tepper 1982): turns to arm and forces.

The verge regime machine (``components.verge_escapement.VergeCore``) runs with the *live*
train physics (``components.gear_train.TrainPhysics``) instead of a held affine response,
so train and verge form one ODE system, integrated by the same event-locating integrator with exact
location of every event (regime changes, impacts, mesh tooth changes and pitch points,
friction reversals, arming angle).  No equation is repeated here.

``run_m739`` returns turns to arm, arming time, force maxima (the report's F23MAX, F12MAX
in coupled motion, FF23MAX, FF12MAX in free motion, PNMAX), number of impacts, a regime
log [(t, from, to)] (codes of ``components.verge_escapement``: 0 free, 1 coupled on the
entrance face, 2 coupled on the exit face), every event with its cause, a log of the
train's direction of motion [(t, from, to)] (the ``components.gear_train`` regime codes: 0
stuck, 1 forward, 2 backward) and time series sampled every ``sample_dt`` (t, phi, phi_dot,
psi, psi_dot, regime, f12, f23, pn; SI).
It never raises: a run that cannot arm ends with ``armed = False`` and a reason (stall,
self-locking, verge disengaged, stop time reached, numerical failure).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from components.event_integration import IntegrationStepControl, advance
from components.gear_train import (
    INDEXING_AS_RUN,
    INDEXING_PHYSICAL,
    TRAIN_BACKWARD,
    TRAIN_FORWARD,
    TRAIN_STUCK,
    TrainPhysics,
)
from components.kernels import load_kernel
from components.m739_data import LBF, M739, M739Data, rpm_to_rad_s
from components.verge_escapement import (
    IND_CONTACT,
    IND_FACE_END,
    STATE_SCALES,
    VergeConstants,
    VergeCore,
)

#: Relative local error tolerance of the monolithic integration: turns to arm move by less
#: than 1e-7 relative when it is tightened tenfold (tests/components/test_m739_physics.py; with
#: restitution 0.3 and 0.6 too, tests/scenes/test_m739_restitution.py).  Not so at e_rest = 1:
#: elastic impacts make the motion chaotic (a 1e-11 s difference in the event times at 20 ms
#: grows to 1e-4 s at 90 ms) and turns to arm move by 8.7e-4 from 1e-9 to 1e-10.
REFERENCE_TOLERANCE = 1.0e-9
#: The integration runs in stretches of this length (a stall or fault ends at the next).
OUTPUT_CHUNK = 1.0e-3


@dataclass
class M739Result:
    """Outcome of one reference run (SI units)."""

    armed: bool
    reason: str
    t_arm: float | None
    turns: float | None
    f23_max: float
    f12_max: float
    ff23_max: float
    ff12_max: float
    pn_max: float
    impacts: int
    regime_log: list[tuple[float, int, int]]
    events: list[tuple[float, int, int, str]]
    t_end: float
    phi_end: float
    series: dict[str, np.ndarray] = field(default_factory=dict)
    train_log: list[tuple[float, int, int]] = field(default_factory=list)

    def summary(self) -> str:
        """One line, forces in lb (the report's unit)."""
        head = f"armed in {self.turns:.3f} turns" if self.armed else f"did not arm: {self.reason}"
        return (
            f"{head}; F23 {self.f23_max / LBF:.3f} F12 {self.f12_max / LBF:.3f} "
            f"FF23 {self.ff23_max / LBF:.3f} FF12 {self.ff12_max / LBF:.3f} "
            f"PN {self.pn_max / LBF:.3f} lb; {self.impacts} impacts"
        )


class VergeTrainMonolithic(VergeCore):
    """VergeCore with live train physics, recording maxima and the time series."""

    def __init__(self, *args: object, **kwargs: object) -> None:
        super().__init__(*args, **kwargs)  # type: ignore[arg-type]
        self.f23_max = self.f12_max = self.ff23_max = self.ff12_max = self.pn_max = 0.0
        # (face, phi_off, shift): the contact indicator of that face is raised by shift [m]
        # (see arm_contact); None: not raised.
        self.gap_shift: tuple[int, float, float] | None = None
        self.train_log: list[tuple[float, int, int]] = []

    def train_code(self) -> int:
        """The train's direction of motion as a regime code of ``components.gear_train``."""
        if self.train_stuck:
            return TRAIN_STUCK
        return TRAIN_FORWARD if self.train.direction > 0 else TRAIN_BACKWARD

    def indicators(self, y: list[float]) -> tuple[float, ...]:
        ind = super().indicators(y)
        shift = self.gap_shift
        if shift is None or self.coupled or shift[:2] != (self.face, self.phi_off):
            return ind
        return (*ind[:IND_CONTACT], ind[IND_CONTACT] + shift[2], *ind[IND_CONTACT + 1 :])

    def arm_contact(self, y: list[float]) -> None:
        """Arm the face's contact indicator after the tooth left it in free motion.

        A contact is located just past the face plane (sigma f < 0 by the location
        tolerance, about 1e-13 m), and a rebound (e > 0) or a separation leaves the tooth
        there.  An indicator that starts a step below zero is not armed, so a return to the
        face within the same step went unseen: at e = 0.3 one step ran 57 us from an exit
        rebound past the face end while the tooth struck the face again, and the reference
        lost that impact and every later one.  Raising the indicator by twice the
        penetration arms it; the next contact is then located 1e-13 m behind the plane.
        """
        self.gap_shift = None
        if self.coupled:
            return
        raw = super().indicators(y)[IND_CONTACT]
        if raw < 0.0:
            self.gap_shift = (self.face, self.phi_off, -2.0 * raw)

    def record(self, y: list[float]) -> None:
        """Forces at an accepted point (OUTP / OUTPF of the report)."""
        tr = self.train
        if self.coupled:
            acc, _, _, _, pn, _, _, _, _, den, *_ = self.coupled_terms(y)
            j = tr.response(y[0], y[1])[0]
            if den <= 0.0 or j <= 0.0:
                self.fault = "self-locking: effective inertia not positive"
                self.halted = True
                return
            f12, f23 = tr.forces(y[0], y[1], acc)
            self.f23_max = max(self.f23_max, f23)
            self.f12_max = max(self.f12_max, f12)
            self.pn_max = max(self.pn_max, pn)
        else:
            acc = self.free_terms(y)[0]
            f12, f23 = tr.forces(y[0], y[1], acc)
            self.ff23_max = max(self.ff23_max, f23)
            self.ff12_max = max(self.ff12_max, f12)

    def accept(self, y: list[float], t: float) -> None:
        self.record(y)

    def event(self, y: list[float], index: int, t: float) -> list[float]:
        before = self.train_code()
        y = super().event(y, index, t)
        after = self.train_code()
        if after != before:  # impact recoil, wheel reversal or stall
            self.train_log.append((self.t_base + t, before, after))
        if index in (IND_FACE_END, IND_CONTACT):  # the tooth may now leave a face plane
            self.arm_contact(y)
        if self.train_stuck:
            self.halted = True
        elif not self.halted:
            self.record(y)
        return y


_KERNEL = load_kernel("m739_kernel")
if _KERNEL is not None:  # its integration between events runs compiled (components.kernels)
    _KERNEL.use_classes(monolithic=VergeTrainMonolithic)


def _indexing_code(indexing: int | str) -> int:
    if isinstance(indexing, str):
        key = indexing.strip().lower().replace("_", "-")
        if key in ("physical", "phys"):
            return INDEXING_PHYSICAL
        if key in ("as-run", "asrun", "report"):
            return INDEXING_AS_RUN
        raise ValueError(f"unknown indexing {indexing!r}; use 'physical' or 'as-run'")
    return int(indexing)


def run_m739(
    mu: float = M739.mu,
    mu1: float = M739.mu1,
    rpm: float = M739.rpm,
    e_rest: float = M739.e_rest,
    t_stop: float = 0.2,
    indexing: int | str = "physical",
    tolerance: float = REFERENCE_TOLERANCE,
    sample_dt: float = 1.0e-5,
    data: M739Data = M739,
    h_max: float = math.inf,
) -> M739Result:
    """Simulate the M739 from rest on the entrance face until arming or t_stop.

    Arming is phi_T = PHICUTD (1485 deg of escape wheel); turns = spin [rev/s] * t_arm.
    ``h_max`` [s] caps the integration step (none by default: every event is located).
    """
    omega = rpm_to_rad_s(rpm)
    events: list[tuple[float, int, int, str]] = []

    def log(t: float, old: int, new: int, why: str) -> None:
        events.append((t, old, new, why))

    code = _indexing_code(indexing)
    train = TrainPhysics(data, mu=mu, omega=omega, indexing=code)
    k = VergeConstants(data, mu1, mu, omega, e_rest)
    core = VergeTrainMonolithic(k, train, data.phi_start, phi_stop=data.phi_cut, log=log)
    return simulate(core, data, events, t_stop, tolerance, sample_dt, h_max=h_max)


def simulate(
    core: VergeTrainMonolithic,
    data: M739Data,
    events: list[tuple[float, int, int, str]],
    t_stop: float,
    tolerance: float,
    sample_dt: float,
    max_events: int = 100_000,
    h_max: float = math.inf,
) -> M739Result:
    """Run a monolithic verge-and-train model from rest until it halts or t_stop; never raises.

    ``events`` is the list the core's log callback appends to.
    """
    y = core._sync_kinematics([0.0, 0.0, 0.0, 0.0, 0.0])
    if core.k.omega == 0.0:
        return _finish(core, y, 0.0, False, "no spin: no driving torque", events, {})
    core.s4 = core.s5 = 1  # V_S/T = 0 and psi_d = 0 at rest: +1 (the report's t = 0 row)
    core.record(y)  # the report's t = 0 printout uses these signs
    y = core.decide_direction(y, 0.0, 1)  # then all friction signs follow the motion

    names = ("t", "phi", "phi_dot", "psi", "psi_dot", "regime", "f12", "f23", "pn")
    cols: dict[str, list[float]] = {n: [] for n in names}

    def sample(t: float, y: list[float]) -> None:
        cols["t"].append(t)
        cols["phi"].append(y[0])
        cols["phi_dot"].append(y[1])
        body = y[2] + core.psic - data.psic
        cols["psi"].append(math.atan2(math.sin(body), math.cos(body)))
        cols["psi_dot"].append(y[3])
        cols["regime"].append(core.regime)
        if core.coupled:
            terms = core.coupled_terms(y)
            acc, pn = terms[0], terms[4]
        else:
            acc, pn = core.free_terms(y)[0], 0.0
        f12, f23 = core.train.forces(y[0], y[1], acc)
        cols["f12"].append(f12)
        cols["f23"].append(f23)
        cols["pn"].append(pn)

    control = IntegrationStepControl(tolerance, STATE_SCALES, h_max)
    h_next = 0.0
    t = 0.0
    sample(t, y)
    # Samples every sample_dt come from the solution between steps (dense output), so
    # they do not shorten the steps.
    count = [1]  # index of the next sample time, count * sample_dt

    def observe(t0: float, t1: float, state_at: Callable[[float], list[float]]) -> None:
        while count[0] * sample_dt - core.t_base <= t1:
            t_abs = count[0] * sample_dt
            sample(t_abs, state_at(t_abs - core.t_base))
            count[0] += 1

    if _KERNEL is not None:  # the same samples, taken inside the compiled loop
        columns = [cols[n] for n in names]
        observe = _KERNEL.Sampler(core, observe, columns, count, sample_dt, data.psic)

    try:
        while t < t_stop and not core.halted and not core.train_stuck:
            h = min(OUTPUT_CHUNK, t_stop - t)
            core.t_base = t
            done = advance(core, y, h, control, h_next, max_events=max_events, observe=observe)
            y, h_next = done.y, done.h_next
            if core.halted:
                t += done.t_last_event if done.t_last_event >= 0.0 else h
                break
            t += h
        if t > cols["t"][-1]:
            sample(t, y)
    except (ArithmeticError, ValueError, RuntimeError) as exc:
        return _finish(core, y, t, False, f"numerical failure: {exc}", events, cols)
    if core.halted and not core.train_stuck and not core.fault:
        return _finish(core, y, t, True, "armed", events, cols)
    reason = "stop time reached"
    if core.train_stuck:
        reason = f"stall: {core.stall_reason}"
    elif core.fault:
        reason = core.fault
    return _finish(core, y, t, False, reason, events, cols)


def _finish(
    core: VergeTrainMonolithic,
    y: list[float],
    t: float,
    armed: bool,
    reason: str,
    events: list[tuple[float, int, int, str]],
    cols: dict[str, list[float]],
) -> M739Result:
    regime_log = [(te, a, b) for te, a, b, _ in events if a != b]
    spin = abs(core.k.omega) / (2.0 * math.pi)
    return M739Result(
        armed=armed,
        reason=reason,
        t_arm=t if armed else None,
        turns=spin * t if armed else None,
        f23_max=core.f23_max,
        f12_max=core.f12_max,
        ff23_max=core.ff23_max,
        ff12_max=core.ff12_max,
        pn_max=core.pn_max,
        impacts=core.impacts,
        regime_log=regime_log,
        events=events,
        t_end=t,
        phi_end=y[0],
        series={n: np.asarray(v) for n, v in cols.items()},
        train_log=list(core.train_log),
    )
