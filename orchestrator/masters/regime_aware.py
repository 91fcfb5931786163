"""The regime-aware master: steps that land on every regime switch, sized by an error test.

Each macro step starts from a saved state of every FMU (fmi2GetFMUstate), so any trial can
be rolled back.  A trial step is accepted when

* no FMU changed regime, fired an internal event or crossed an event indicator (outputs
  named ``ind_*``) inside it — otherwise the switching instant is located (from the FMU's
  reported ``t_event`` when it has one, else by secant/bisection on the indicator) and the
  step is retaken to land on it within ``event_tolerance`` (on an instant an FMU reported,
  within one instant, ``settle_window`` event tolerances: a retaken step moves the FMU's
  located instant by its own rounding and held inputs); and
* the coupling error estimate is within ``tolerance``.  With ``input_hold = "start"`` the
  inputs are held at their step-start values, and the estimate is how much the exchanged
  signals change over the step, relative to each signal's running scale (first order).
  With ``input_hold = "midpoint"`` the step is taken twice: once with the step-start
  inputs (predictor), then again from the saved state with each held input at the mean of
  its start and predicted end values (corrector, second order).  The estimate is the
  difference the correction makes to the exchanged outputs, i.e. the effect of the held
  inputs on the receivers, not the size of their change: a small change of a large
  torque that nearly cancels the receiver's drive is seen as the large effect it has.
  An FMU whose held inputs the correction leaves bit for bit as they were (the train while
  the verge flies free) is not stepped again: it is restored to its state just after the
  predictor's step.
  Sampled inputs (a state taken at the step start) are never averaged.  Where an FMU
  takes a held input's rate over the step (a Real input named after it with ``_rate``,
  neither connected nor driven: the press feed's drive and brake take the clutch torque's),
  the corrector also sets that rate, the slope from the start to the predicted end value,
  so the input ramps through the step (first-order hold) rather than sitting at its mean:
  the receiver then takes the first moment of its change too (press feed Run 1: trajectory
  error 5.7e-4 against 7.5e-4 at 2e-4, 8.2e-4 against 1.1e-3 at 3e-4, in as many doSteps).

After a switch the master iterates the exchange at that instant to a fixed point (so an
impact's momentum exchange reaches the other FMU before anything moves), records the left
and right values, logs the switch, and restarts with a short step (``master.first_step``;
into regimes where every accepted step so far had zero coupling error, a fraction of the
step proposed there last).  A guard stops runs that keep switching at one instant (chattering /
Zeno) with a diagnosis.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, NamedTuple

from orchestrator.errors import RunError
from orchestrator.master_settings import RegimeAwareSettings
from orchestrator.masters.macro_step import MacroStep
from orchestrator.observers import regime_changes
from orchestrator.recorder import StepStats
from orchestrator.system import CoupledSystem

#: Suffix of the Real input by which an FMU takes a held input's rate over a step.
RATE_SUFFIX = "_rate"


@dataclass
class _Readings:
    """Everything read from the FMUs at one instant."""

    values: list[list[float]]
    ints: list[list[int]]
    regimes: list[int | None]
    indicators: list[list[float]]
    stop: float | None  # the scene's stop indicator (> 0 until the condition is met)


# What one stage of a macro step hands to the next: its trials, their corrections, the
# switch they found and the error estimate that accepts one.


@dataclass(frozen=True)
class _Predictor:
    """A predictor step over [t, t+h] with every input held at its value at t."""

    t: float
    h: float
    states: list[Any] | None  # FMU states just after it (midpoint hold: for the corrector)


@dataclass(frozen=True)
class _Correction:
    """A corrector step: held inputs averaged between the start and ``predicted``."""

    predicted: list[list[float]]  # the end values it averaged toward (to retake the step)
    ratio: float  # the correction's size relative to the tolerance


class _Switch(NamedTuple):
    """The earliest switch inside a trial step."""

    at: float | None  # its instant, None if nothing switched
    located: bool  # an instant an FMU reported (not an estimate from an indicator)


class _Estimate(NamedTuple):
    """Error estimate of a trial step relative to the tolerance (<= 1 accepts)."""

    ratio: float
    first_order: bool  # its order in h (sets how far the step shrinks or grows)


@dataclass(frozen=True)
class _Accepted:
    """The trial a macro step keeps."""

    h: float
    switch_at: float | None  # the switch it ends on, if any
    correction: _Correction | None  # its corrector step (midpoint hold)
    left_row: list[float] | None  # values just before the switch, taken on the way
    estimate: _Estimate | None  # its error estimate (None: not needed to accept it)


class RegimeAwareMaster:
    def __init__(
        self,
        system: CoupledSystem,
        settings: RegimeAwareSettings,
        stats: StepStats,
    ):
        self.system, self.stats = system, stats
        self.cfg, self.control = settings, settings.control
        self.names = system.names
        self.h = settings.first_step  # the step the next macro step tries first
        self.same_instant = 0  # switches in a row within one instant (chattering guard)
        self.last_change: tuple[str, str, str] | None = None  # (FMU, from, to), last seen
        # Exchanged Real signals held over a step: (instance, slot) of their sources.  Inputs
        # that are sampled as a state at the step start carry no hold error of their own.
        # Midpoint hold: per instance, its Real inputs in feed order as (source, averaged?);
        # the held ones are averaged over the step.  An FMU that does not say which of its
        # inputs are sampled (one from another tool) is a black box: averaging a sampled
        # input would be wrong at first order, unseen by the error test, so its inputs stay
        # at their step-start values and their change over the step is the error (first
        # order, as with input_hold = "start").
        held, unannotated = set(), set()
        self.held_inputs: list[list[tuple[tuple[int, int], bool]]] = [[] for _ in self.names]
        #: (instance, index of the held input in its feed order, setter of its rate input):
        #: the midpoint corrector's ramped inputs
        self.ramps: list[tuple[int, int, Any]] = []
        self._ramps_set: dict[tuple[int, int], tuple[int, float]] = {}
        for c, src in zip(system.connections, system.connection_sources, strict=True):
            if src is None:
                continue
            j = system.index[c.target[0]]
            model = system.models[j]
            sampled = c.target[1] in model.sampled
            if not model.annotated:
                unannotated.add(src)
            elif not sampled:
                held.add(src)
            averaged = model.annotated and not sampled
            if averaged and settings.midpoint:
                rate = self._rate_input(j, c.target[1])
                if rate is not None:
                    self.ramps.append((j, len(self.held_inputs[j]), rate))
            self.held_inputs[j].append((src, averaged))
        self.signals = sorted(held | unannotated)  # start hold: every held signal's change
        self.unannotated = sorted(unannotated)
        # Running scales of the relative error measures, from each signal's declared nominal
        # (FMI 2.0): a speed starting from rest is not held to its first millionths.
        self.scale = {s: system.nominal(*s) for s in self.signals}
        black_boxes = sorted(
            {c.target[0] for c in system.connections}
            & {n for n, model in zip(self.names, system.models, strict=True) if not model.annotated}
        )
        if black_boxes and self.cfg.midpoint:
            stats.extra.setdefault("warnings", []).append(
                f"FMU {', '.join(map(repr, black_boxes))} declares no sampled inputs, event "
                "indicators or regimes: its inputs are held at the step start (first order in "
                "the step, the step sized by their change) and its internal switches are found "
                "only through the error test"
            )
        # Every Real connection source: its predictor-corrector difference is the error.
        self.outputs = sorted({s for s in system.connection_sources if s is not None})
        self.out_scale = {s: system.nominal(*s) for s in self.outputs}
        #: FMU states the predictors of this macro step kept, freed at its end
        self.kept_states: list[list[Any]] = []
        #: switches this close are one instant (chattering guard, landing on a located switch)
        self.instant = settings.control.settle_window * settings.event_tolerance
        #: per combination of regimes in which every accepted step had zero coupling error:
        #: the largest step the controller proposed there (the restart after a switch)
        self.zero_error_step: dict[tuple[int | None, ...], float] = {}

    # -- helpers ----------------------------------------------------------------------
    def _rate_input(self, j: int, name: str) -> Any:
        """A setter of instance j's ``<name>_rate`` input, None where it takes no rate (no
        such Real input, or one a connection or a scene signal drives)."""
        system = self.system
        rate = system.models[j].variables.get(name + RATE_SUFFIX)
        if rate is None or rate.causality != "input" or rate.is_integer:
            return None
        target = (self.names[j], rate.name)
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

    def readings(self) -> _Readings:
        s = self.system
        return _Readings(
            [list(v) for v in s.values],
            [list(v) for v in s.ints],
            s.regimes(),
            s.indicators(),
            s.stop_indicator(),
        )

    def trial(self, t: float, h: float) -> _Predictor:
        """One Jacobi pass over [t, t+h] with every input held at its value at t."""
        system = self.system
        for i in range(len(system.instances)):
            system.feed(i)
        if self.ramps:
            self._set_ramps({})
        return _Predictor(t, h, self._step_all(t, h, keep=self.cfg.midpoint))

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
            self.kept_states.append(states)
        system.read_all()
        self.system.exchange()  # indicators of one consistent instant
        self.stats.do_steps += len(which)
        return states

    def free_kept_states(self) -> None:
        for states in self.kept_states:
            self.system.free_state(states)
        self.kept_states.clear()

    def corrected_trial(
        self,
        t: float,
        h: float,
        before: _Readings,
        state: list[Any],
        predicted: list[list[float]],
        at: _Predictor | None,
        compare: list[list[float]] | None = None,
    ) -> _Correction:
        """Retake the step [t, t+h] from the saved state with every held input at the mean
        of its start and ``predicted`` end values (``at``: the predictor step the FMUs are at
        the end of, if any).  The correction's ratio is its size (against the predictor's
        values at t+h, ``compare``, by default ``predicted``) relative to the tolerance:
        the predictor's error estimate."""
        system = self.system
        start = before.values
        feeds, retake = [], []
        at_predictor = at is not None and (at.t, at.h) == (t, h) and at.states is not None
        for i, inputs in enumerate(self.held_inputs):
            reals = [
                0.5 * (start[s][k] + predicted[s][k]) if averaged else start[s][k]
                for (s, k), averaged in inputs
            ]
            feeds.append(reals)
            # An FMU whose held inputs the correction leaves as they were would retake
            # the predictor's very step: when it is at its end, it stays (a doStep fewer).
            if not (at_predictor and _same(reals, [start[s][k] for (s, k), _ in inputs])):
                retake.append(i)
        # Back to the step start, those that stay to the end of their predictor step.
        kept = at.states if at is not None else None
        # Not read back: each is fed the values above, and read again after the step below.
        system.restore([state[i] if i in retake else kept[i] for i in range(len(feeds))])
        self.stats.rollbacks += 1
        for i in range(len(feeds)):
            system.feed(i, feeds[i], before.ints)
        if self.ramps:
            rates = {}
            for j, k, _ in self.ramps:
                s, n = self.held_inputs[j][k][0]
                rates[(j, k)] = (predicted[s][n] - start[s][n]) / h
            self._set_ramps(rates)
        self._step_all(t, h, retake)
        worst, tol = 0.0, self.cfg.tolerance
        values = system.values
        compare = predicted if compare is None else compare
        for i, k in self.outputs:
            a, b = compare[i][k], values[i][k]
            scale = self.out_scale[(i, k)] = max(self.out_scale[(i, k)], abs(start[i][k]), abs(b))
            if scale > 0.0:
                worst = max(worst, abs(b - a) / (tol * scale))
        return _Correction(predicted, worst)

    def switch_time(self, t: float, h: float, before: _Readings) -> _Switch:
        """Earliest switching instant inside (t, t+h], or None if nothing switched.

        An FMU that reports its internal event time gives it exactly; an indicator that
        changed sign (the scene's stop condition among them) gives a secant estimate.
        """
        system = self.system
        after_regimes, after_ind = system.regimes(), system.indicators()
        # An input signal's jump where the step ends is a known, located switch.
        best = reported = t + h if system.signals.jump_at(t + h) else None
        g1 = system.stop_indicator()
        if g1 is not None and g1 <= 0.0 < before.stop:
            best = t + h * before.stop / (before.stop - g1)
        for i, watch in enumerate(system.watches):
            fired = after_regimes[i] != before.regimes[i]
            if watch.t_event is not None:
                te = system.values[i][watch.t_event]
                if t < te <= t + h * (1 + self.control.event_time_slack):
                    best = te if best is None else min(best, te)
                    reported = te if reported is None else min(reported, te)
                    continue
                if fired and te == t:
                    # Switched at the step start, on inputs that crossed by t: land on it
                    # with a step of event_tolerance / 2, so that the exchange at the switch
                    # (an impact's momentum) reaches the others before they move on.
                    best = t if best is None else min(best, t)
                    continue
            for g0, g1 in zip(before.indicators[i], after_ind[i], strict=True):
                # A crossing leaves one strict sign; an indicator starting at zero (the
                # switch it marks has just happened) does not switch again by leaving it.
                if g0 > 0.0 >= g1 or g0 < 0.0 <= g1:
                    te = t + h * g0 / (g0 - g1)
                    best = te if best is None else min(best, te)
            if fired and best is None:
                best = t + 0.5 * h
        return _Switch(best, best is not None and best == reported)

    def step_ratio(self, before: _Readings, correction: _Correction | None) -> _Estimate:
        """Error estimate of the step just taken, relative to the tolerance (<= 1 accepts):
        the corrector's (second order), or the change of the signals held at the step start
        (first order) where that is larger."""
        if not self.cfg.midpoint:
            return _Estimate(self.error_ratio(before, self.signals), True)
        unannotated = self.error_ratio(before, self.unannotated) if self.unannotated else 0.0
        return _Estimate(max(correction.ratio, unannotated), unannotated > correction.ratio)

    def error_ratio(self, before: _Readings, signals: list[tuple[int, int]]) -> float:
        """Held-input error estimate relative to the tolerance: the signals' change."""
        values = self.system.values
        worst = 0.0
        tol = self.cfg.tolerance
        for i, k in signals:
            a, b = before.values[i][k], values[i][k]
            scale = self.scale[(i, k)] = max(self.scale[(i, k)], abs(a), abs(b))
            if scale > 0.0:
                worst = max(worst, abs(b - a) / (tol * scale))
        return worst

    def settle(self) -> int:
        """Exchange at one instant until the values stop changing (event iteration)."""
        system = self.system
        for rounds in range(1, self.cfg.max_iterations + 1):
            old = [list(v) for v in system.values], [list(v) for v in system.ints]
            system.exchange()
            if (system.values, system.ints) == old:
                return rounds
        raise RunError(
            f"the exchange at a switching instant did not settle"
            f" in {self.cfg.max_iterations} rounds"
        )

    def _note_changes(self, before: _Readings) -> None:
        """Remember the last regime change since ``before`` (the chattering diagnosis)."""
        changes = regime_changes(self.system, before.regimes, self.system.regimes())
        if changes:
            self.last_change = changes[-1]

    # -- one macro step (the execution loop calls it) ---------------------------------
    def step(self, t: float, stop: float) -> MacroStep:
        """One accepted macro step from t: onto the first switch inside it (then the
        exchange there is settled), or as long as the error test allows."""
        cfg, system, stats = self.cfg, self.system, self.stats
        control = self.control
        # Ends on an input signal's breakpoint; its hold error within the tolerance.
        h = system.signals.clip(t, min(self.h, stop - t), cfg.tolerance)
        state = system.get_state()
        before = self.readings()  # consistent: every trial and settle ends refreshed
        try:
            accepted = self._attempt(t, h, before, state)
            h, te = accepted.h, accepted.switch_at
            if te is not None:
                left = self._left_values(t, accepted, state, before)
        finally:
            system.free_state(state)
            self.free_kept_states()
        end = t + h
        if te is None:
            ratio, first_order = accepted.estimate
            self._note_changes(before)
            self.h = min(cfg.longest_step, h * control.grow(ratio, first_order))
            self._remember_step(tuple(before.regimes), ratio, self.h)
            self.same_instant = 0
            # A regime that changed without a located switch changed at the step start.
            return MacroStep(end, h, changes_at=t, regimes_before=before.regimes)
        stats.iterations += self.settle() - 1
        self._note_changes(before)
        failure = self._chattering(h, end)
        self.h = self._restart_step(tuple(system.regimes()))
        return MacroStep(
            end,
            h,
            switched=True,
            regimes_before=before.regimes,
            left_row=left,  # values just before the switch
            failure=failure,
        )

    def _chattering(self, h: float, end: float) -> RunError | None:
        """After a step of h onto a switch: the error that ends a run switching again and
        again within one instant (Zeno / chattering guard), else None."""
        window = self.instant
        self.same_instant = self.same_instant + 1 if h <= window else 0
        if self.same_instant <= self.cfg.max_events_per_step:
            return None
        return RunError(
            f"chattering: {self.same_instant} switches within {window:.1e} s of each other; "
            f"last in {self._last_switch()}",
            end,
        )

    def _remember_step(self, regimes: tuple[int | None, ...], ratio: float, h: float) -> None:
        """Keep the step proposed after an accepted one in ``regimes`` while no step there
        has had a coupling error."""
        if ratio == 0.0:
            self.zero_error_step[regimes] = max(h, self.zero_error_step.get(regimes, 0.0))
        else:
            self.zero_error_step.pop(regimes, None)

    def _restart_step(self, regimes: tuple[int | None, ...]) -> float:
        """The first step after a switch into ``regimes``: master.first_step, or where the
        coupling error has been exactly zero, a fraction of the step proposed there."""
        remembered = self.zero_error_step.get(regimes, 0.0) * self.control.zero_error_restart
        return max(self.cfg.first_step, remembered)  # remembered steps are <= longest_step

    def _attempt(self, t: float, h: float, before: _Readings, state: list[Any]) -> _Accepted:
        """Trial steps from t until one is accepted.

        A signal that jumps without a reported event (its change does not shrink with the
        step) is a discontinuity: the step that contains it is accepted as a switch.
        """
        cfg, control = self.cfg, self.control
        last_ratio = None
        stalled = 0
        for _ in range(control.max_trials):
            left_row, correction = None, None  # _correct_landing may take both
            predictor = self.trial(t, h)
            te, located = self.switch_time(t, h, before)
            if te is not None and cfg.midpoint:
                te, located, left_row, correction = self._correct_landing(
                    t, h, te, located, before, state, predictor
                )
            elif cfg.midpoint:
                correction = self.corrected_trial(
                    t, h, before, state, [list(v) for v in self.system.values], predictor
                )
                te, located = self.switch_time(t, h, before)
            if te is not None:
                if t + h - te <= self._landing_window(located) or h <= cfg.min_step:
                    estimate = self.step_ratio(before, correction) if cfg.midpoint else None
                    ratio = estimate.ratio if estimate is not None else 0.0
                    if ratio > 1.0 and h > cfg.min_step:
                        # The step onto the switch must pass the error test as well:
                        # approach it in shorter steps (the held-input error at an impact
                        # is the speed mismatch of the two sides, hence the energy).
                        h = max(cfg.min_step, h * control.shrink(ratio, estimate.first_order))
                        self._rollback(state, before)
                        last_ratio = None
                        continue
                    # The step ends on the switch.
                    return _Accepted(h, te, correction, left_row, estimate)
                # End the retaken step just past the located instant.
                h = max(te - t + 0.5 * cfg.event_tolerance, cfg.min_step)
                self._rollback(state, before)
                last_ratio = None
                continue
            estimate = self.step_ratio(before, correction)
            ratio = estimate.ratio
            if ratio > 1.0 and h > cfg.min_step:
                # Two shrinks in a row that leave the change as large: a jump, not a smooth
                # change (one shrink is not proof: a long step may span an oscillation).
                as_large = last_ratio is not None and ratio > control.jump_ratio * last_ratio
                stalled = stalled + 1 if as_large else 0
                if stalled >= control.jump_shrinks:
                    self.stats.extra["jumps"] = self.stats.extra.get("jumps", 0) + 1
                    # Land after the jump and treat it as a switch.
                    return _Accepted(h, t + h, correction, left_row, estimate)
                last_ratio = ratio
                h = max(cfg.min_step, h * control.shrink(ratio, estimate.first_order))
                self._rollback(state, before)
                continue
            return _Accepted(h, None, correction, left_row, estimate)
        raise RunError(
            f"no acceptable step from here after {control.max_trials} trials (last h = {h:.3e} s)",
            t,
        )

    def _correct_landing(
        self,
        t: float,
        h: float,
        te: float,
        located: bool,
        before: _Readings,
        state: list[Any],
        predictor: _Predictor,
    ) -> tuple[float | None, bool, list[float] | None, _Correction | None]:
        """The predictor saw a switch at te inside [t, t+h]: if the step does not yet end on
        it, the caller shortens it (te is returned as is).  If it does, the step is corrected
        with the end values predicted just before the switch (those after it would average a
        jump into the held inputs), and the corrected step's own switch is returned (None if
        the correction moved it past the step end), with the values recorded just before the
        switch and the correction."""
        cfg = self.cfg
        if t + h - te > self._landing_window(located) and h > cfg.min_step:
            return te, located, None, None
        crossed = [list(v) for v in self.system.values]  # the predictor across the switch
        h_left = te - t - 0.5 * cfg.event_tolerance
        if h_left > 0.0:
            self._restore(state, before)
            predictor = self.trial(t, h_left)
            predicted = [list(v) for v in self.system.values]
            # Kept as the recorded values just before the switch: the accepted step's error
            # test bounds this predictor's error by the tolerance, and retaking the step
            # only to record them cost four trials per switch.
            left_row = self.system.record_row(t + h_left)
        else:
            predicted = before.values
            left_row = None
        correction = self.corrected_trial(t, h, before, state, predicted, predictor, crossed)
        return *self.switch_time(t, h, before), left_row, correction

    def _landing_window(self, located: bool) -> float:
        """How far before the step end a switch may be for the step to end on it: the
        event tolerance, or for an instant an FMU located, one instant (retaking a step
        moves the located instant by the retake's own rounding and held inputs, by a few
        event tolerances; chasing that cost three trials a time for nothing measurable)."""
        return self.instant if located else self.cfg.event_tolerance

    def _left_values(
        self, t: float, accepted: _Accepted, state: list[Any], before: _Readings
    ) -> list[float] | None:
        """Recorded values just before the switch the accepted step ends on (then the step
        is retaken to its end)."""
        te, h = accepted.switch_at, accepted.h
        h_left = te - t - 0.5 * self.cfg.event_tolerance
        if h_left <= 0.0:
            return None
        if self.cfg.midpoint and accepted.left_row is not None:
            return accepted.left_row  # taken on the way to this step (_correct_landing)
        self._rollback(state, before)
        predictor = self.trial(t, h_left)
        if self.cfg.midpoint:
            predicted = [list(v) for v in self.system.values]
            self.corrected_trial(t, h_left, before, state, predicted, predictor)
        row = self.system.record_row(t + h_left)
        if self.cfg.midpoint:
            # The very inputs of the accepted step: the retake must cross the switch again.
            self.corrected_trial(t, h, before, state, accepted.correction.predicted, None)
        else:
            self._rollback(state, before)
            self.trial(t, h)
        return row

    def _restore(self, state: list[Any], before: _Readings) -> None:
        """Back to the step start (a rollback, not a rejection: the corrector's retake);
        the values there are those read then."""
        self.system.set_state(state, (before.values, before.ints))
        self.stats.rollbacks += 1

    def _rollback(self, state: list[Any], before: _Readings) -> None:
        """Back to the step start after a rejected trial."""
        self._restore(state, before)
        self.stats.rejections += 1

    def _last_switch(self) -> str:
        if self.last_change is None:
            return "no FMU"
        sub, a, b = self.last_change
        return f"FMU {sub!r} ({a} -> {b})"


def _same(a: list[float], b: list[float]) -> bool:
    """Bit for bit the same values (0.0 and -0.0 differ)."""
    return all(
        x == y and math.copysign(1.0, x) == math.copysign(1.0, y) for x, y in zip(a, b, strict=True)
    )
