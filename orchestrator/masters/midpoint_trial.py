"""The regime-aware master's held-input trials (``input_hold = "midpoint"`` or ``"start"``).

With ``"start"`` the inputs are held at their step-start values, and the estimate is how
much the exchanged signals change over the step, relative to each signal's running scale
(first order).  With ``"midpoint"`` the step is taken twice: once with the step-start
inputs (predictor), then again from the saved state with each held input at the mean of
its start and predicted end values (corrector, second order).  The estimate is the
difference the correction makes to the exchanged outputs, i.e. the effect of the held
inputs on the receivers, not the size of their change: a small change of a large torque
that nearly cancels the receiver's drive is seen as the large effect it has.  An FMU whose
held inputs the correction leaves bit for bit as they were (the train while the verge
flies free) is not stepped again: it is restored to its state just after the predictor's
step.  Black-box inputs stay at their step-start values (masters/held_inputs.py), and
their change counts where it is the larger error.

Where an FMU takes a held input's rate over the step (a Real input with the role rate_of
it, neither connected nor driven: the press feed's drive and brake take the clutch
torque's), the corrector also sets that rate, the slope from the start to the predicted
end value, so the input ramps through the step (first-order hold) rather than sitting at
its mean: the receiver then takes the first moment of its change too.  A black box that
declares it interpolates its inputs (FMI 2.0 ``canInterpolateInputs``, and no rate_of input
of its own) takes that slope by fmi2SetRealInputDerivatives, its input held at its start
value and ramped from there (the predictor's slope is 0); its inputs' change then is judged
by the corrector, not by the first-order change measure.

A predictor that crosses a switch is shortened to it; the step that lands on it is
corrected with the end values predicted just before the switch (those after it would
average a jump into the held inputs).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, NamedTuple

from orchestrator.master_settings import RegimeAwareSettings
from orchestrator.masters.held_inputs import HeldInputs
from orchestrator.masters.regime_aware import Estimate, RegimeAwareStats, RestartSteps, Trial
from orchestrator.masters.switches import Landing, StepStart, Switch, back_to_start, switch_time
from orchestrator.system import CoupledSystem


@dataclass(frozen=True)
class _Predictor:
    """A predictor step over [t, t+h] with every input held at its value at t."""

    t: float
    h: float
    states: list[Any] | None  # FMU states just after it (midpoint hold: for the corrector)


class _Correction(NamedTuple):
    """A corrector step: held inputs averaged between the start and ``predicted``."""

    predicted: list[list[float]]  # the end values it averaged toward (to retake the step)
    ratio: float  # the correction's size relative to the tolerance


class _Ramp(NamedTuple):
    """A held input the corrector ramps through the step."""

    instance: int
    index: int  # of the input in its instance's feed order
    setter: Any  # sets the instance's rate input


class MidpointTrials:
    """Predictor (and with the midpoint hold, corrector) trials; see the module doc."""

    growth_safety = 1.0  # the estimate's own safety factor suffices
    #: none: after a step of master.min_step onto an impact the held-start estimate may
    #: propose a shorter one (M739 under the start hold: 2e-15 s)
    next_step_floor = 0.0

    def __init__(
        self,
        system: CoupledSystem,
        settings: RegimeAwareSettings,
        stats: RegimeAwareStats,
        landing: Landing,
    ) -> None:
        self.system, self.settings, self.stats, self.landing = system, settings, stats, landing
        self.midpoint = settings.midpoint
        self.held = HeldInputs(system)
        self.ramps = self._ramps() if self.midpoint else []
        self.slopes = self.held.slopes() if self.midpoint else []
        self._ramps_set: dict[tuple[int, int], tuple[int, float]] = {}
        #: FMU states the predictors of this macro step kept, freed at its end
        self._kept: list[list[Any]] = []
        control = settings.control
        self.restart = RestartSteps(settings.first_step, control.zero_error_restart, True)
        self.sloped = {j for j, _, _ in self.slopes}
        held_boxes = [b for b in self.held.black_boxes if system.index[b] not in self.sloped]
        if held_boxes and self.midpoint:
            stats.warnings.append(
                f"FMU {', '.join(map(repr, held_boxes))} declares no sampled "
                "inputs, event indicators or regimes: its inputs are held at the step start "
                "(first order in the step, the step sized by their change) and its internal "
                "switches are found only through the error test"
            )

    # -- the scheme's part of a macro step ---------------------------------------------
    def begin(self, start: StepStart) -> None:
        pass

    def accepted(self, start: StepStart) -> None:
        pass

    def switched(self, accepted: Trial, do_steps: int) -> None:
        pass

    def end(self) -> None:
        for states in self._kept:
            self.system.free_state(states)
        self._kept.clear()

    def trial(self, h: float, start: StepStart) -> Trial:
        t, before = start.t, start.before
        do_steps = self.stats.do_steps
        slack = self.settings.control.event_time_slack
        left_row, correction = None, None
        predictor = self._predict(t, h)
        switch = switch_time(self.system, t, h, before, slack)
        if switch is not None and self.midpoint:
            switch, left_row, correction = self._correct_landing(h, switch, start, predictor)
        elif self.midpoint:
            predicted = [list(v) for v in self.system.values]
            correction = self._correct(t, h, start, predicted, predictor)
            switch = switch_time(self.system, t, h, before, slack)
        # Estimated where it is needed: a step that switched is judged only where it lands
        # on the switch, and only under the midpoint hold.
        needed = switch is None or (self.midpoint and self.landing.lands(t, h, switch))
        return Trial(
            h=h,
            h_asked=h,
            switch=switch,
            estimate=self._estimate(start, correction) if needed else None,
            do_steps=self.stats.do_steps - do_steps,
            predicted=None if correction is None else correction.predicted,
            left_row=left_row,
        )

    def left_row(self, accepted: Trial, switch_at: float, start: StepStart) -> list[float] | None:
        """Recorded values just before the switch the accepted step ends on (then the step
        is retaken to its end)."""
        t, h = start.t, accepted.h
        h_left = switch_at - t - 0.5 * self.settings.event_tolerance
        if h_left <= 0.0:
            return None
        if self.midpoint and accepted.left_row is not None:
            return accepted.left_row  # taken on the way to this step (_correct_landing)
        back_to_start(self.system, start)
        self.stats.rollbacks += 1
        self.stats.rejections += 1
        predictor = self._predict(t, h_left)
        if self.midpoint:
            predicted = [list(v) for v in self.system.values]
            self._correct(t, h_left, start, predicted, predictor)
        row = self.system.record_row(t + h_left)
        if self.midpoint:
            # The very inputs of the accepted step: the retake must cross the switch again.
            self._correct(t, h, start, accepted.predicted, None)
        else:
            back_to_start(self.system, start)
            self.stats.rollbacks += 1
            self.stats.rejections += 1
            self._predict(t, h)
        return row

    # -- predictor and corrector -------------------------------------------------------
    def _predict(self, t: float, h: float) -> _Predictor:
        """One Jacobi pass over [t, t+h] with every input held at its value at t."""
        system = self.system
        for i in range(len(system.instances)):
            system.feed(i)
        if self.ramps:
            self._set_ramps({})
        for _, indices, setter in self.slopes:
            setter([0.0] * len(indices))
        return _Predictor(t, h, self._step_all(t, h, keep=self.midpoint))

    def _step_all(
        self, t: float, h: float, which: list[int] | None = None, keep: bool = False
    ) -> list[Any] | None:
        """Step the instances (those in ``which``) over [t, t+h] and exchange; with
        ``keep``, their states just after the step are returned for the corrector."""
        system = self.system
        which = range(len(system.instances)) if which is None else which
        for i in which:
            system.step(i, t, h)
        states = None
        if keep:
            states = system.get_state()
            self._kept.append(states)
        system.read_all()
        system.exchange()  # indicators of one consistent instant
        self.stats.do_steps += len(which)
        return states

    def _correct(
        self,
        t: float,
        h: float,
        start: StepStart,
        predicted: list[list[float]],
        at: _Predictor | None,
        compare: list[list[float]] | None = None,
    ) -> _Correction:
        """Retake the step [t, t+h] from the step start with every held input at the mean
        of its start and ``predicted`` end values (``at``: the predictor step the FMUs are
        at the end of, if any).  The correction's ratio is its size (against the
        predictor's values at t+h, ``compare``, by default ``predicted``) relative to the
        tolerance: the predictor's error estimate."""
        system, before = self.system, start.before
        values0 = before.values
        feeds, retake = [], []
        at_predictor = at is not None and (at.t, at.h) == (t, h) and at.states is not None
        for i, inputs in enumerate(self.held.inputs):
            # At the step mean where averaged, else at the step-start value (one its FMU
            # ramps by an input derivative, too: from there).
            reals = [
                0.5 * (values0[s][k] + predicted[s][k])
                if averaged and not interpolated
                else values0[s][k]
                for (s, k), averaged, _, interpolated in inputs
            ]
            feeds.append(reals)
            # An FMU whose held inputs the correction leaves as they were would retake
            # the predictor's very step: when it is at its end, it stays (a doStep fewer).
            same = _same(reals, [values0[s][k] for (s, k), *_ in inputs])
            if same and i in self.sloped:  # and with no slope now
                same = all(predicted[s][k] == values0[s][k] for (s, k), *_ in inputs)
            if not (at_predictor and same):
                retake.append(i)
        # Back to the step start, those that stay to the end of their predictor step.
        kept = at.states if at is not None else None
        # Not read back: each is fed the values above, and read again after the step below.
        system.restore([start.state[i] if i in retake else kept[i] for i in range(len(feeds))])
        self.stats.rollbacks += 1
        for i in range(len(feeds)):
            system.feed(i, feeds[i], before.ints)
        if self.ramps:
            rates = {}
            for j, k, _ in self.ramps:
                s, n = self.held.inputs[j][k].source
                rates[(j, k)] = (predicted[s][n] - values0[s][n]) / h
            self._set_ramps(rates)
        for j, indices, setter in self.slopes:
            if j in system.held_back:  # stepped as Jacobi steps it: held (masters/held_back.py)
                continue
            sources = [self.held.inputs[j][k].source for k in indices]
            setter([(predicted[s][n] - values0[s][n]) / h for s, n in sources])
        self._step_all(t, h, retake)
        worst, tol = 0.0, self.settings.tolerance
        values = system.values
        compare = predicted if compare is None else compare
        out_scale = self.held.out_scale
        for i, k in self.held.outputs:
            a, b = compare[i][k], values[i][k]
            scale = out_scale[(i, k)] = max(out_scale[(i, k)], abs(values0[i][k]), abs(b))
            if scale > 0.0:
                worst = max(worst, abs(b - a) / (tol * scale))
        return _Correction(predicted, worst)

    def _correct_landing(
        self, h: float, switch: Switch, start: StepStart, predictor: _Predictor
    ) -> tuple[Switch | None, list[float] | None, _Correction | None]:
        """The predictor saw ``switch`` inside the step: if the step does not yet end on
        it, the caller shortens it (the switch is returned as is).  If it does, the step is
        corrected with the end values predicted just before the switch, and the corrected
        step's own switch is returned (None if the correction moved it past the step end),
        with the values recorded just before the switch and the correction."""
        t, before = start.t, start.before
        if not self.landing.lands(t, h, switch):
            return switch, None, None
        crossed = [list(v) for v in self.system.values]  # the predictor across the switch
        h_left = switch.at - t - 0.5 * self.settings.event_tolerance
        if h_left > 0.0:
            back_to_start(self.system, start)
            self.stats.rollbacks += 1
            predictor = self._predict(t, h_left)
            predicted = [list(v) for v in self.system.values]
            # Kept as the recorded values just before the switch: the accepted step's error
            # test bounds this predictor's error by the tolerance (retaking the step only to
            # record them cost trials at every switch).
            left_row = self.system.record_row(t + h_left)
        else:
            predicted = before.values
            left_row = None
        correction = self._correct(t, h, start, predicted, predictor, crossed)
        slack = self.settings.control.event_time_slack
        return switch_time(self.system, t, h, before, slack), left_row, correction

    # -- error estimate ----------------------------------------------------------------
    def _estimate(self, start: StepStart, correction: _Correction | None) -> Estimate:
        """Error estimate of the step just taken, relative to the tolerance (<= 1 accepts):
        the corrector's (second order), or the change of the signals held at the step start
        (first order) where that is larger."""
        held, tol = self.held, self.settings.tolerance
        if not self.midpoint:
            return Estimate(held.change_ratio(start.before, held.signals, tol), True)
        # the black-box signals held through the step (not ramped by a slope)
        unannotated = held.change_ratio(start.before, held.unsloped, tol) if held.unsloped else 0.0
        return Estimate(max(correction.ratio, unannotated), unannotated > correction.ratio)

    # -- ramped inputs -----------------------------------------------------------------
    def _ramps(self) -> list[_Ramp]:
        """The averaged inputs whose receiver takes their rate."""
        ramps = []
        for j, inputs in enumerate(self.held.inputs):
            for k, held in enumerate(inputs):
                setter = self._rate_input(j, held.name) if held.averaged else None
                if setter is not None:
                    ramps.append(_Ramp(j, k, setter))
        return ramps

    def _rate_input(self, j: int, name: str) -> Any:
        """A setter of instance j's input with the role rate_of ``name``, None where it takes
        no rate (no such Real input, or one a connection or a scene signal drives)."""
        system = self.system
        rate = system.models[j].with_role("rate_of", name)
        if rate is None or rate.is_integer:
            return None
        target = (system.names[j], rate.name)
        if target in system.signals.driven or any(
            tuple(c.target) == target for c in system.connections
        ):
            return None
        inst = system.instances[j]
        return inst.setter(inst.refs([rate.name]))

    def _set_ramps(self, rates: dict[tuple[int, int], float]) -> None:
        """Set each ramped input's rate (0 where ``rates`` has none: held), unless the FMU
        holds that value already (a restored state brings the rate it was saved with)."""
        instances = self.system.instances
        for j, k, setter in self.ramps:
            value = rates.get((j, k), 0.0)
            key = (instances[j].restores, value)
            if self._ramps_set.get((j, k)) != key:
                setter([value])
                self._ramps_set[(j, k)] = key


def _same(a: list[float], b: list[float]) -> bool:
    """Bit for bit the same values (0.0 and -0.0 differ)."""
    return all(
        x == y and math.copysign(1.0, x) == math.copysign(1.0, y) for x, y in zip(a, b, strict=True)
    )
