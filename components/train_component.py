"""What every spin-driven train FMU shares: the held escapement load and the motion at zero
wheel speed (start, reversal, stick), taking impacts, stepping with event location, and
cheap state snapshots.
"""

from __future__ import annotations

from typing import Any

from .augmented_model import AugmentedModel
from .base import Component, SnapshotPlan
from .early_return import UntilFirstEvent, reached
from .event_integration import STEP_BUDGET_VARIABLE, advance, integration_step_control
from .kernels import load_kernel

#: Magnitudes below which the integration controls the state [phi, phi_d, W] absolutely:
#: rad, rad/s, J.
STATE_SCALES = (1.0, 10.0, 1.0e-3)
#: Difference steps of the response's slopes: rad, and relative to the speed
#: (at least 1 rad/s).
SLOPE_STEP_ANGLE = 1.0e-6
SLOPE_STEP_SPEED = 1.0e-6


class TrainLoadModel:
    """A train model's held escapement load and its motion at zero wheel speed.

    The load is affine in the wheel acceleration, t_esc - j_esc phi_dd (j_esc = 0: a plain
    held torque), so J_ref phi_dd = T_ref + c (t_esc - j_esc phi_dd).  Reversal, start and
    stick at zero speed need ``p`` (the physics: response, direction, set_direction,
    update_i1r) and ``stuck``.
    """

    def __init__(self, phys: Any) -> None:
        self.p = phys
        self.t_esc = 0.0  # the held load; set from the inputs by TrainComponent._take_loads
        self.j_esc = 0.0
        self.stuck = False
        self.t_first_event = -1.0  # first internal event (reversal, stick) in the step
        #: largest mesh forces at accepted points so far: (F12, F23) loaded, (FF12, FF23)
        #: unloaded (a tuple: a snapshot's shallow copy restores it)
        self.peaks = (0.0, 0.0, 0.0, 0.0)

    def accel(self, phi: float, phi_dot: float) -> float:
        j, t, c = self.p.response(phi, phi_dot)
        return (t + c * self.t_esc) / (j + c * self.j_esc)

    def accept(self, y: list[float], t: float) -> None:
        """An accepted internal point: the mesh-force peaks between communication points,
        which the outputs at step ends miss when steps are long."""
        if self.stuck:
            return
        f12, f23 = self.p.forces(y[0], y[1], self.accel(y[0], y[1]))
        p12, p23, q12, q23 = self.peaks
        if self.t_esc != 0.0 or self.j_esc != 0.0:  # loaded: the escapement in contact
            if f12 > p12 or f23 > p23:
                self.peaks = (max(p12, f12), max(p23, f23), q12, q23)
        elif f12 > q12 or f23 > q23:
            self.peaks = (p12, p23, max(q12, f12), max(q23, f23))

    def load(self, phi_ddot: float) -> float:
        """The escapement moment on the wheel at this acceleration."""
        return self.t_esc - self.j_esc * phi_ddot

    def reverse_or_stick(self, y: list[float]) -> list[float]:
        """Speed crossed zero: reverse if the drive beats friction backwards, else stick."""
        p = self.p
        phi = y[0]
        old = p.direction
        for direction in (-old, old):
            p.set_direction(direction, phi)
            if direction * self.accel(phi, 0.0) > 0.0:
                self._restart_branch(phi)
                return [phi, 0.0, y[2]]
        self.stuck = True
        return [phi, 0.0, y[2]]

    def try_unstick(self, phi: float) -> None:
        """At rest: start in whichever direction the net torque beats static friction."""
        p = self.p
        held = p.direction
        for direction in (held, -held):
            p.set_direction(direction, phi)
            if direction * self.accel(phi, 0.0) > 0.0:
                self.stuck = False
                self._restart_branch(phi)
                return
        # Stuck: keep the direction it had, so the outputs (and a master's exchange at
        # this instant) do not flip between the two friction pieces from call to call.
        p.set_direction(held, phi)
        self.stuck = True

    def _restart_branch(self, phi: float) -> None:
        # The acceleration-dependent branches (I1R, normal-force signs) lag one accepted
        # step; at a start from rest they take the new motion's acceleration at once, so
        # the first step after it does not depend on its length.
        self.p.update_i1r(0.0, self.accel(phi, 0.0))


class RampedLoad(AugmentedModel):
    """A train model whose held escapement torque ramps over the step, the torque a fourth
    state moving at ``rate``: the train takes an impulse and its first moment."""

    def __init__(self, model: TrainLoadModel, rate: float) -> None:
        super().__init__(model, 3)
        self.rate = rate

    def enter(self, y: list[float]) -> None:
        self.model.t_esc = y[3]

    def extra_deriv(self, y: list[float], own: list[float]) -> list[float]:
        return [self.rate]


class TrainComponent(Component):
    """What every spin-driven train FMU shares: taking impacts and the held escapement load,
    stepping the 1-DOF model with event location, and cheap state snapshots.

    A subclass names its physics and model classes and provides ``initialize`` and
    ``_outputs``; ``self._phys``, ``self._model`` and ``self._y`` hold the state.
    """

    STEP_TAKES_INPUTS = True  # step() starts with _apply_inputs and ends with _outputs

    def __init_subclass__(cls, **kwargs: object) -> None:
        super().__init_subclass__(**kwargs)
        # Every train integrates with event_integration.advance: each bounds the work of
        # one doStep by the same parameter, declared here once for all of them.
        if not any(v.name == STEP_BUDGET_VARIABLE.name for v in cls.VARIABLES):
            cls.VARIABLES = (*cls.VARIABLES, STEP_BUDGET_VARIABLE)

    _PHYSICS: type
    _MODEL: type
    # The snapshot copies the mutable mode and state; the constants (and the memo of
    # mode-only coefficients) are immutable in use and shared, which keeps it cheap.
    SNAPSHOT = SnapshotPlan(lists=("_y",), objects={"_phys": {}, "_model": {"p": "_phys"}})

    def _take_loads(self) -> None:
        """Copy the held inputs the model integrates with: the escapement as an affine
        load when its inertia at the wheel is given, else the plain torque."""
        m = self._model
        m.j_esc = self.J_esc
        m.t_esc = self.T_esc_static if self.J_esc != 0.0 else self.T_esc

    def _send_response(self, phi: float, phi_dot: float) -> None:
        """The affine response and the impact inertia at the wheel state, with their slopes
        in that state in the mode in force (differences: smooth within a mode).
        The slopes of the last state and mode are kept: the outputs after a step and
        those after the exchange that follows ask at the same point."""
        p = self._phys
        self.J_ref, self.T_ref, self.c_load = p.response(phi, phi_dot)
        self.J_stot = p.impact_inertia(phi)
        key = (phi, phi_dot, p.mode_key())
        if key != self._slopes_at:
            self._slopes, self._slopes_at = self._slopes_of(phi, phi_dot), key
        self.J_ref_phi, self.T_ref_phi, self.T_ref_phi_dot, self.J_stot_phi = self._slopes

    def _slopes_of(self, phi: float, phi_dot: float) -> tuple[float, float, float, float]:
        """(J_ref, T_ref in phi; T_ref in phi_dot; J_stot in phi): forward differences from
        the state's response and impact inertia, just sent (a central difference costs two
        evaluations more per output; the one-sided truncation, dp/2 times the second
        derivative, is about 1e-5 of the slope on the clock train).  The physics remembers
        its last point (the friction branches read it): after each neighbour it remembers
        the state's again, so the neighbour in the speed shares the state's kinematics and
        the step ends at the state."""
        p = self._phys
        dp = SLOPE_STEP_ANGLE
        dw = SLOPE_STEP_SPEED * max(1.0, abs(phi_dot))
        j_0, t_0, i_0 = self.J_ref, self.T_ref, self.J_stot
        at_state = p.memos()
        (j_hi, t_hi, _), i_hi = p.response(phi + dp, phi_dot), p.impact_inertia(phi + dp)
        p.restore_memos(at_state)
        t_fast = p.response(phi, phi_dot + dw)[1]
        p.restore_memos(at_state)
        return (
            (j_hi - j_0) / dp,
            (t_hi - t_0) / dp,
            (t_fast - t_0) / dw,
            (i_hi - i_0) / dp,
        )

    def _start_integration(self) -> None:
        """The integration accuracy from the parameters (initialize calls it first)."""
        self._control = integration_step_control(self, STATE_SCALES)
        # The ramped torque is integrated exactly: its scale only keeps the norm defined.
        self._ramp_control = integration_step_control(self, (*STATE_SCALES, 1.0))
        self._h_next = 0.0
        self._slopes_at: tuple = ()  # the state and mode of the slopes kept (_send_response)
        self._slopes = (0.0, 0.0, 0.0, 0.0)

    def _apply_inputs(self) -> None:
        """Take a new impact speed (once per impact_count change) and the held load.

        Idempotent, so it may run in update_outputs and again at the step start.
        """
        self._take_loads()
        m, y = self._model, self._y
        if int(self.impact_count) != self._seen_impacts:
            self._seen_impacts = int(self.impact_count)
            y = self._y = [y[0], self.phi_dot_impact, y[2]]
            if y[1] != 0.0:
                m.p.set_direction(1 if y[1] > 0.0 else -1, y[0])
                m.stuck = False
        if y[1] == 0.0:
            m.try_unstick(y[0])
        elif m.p.direction * y[1] < 0.0:
            m.p.set_direction(1 if y[1] > 0.0 else -1, y[0])

    def update_outputs(self) -> None:
        # Direct feedthrough: F12, F23, phi_ddot depend on T_esc; an impact sets phi_dot.
        self._apply_inputs()
        self._outputs()
        self._peak_outputs()

    def _peak_outputs(self) -> None:
        self.F12_peak, self.F23_peak, self.FF12_peak, self.FF23_peak = self._model.peaks

    def step(self, t: float, h: float) -> None:
        self._apply_inputs()
        m = self._model
        m.t_first_event = -1.0
        self.t_reached = t + h
        if m.stuck and self._y[1] == 0.0:
            # Held at rest by static friction under held inputs: nothing moves in this step.
            self._outputs()
            self._peak_outputs()
            return
        # Early return (components.early_return): end at the first event (a mesh piece, a
        # branch, a reversal: each jumps the response the escapement takes).
        rate = self.T_esc_rate if self.J_esc == 0.0 else 0.0
        if rate == 0.0:
            model = UntilFirstEvent(m, t) if self.early_return else m
            done = advance(model, self._y, h, self._control, self._h_next)
            y = done.y
        else:
            # The step's torque from its mean and rate: T_esc(s) = mean + rate (s - h/2).
            ramped = RampedLoad(m, rate)
            model = UntilFirstEvent(ramped, t) if self.early_return else ramped
            y0 = [*self._y, m.t_esc - 0.5 * rate * h]
            done = advance(model, y0, h, self._ramp_control, self._h_next)
            y = done.y[:3]
            m.t_esc = self.T_esc  # the outputs at the step's end: with the inputs held
        self.t_reached = reached(t, h, model)
        self._y, self._h_next = y, done.h_next
        if m.t_first_event >= 0.0:
            self.t_event = t + m.t_first_event
        self._outputs()
        self._peak_outputs()


_KERNEL = load_kernel("m739_kernel")
if _KERNEL is not None:  # the loop between events in C for the M739 train's model
    _KERNEL.use_classes(ramped_load=RampedLoad, until_first_event=UntilFirstEvent)
