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
  Sampled inputs (a state taken at the step start) are never averaged.

After a switch the master iterates the exchange at that instant to a fixed point (so an
impact's momentum exchange reaches the other FMU before anything moves), records the left
and right values, logs the switch, and restarts with a short step (``master.step``; into
regimes where every accepted step so far had zero coupling error, a fraction of the step
proposed there last).  A guard stops runs that keep switching at one instant (chattering /
Zeno) with a diagnosis.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from orchestrator.errors import RunError
from orchestrator.master_settings import RegimeAwareSettings
from orchestrator.masters.fixed_step import run_fixed_step_scene
from orchestrator.recorder import Recorder, RegimeLog, StepStats
from orchestrator.scenario import Scene
from orchestrator.system import CoupledSystem


@dataclass
class _Snapshot:
    """Everything read from the FMUs at one instant."""

    values: list[list[float]]
    ints: list[list[int]]
    regimes: list[int | None]
    indicators: list[list[float]]
    stop: float | None  # the scene's stop indicator (> 0 until the condition is met)


class RegimeAwareMaster:
    def __init__(
        self,
        system: CoupledSystem,
        settings: RegimeAwareSettings,
        start: float,
        stop: float,
        recorder: Recorder,
        stats: StepStats,
    ):
        self.system, self.recorder, self.stats = system, recorder, stats
        self.cfg, self.control = settings, settings.control
        self.start, self.stop = start, stop
        self.names = system.names
        self.log = RegimeLog(system, recorder)
        # Exchanged Real signals held over a step: (instance, slot) of their sources.  Inputs
        # that are sampled as a state at the step start carry no hold error of their own.
        # Midpoint hold: per instance, its Real inputs in feed order as (source, averaged?);
        # the held ones are averaged over the step.  An FMU that does not say which of its
        # inputs are sampled (one from another tool) is a black box: averaging a sampled
        # input would be wrong at first order, unseen by the error test, so its inputs stay
        # at their step-start values and their change over the step is the error (first
        # order, as with input_hold = "start").
        held, blind = set(), set()
        self.held_inputs: list[list[tuple[tuple[int, int], bool]]] = [[] for _ in self.names]
        for c, src in zip(system.connections, system.connection_sources, strict=True):
            if src is None:
                continue
            model = system.models[system.index[c.target[0]]]
            sampled = c.target[1] in model.sampled
            if not model.annotated:
                blind.add(src)
            elif not sampled:
                held.add(src)
            averaged = model.annotated and not sampled
            self.held_inputs[system.index[c.target[0]]].append((src, averaged))
        self.signals = sorted(held | blind)  # start hold: every held signal's change
        self.blind = sorted(blind)
        self.scale = {s: 0.0 for s in self.signals}
        self.first_order = not self.cfg.midpoint  # the last error ratio's order in h
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
        self.out_scale = {s: 0.0 for s in self.outputs}
        self.ratio = 0.0  # error ratio of the last corrected trial
        self.predicted: list[list[float]] = []  # end values the last corrected trial used
        self.left_row: list[float] | None = None  # values just before the last landed switch
        self.predictor_end: tuple[float, float] | None = None  # (t, h) the FMUs are at
        self.predictor_states: list[Any] | None = None  # just after the last predictor step
        self.located = False  # the last switch_time is an instant an FMU reported
        #: switches this close are one instant (chattering guard, landing on a located switch)
        self.instant = settings.control.settle_window * settings.event_tolerance
        #: per combination of regimes in which every accepted step had zero coupling error:
        #: the largest step the controller proposed there (the restart after a switch)
        self.zero_error_step: dict[tuple[int | None, ...], float] = {}

    # -- helpers ----------------------------------------------------------------------
    def snapshot(self) -> _Snapshot:
        s = self.system
        return _Snapshot(
            [list(v) for v in s.values],
            [list(v) for v in s.ints],
            s.regimes(),
            s.indicators(),
            s.stop_indicator(),
        )

    def trial(self, t: float, h: float) -> None:
        """One Jacobi pass over [t, t+h] with every input held at its value at t."""
        system = self.system
        for i in range(len(system.instances)):
            system.feed(i)
        self._step_all(t, h, keep=self.cfg.midpoint)
        self.predictor_end = (t, h)

    def _step_all(
        self, t: float, h: float, which: list[int] | None = None, keep: bool = False
    ) -> None:
        """Step the instances (those in ``which``) over [t, t+h] and exchange; with
        ``keep``, their states just after the step are kept for the corrector."""
        system = self.system
        which = range(len(system.instances)) if which is None else which
        for i in which:
            system.step(i, t, h)
        if keep:
            self.free_predictor_states()
            self.predictor_states = system.get_state()
        system.read_all()
        self.refresh()
        self.stats.do_steps += len(which)

    def free_predictor_states(self) -> None:
        if self.predictor_states is not None:
            self.system.free_state(self.predictor_states)
            self.predictor_states = None

    def corrected_trial(
        self,
        t: float,
        h: float,
        before: _Snapshot,
        state: list[Any],
        predicted: list[list[float]],
        compare: list[list[float]] | None = None,
    ) -> None:
        """Retake the step [t, t+h] from the saved state with every held input at the mean
        of its start and ``predicted`` end values; ``self.ratio`` is the correction's size
        (against the predictor's values at t+h, ``compare``, by default ``predicted``)
        relative to the tolerance: the predictor's error estimate."""
        system = self.system
        self.predicted = predicted  # to retake this very step (see _left_values)
        start = before.values
        feeds, retake = [], []
        at_predictor = self.predictor_end == (t, h) and self.predictor_states is not None
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
        kept = self.predictor_states
        # Not read back: each is fed the values above, and read again after the step below.
        system.restore([state[i] if i in retake else kept[i] for i in range(len(feeds))])
        self.stats.rollbacks += 1
        self.predictor_end = None
        for i in range(len(feeds)):
            system.feed(i, feeds[i], before.ints)
        self._step_all(t, h, retake)
        worst, tol = 0.0, self.cfg.tolerance
        values = system.values
        compare = predicted if compare is None else compare
        for i, k in self.outputs:
            a, b = compare[i][k], values[i][k]
            scale = self.out_scale[(i, k)] = max(self.out_scale[(i, k)], abs(start[i][k]), abs(b))
            if scale > 0.0:
                worst = max(worst, abs(b - a) / (tol * scale))
        self.ratio = worst

    def refresh(self) -> None:
        """Give every FMU the others' newest outputs, so that outputs which depend on
        inputs (indicators among them) are those of one consistent instant."""
        system = self.system
        for i in range(len(system.instances)):
            system.feed(i)
        system.read_all()

    def switch_time(self, t: float, h: float, before: _Snapshot) -> float | None:
        """Earliest switching instant inside (t, t+h], or None if nothing switched.

        An FMU that reports its internal event time gives it exactly; an indicator that
        changed sign (the scene's stop condition among them) gives a secant estimate.
        """
        system = self.system
        after_regimes, after_ind = system.regimes(), system.indicators()
        best: float | None = None
        reported: float | None = None  # the earliest instant an FMU reported
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
        self.located = best is not None and best == reported
        return best

    def step_ratio(self, before: _Snapshot) -> float:
        """Error estimate of the step just taken, relative to the tolerance (<= 1 accepts):
        the corrector's (second order), or the change of the signals held at the step start
        (first order) where that is larger."""
        if not self.cfg.midpoint:
            return self.error_ratio(before, self.signals)
        blind = self.error_ratio(before, self.blind) if self.blind else 0.0
        self.first_order = blind > self.ratio
        return max(self.ratio, blind)

    def error_ratio(self, before: _Snapshot, signals: list[tuple[int, int]]) -> float:
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
            for i in range(len(system.instances)):
                system.feed(i)
            system.read_all()
            if (system.values, system.ints) == old:
                return rounds
        raise RunError(
            f"the exchange at a switching instant did not settle"
            f" in {self.cfg.max_iterations} rounds"
        )

    def log_switches(self, t: float, before: _Snapshot) -> int:
        self.log.last = before.regimes
        return self.log.update(t)

    # -- main loop --------------------------------------------------------------------
    def run(self, progress) -> None:
        cfg, system, stats, recorder = self.cfg, self.system, self.stats, self.recorder
        control = self.control
        t, stop = self.start, self.stop
        h = cfg.first_step
        recorder.row(system.record_row(t))
        same_instant = 0
        while t < stop - control.stop_slack * max(1.0, abs(stop)):
            h = min(h, stop - t)
            state = system.get_state()
            before = self.snapshot()  # consistent: every trial and settle ends refreshed
            try:
                h, te = self._attempt(t, h, before, state)
                if te is not None:
                    left = self._left_values(t, te, h, state, before)
            finally:
                system.free_state(state)
                self.free_predictor_states()
            t += h
            stats.steps += 1
            if te is None:
                ratio = self.step_ratio(before)
                stats.events += self.log_switches(t - h, before)  # switched at the start
                recorder.row(system.record_row(t))
                h = min(cfg.max_step, h * control.grow(ratio, self.first_order))
                self._remember_step(tuple(before.regimes), ratio, h)
                same_instant = 0
            else:
                if left is not None:
                    recorder.row(left)  # values just before the switch
                stats.iterations += self.settle() - 1
                stats.events += max(self.log_switches(t, before), 1)
                recorder.row(system.record_row(t))  # values just after the switch
                window = self.instant
                same_instant = same_instant + 1 if h <= window else 0
                if same_instant > cfg.max_events_per_step:
                    raise RunError(
                        f"chattering: {same_instant} switches within "
                        f"{window:.1e} s of each other; "
                        f"last in {self._last_switch()}",
                        t,
                    )
                h = self._restart_step(tuple(system.regimes()))
            progress(t)
            stop_indicator = system.stop_indicator()
            if stop_indicator is not None and stop_indicator <= 0.0:
                stats.extra["stopped_by_condition"] = True
                return

    def _remember_step(self, regimes: tuple[int | None, ...], ratio: float, h: float) -> None:
        """Keep the step proposed after an accepted one in ``regimes`` while no step there
        has had a coupling error."""
        if ratio == 0.0:
            self.zero_error_step[regimes] = max(h, self.zero_error_step.get(regimes, 0.0))
        else:
            self.zero_error_step.pop(regimes, None)

    def _restart_step(self, regimes: tuple[int | None, ...]) -> float:
        """The first step after a switch into ``regimes``: master.step, or where the
        coupling error has been exactly zero, a fraction of the step proposed there."""
        remembered = self.zero_error_step.get(regimes, 0.0) * self.control.zero_error_restart
        return max(self.cfg.first_step, remembered)  # remembered steps are <= max_step

    def _attempt(self, t: float, h: float, before: _Snapshot, state: list[Any]):
        """Trial steps from t until one is accepted; returns (h, switch time or None).

        A signal that jumps without a reported event (its change does not shrink with the
        step) is a discontinuity: the step that contains it is accepted as a switch.
        """
        cfg, control = self.cfg, self.control
        last_ratio = None
        stalled = 0
        for _ in range(control.max_trials):
            self.left_row = None  # set by _correct_landing for this very trial
            self.trial(t, h)
            te = self.switch_time(t, h, before)
            if te is not None and cfg.midpoint:
                te = self._correct_landing(t, h, te, before, state)
            elif cfg.midpoint:
                self.corrected_trial(t, h, before, state, [list(v) for v in self.system.values])
                te = self.switch_time(t, h, before)
            if te is not None:
                if t + h - te <= self._landing_window() or h <= cfg.min_step:
                    ratio = self.step_ratio(before) if cfg.midpoint else 0.0
                    if ratio > 1.0 and h > cfg.min_step:
                        # The step onto the switch must pass the error test as well:
                        # approach it in shorter steps (the held-input error at an impact
                        # is the speed mismatch of the two sides, hence the energy).
                        h = max(cfg.min_step, h * control.shrink(ratio, self.first_order))
                        self._rollback(state, before)
                        last_ratio = None
                        continue
                    return h, te  # the step ends on the switch
                # End the retaken step just past the located instant.
                h = max(te - t + 0.5 * cfg.event_tolerance, cfg.min_step)
                self._rollback(state, before)
                last_ratio = None
                continue
            ratio = self.step_ratio(before)
            if ratio > 1.0 and h > cfg.min_step:
                # Two shrinks in a row that leave the change as large: a jump, not a smooth
                # change (one shrink is not proof: a long step may span an oscillation).
                as_large = last_ratio is not None and ratio > control.jump_ratio * last_ratio
                stalled = stalled + 1 if as_large else 0
                if stalled >= control.jump_shrinks:
                    self.stats.extra["jumps"] = self.stats.extra.get("jumps", 0) + 1
                    return h, t + h  # land after the jump and treat it as a switch
                last_ratio = ratio
                h = max(cfg.min_step, h * control.shrink(ratio, self.first_order))
                self._rollback(state, before)
                continue
            return h, None
        raise RunError(
            f"no acceptable step from here after {control.max_trials} trials (last h = {h:.3e} s)",
            t,
        )

    def _correct_landing(
        self, t: float, h: float, te: float, before: _Snapshot, state: list[Any]
    ) -> float | None:
        """The predictor saw a switch at te inside [t, t+h]: if the step does not yet end on
        it, the caller shortens it (te is returned as is).  If it does, the step is corrected
        with the end values predicted just before the switch (those after it would average a
        jump into the held inputs), and the corrected step's own switch time is returned
        (None if the correction moved the switch past the step end)."""
        cfg = self.cfg
        if t + h - te > self._landing_window() and h > cfg.min_step:
            return te
        crossed = [list(v) for v in self.system.values]  # the predictor across the switch
        h_left = te - t - 0.5 * cfg.event_tolerance
        if h_left > 0.0:
            self._restore(state, before)
            self.trial(t, h_left)
            predicted = [list(v) for v in self.system.values]
            # Kept as the recorded values just before the switch: the accepted step's error
            # test bounds this predictor's error by the tolerance, and retaking the step
            # only to record them cost four trials per switch.
            self.left_row = self.system.record_row(t + h_left)
        else:
            predicted = before.values
            self.left_row = None
        self.corrected_trial(t, h, before, state, predicted, compare=crossed)
        return self.switch_time(t, h, before)

    def _landing_window(self) -> float:
        """How far before the step end a switch may be for the step to end on it: the
        event tolerance, or for an instant an FMU located, one instant (retaking a step
        moves the located instant by the retake's own rounding and held inputs, by a few
        event tolerances; chasing that cost three trials a time for nothing measurable)."""
        return self.instant if self.located else self.cfg.event_tolerance

    def _left_values(
        self, t: float, te: float, h: float, state: list[Any], before: _Snapshot
    ) -> list[float] | None:
        """Recorded values just before the switch at te (then the step is retaken to t+h)."""
        h_left = te - t - 0.5 * self.cfg.event_tolerance
        if h_left <= 0.0:
            return None
        if self.cfg.midpoint and self.left_row is not None:
            return self.left_row  # taken on the way to this step (_correct_landing)
        accepted = self.predicted
        self._rollback(state, before)
        self.trial(t, h_left)
        if self.cfg.midpoint:
            predicted = [list(v) for v in self.system.values]
            self.corrected_trial(t, h_left, before, state, predicted)
        row = self.system.record_row(t + h_left)
        if self.cfg.midpoint:
            # The very inputs of the accepted step: the retake must cross the switch again.
            self.corrected_trial(t, h, before, state, accepted)
        else:
            self._rollback(state, before)
            self.trial(t, h)
        return row

    def _restore(self, state: list[Any], before: _Snapshot) -> None:
        """Back to the step start (a rollback, not a rejection: the corrector's retake);
        the values there are those read then."""
        self.system.set_state(state, (before.values, before.ints))
        self.stats.rollbacks += 1
        self.predictor_end = None

    def _rollback(self, state: list[Any], before: _Snapshot) -> None:
        """Back to the step start after a rejected trial."""
        self._restore(state, before)
        self.stats.rejections += 1

    def _last_switch(self) -> str:
        if not self.recorder.events:
            return "no FMU"
        t, sub, a, b = self.recorder.events[-1]
        return f"FMU {sub!r} ({a} -> {b})"


def _same(a: list[float], b: list[float]) -> bool:
    """Bit for bit the same values (0.0 and -0.0 differ)."""
    return all(
        x == y and math.copysign(1.0, x) == math.copysign(1.0, y) for x, y in zip(a, b, strict=True)
    )


def run_regime_aware(
    system: CoupledSystem, scene: Scene, recorder: Recorder, stats: StepStats, progress
) -> None:
    blind = [n for n, m in zip(system.names, system.models, strict=True) if not m.can_get_set_state]
    if blind:
        # Without rollback no trial can be taken back: say what is given up, and couple
        # the way every tool can.
        stats.extra.setdefault("warnings", []).append(
            f"FMU {', '.join(map(repr, blind))} cannot save and restore its state "
            "(canGetAndSetFMUstate is false), which the regime-aware master needs to reject "
            "steps and to land on switches: it gives both up and runs fixed-step Jacobi at "
            f"master.step = {scene.master.step:g} s (no error control, switches seen only "
            "at communication points)"
        )
        run_fixed_step_scene(
            system, scene, scene.master.step, recorder, stats, progress, sequential=False
        )
        return
    settings = scene.master.settings
    if settings.single_pass:
        # Imported here: the single-pass master builds on this module's master.
        from orchestrator.masters.single_pass import SinglePassMaster

        master: RegimeAwareMaster = SinglePassMaster(
            system, settings, scene.start, scene.stop, recorder, stats
        )
    else:
        master = RegimeAwareMaster(system, settings, scene.start, scene.stop, recorder, stats)
    master.run(progress)
