"""The regime-aware master's single-pass trials (``input_hold = "extrapolated"``).

Each FMU is stepped once per macro step; a step is retaken only when its error estimate
exceeds the tolerance.

Inputs.  A held input is set to the mean over the step of its source's linear
extrapolation from the last exchange point of the same regime (after a regime switch the
first step holds the start values; over an FMU's internal event the slopes go on:
masters/input_extrapolation.py).  A black box that declares it interpolates its inputs
(FMI 2.0 ``canInterpolateInputs``) takes them at their start values with the
extrapolation's slope there, by fmi2SetRealInputDerivatives, and is judged as the held
signals are.  A source stepped earlier in the same pass that gives its
step mean (an output with the role step_mean_of the connected one: the verge's escapement
torque whose impulse its wheel took) gives that instead, so its receiver takes the very
impulse of the step; so does its rate over the step (``T_esc_rate_mean``, from the
torque's first moment), so the train ramps its load and takes the impulse's first moment
too.  The other way, the train sends its response with its slopes in the wheel state (a
reduced model of the train, sampled at the step start), so the verge's copy of the wheel
follows the train over the step rather than held values: the copy's mismatch then falls so
far that M739's macro steps are bounded by its switches, not by the tolerance (no longest
step but the run unless the scene sets one: ``RegimeAwareSettings.longest_step``).

Error.  Where a receiver reports its own copy of a sampled input (an output with the role
own_copy_of it, masters/copies.py: the
verge's copy of the escape wheel), the estimate is the copy's mismatch with the source at
the step end against the source's travel in the step: it measures the held inputs' effect
on the motion, and the mismatches of all steps add up to at most the tolerance times the
whole travel (the tolerance bounds the relative error in turns).  A speed copy (its unit
the angle's per second) counts as the angle its mismatch moves the copy by in the step,
except where the source ended the step at its own event (its speed jumps there); a source
at rest counts as travelling ``SinglePassControl.travel_floor`` of its travel at its
largest rate so far.  Elsewhere it is each held signal's extrapolated mean against the
trapezoidal mean of its actual start and end values, relative to its running scale, as in
Schierz, Arnold & Clauß, "Co-simulation with communication step size control in an FMI
compatible master algorithm", 9th International Modelica Conference (2012).

Switches.  An FMU with an input of the role early_return (``components.early_return``)
ends its step at its first event and says where in its reached_time output; such FMUs are stepped
first (those giving step means before their receivers), each to where the earliest so far
stopped, and the others once to that instant: landing on a switch costs one doStep of
each FMU, none retaken.  When one stops before an instant the ones before it were stepped
to, those are stepped again to it (it stays where it stopped, with the inputs it had).
A switch that only an indicator or a reported event time of another FMU shows is located
and landed on as in the midpoint hold (masters/regime_aware.py).
"""

from __future__ import annotations

from typing import NamedTuple

from orchestrator.master_settings import RegimeAwareSettings
from orchestrator.masters.copies import Copy, angles_with_speeds, copied_inputs
from orchestrator.masters.held_inputs import HeldInputs
from orchestrator.masters.input_extrapolation import InputExtrapolation
from orchestrator.masters.regime_aware import Estimate, RegimeAwareStats, RestartSteps, Trial
from orchestrator.masters.switches import Landing, Readings, StepStart, Switch, switch_time
from orchestrator.system import CoupledSystem


class _Pass(NamedTuple):
    """What one pass of every FMU reached."""

    h: float  # the step taken (shorter than asked where an FMU ended at its event)
    returned: frozenset[int]  # the FMUs that ended it at their own event
    #: the values at the step end with the inputs of the step (an impact not yet taken)
    end_values: list[list[float]]


class SinglePassTrials:
    """One pass of every FMU per trial, inputs extrapolated; see the module doc."""

    def __init__(
        self,
        system: CoupledSystem,
        settings: RegimeAwareSettings,
        stats: RegimeAwareStats,
        landing: Landing,
    ) -> None:
        self.system, self.settings, self.stats, self.landing = system, settings, stats, landing
        control = settings.single_pass_control
        self.growth_safety = control.growth_safety
        self.next_step_floor = settings.min_step
        self.rounds = control.early_return_rounds
        self.travel_floor = control.travel_floor
        self.restart = RestartSteps(settings.first_step, control.restart, False)
        self.held = HeldInputs(system)
        # Every averaged signal is extrapolated (for the feeds); not every one is judged.
        sloped = self.held.interpolated_sources()
        self.slopes = {j: (indices, setter) for j, indices, setter in self.held.slopes()}
        self.extrapolation = InputExtrapolation(
            sorted({*self.held.averaged_sources(), *sloped}), control.extrapolation_points
        )
        # FMUs that end a step at their first event: set them to do so, stepped first.
        self.early: list[int] = []
        self.reached_slot: dict[int, int] = {}
        for i, (inst, model) in enumerate(zip(system.instances, system.models, strict=True)):
            var = model.with_role("early_return")
            out = model.with_role("reached_time")
            if var is None or out is None:
                continue
            if any(c.target == (system.names[i], var.name) for c in system.connections):
                continue  # the scene drives it
            inst.setter(inst.refs([var.name]), integer=True)([1])
            self.early.append(i)
            self.reached_slot[i] = system.real_output_slot(i, out.name)
        # Step means: an output with the role step_mean_of a connected one is its mean over
        # the last step, what a receiver stepped after it should hold.
        self.means: dict[tuple[int, int], int] = {}
        for c, src in zip(system.connections, system.connection_sources, strict=True):
            mean = system.models[src[0]].with_role("step_mean_of", c.source[1]) if src else None
            if mean is not None:
                self.means[src] = system.real_output_slot(src[0], mean.name)
        givers = {s for s, _ in self.means}
        self.early.sort(key=lambda i: i not in givers)
        self.late = [i for i in range(len(system.names)) if i not in self.early]
        # Sampled inputs whose receiver reports its own copy at the step end: the copy
        # follows the held inputs, the source the true ones: their difference at the step
        # end is the coupling error the next step start discards.
        copied = copied_inputs(system)
        copies: list[Copy] = [
            (src, (j, system.real_output_slot(j, own))) for src, j, _, own in copied
        ]
        units = [
            system.models[j].base_unit(system.models[j].variables[n].unit) for _, j, n, _ in copied
        ]
        self.judged = angles_with_speeds(copies, units)
        # The held inputs of FMUs joined by such a copy are judged by it (their effect on
        # the motion, not the size of their change); the others by their extrapolation.
        covered = {j for (_, (j, _)) in copies} | {s[0] for (s, _) in copies}
        self.averaged = self.held.averaged_sources(skip=covered)
        if sloped:
            self.averaged = sorted({*self.averaged, *(s for s in sloped if s[0] not in covered)})
        self.rate: dict[tuple[int, int], float] = {}  # largest rate of a copied source

    # -- the scheme's part of a macro step ---------------------------------------------
    def begin(self, start: StepStart) -> None:
        self.extrapolation.prepare(start.t, start.before.values)

    def accepted(self, start: StepStart) -> None:
        self.extrapolation.accepted(start.t, start.before.values)

    def switched(self, accepted: Trial, do_steps: int) -> None:
        if not accepted.internal:
            # Its doSteps (rejected passes included) and the accepted pass's.
            self.stats.landed(do_steps, accepted.do_steps)
        self.extrapolation.switched(accepted.internal)

    def left_row(self, accepted: Trial, switch_at: float, start: StepStart) -> None:
        return None  # a pass ends on its switch: the values there are the right ones

    def end(self) -> None:
        pass

    def trial(self, h: float, start: StepStart) -> Trial:
        t, before = start.t, start.before
        do_steps = self.stats.do_steps
        taken = self._one_pass(t, h, start)
        switch = switch_time(
            self.system, t, taken.h, before, self.settings.control.event_time_slack
        )
        internal = False
        if taken.h < h:  # an FMU ended its step at its own event
            window = self.landing.window(switch is not None and switch.located)
            if switch is None or switch.at >= t + taken.h - window:
                internal = switch is None
                switch = Switch(t + taken.h, True)
        return Trial(
            h=taken.h,
            h_asked=h,
            switch=switch,
            estimate=self._estimate(taken, before),
            do_steps=self.stats.do_steps - do_steps,
            internal=internal,
        )

    # -- one pass ----------------------------------------------------------------------
    def _feed_row(
        self, i: int, h: float, before: Readings, done: set[int] = frozenset()
    ) -> list[float]:
        """FMU i's Real inputs for a step h from ``before``: held signals at the mean of
        their extrapolation, sampled ones at their start values, and from a source already
        stepped over this very step (``done``) that gives its step mean, that."""
        start, now = before.values, self.system.values
        ex, means = self.extrapolation, self.means
        row = []
        for (s, k), averaged, _, interpolated in self.held.inputs[i]:
            mean = means.get((s, k)) if s in done else None
            if interpolated:
                row.append(start[s][k])  # ramped from there (_feed)
            elif mean is not None:
                row.append(now[s][mean])
            elif averaged:
                row.append(ex.mean((s, k), start[s][k], h))
            else:
                row.append(start[s][k])
        return row

    def _feed(self, i: int, h: float, before: Readings, done: set[int]) -> None:
        """Set FMU i's inputs for a step h from ``before``, and the slopes of those it
        ramps."""
        self.system.feed(i, self._feed_row(i, h, before, done), before.ints)
        if i in self.slopes:
            indices, setter = self.slopes[i]
            inputs, ex = self.held.inputs[i], self.extrapolation
            if i in self.system.held_back:  # stepped as Jacobi steps it (masters/held_back.py)
                setter([0.0] * len(indices))
            else:
                setter([ex.slope(inputs[k].source) for k in indices])

    def _one_pass(self, t: float, h: float, start: StepStart) -> _Pass:
        """Step every FMU once from t, those that end at their first event first (the
        ones that give step means before their receivers), each to where the earliest so
        far stopped, then the others there.  When one stops before an instant the ones
        before it were stepped to, those are stepped again from t to it."""
        system, stats, before = self.system, self.stats, start.before
        h_end = h
        returned: set[int] = set()
        for round_ in range(self.rounds):
            # The one that ended at its event is at the instant the others are stepped
            # again to: kept, with the inputs it had (the copy's mismatch judges them).
            done: set[int] = set(returned)
            again = False
            for i in self.early:
                if i in done:
                    continue
                if round_ > 0:
                    system.instances[i].set_state(start.state[i])
                    stats.rollbacks += 1
                self._feed(i, h_end, before, done)
                system.step(i, t, h_end)
                stats.do_steps += 1
                system.read(i)
                done.add(i)
                reached = system.values[i][self.reached_slot[i]]
                if t < reached < t + h_end:
                    again = bool(done - {i})  # those before it went past its event
                    h_end = reached - t
                    returned.clear()
                    returned.add(i)
                # One that returned in an earlier round, stepped again to that instant,
                # ends there at its event again: it stays among those that returned.
            if not again:
                break
        for i in self.late:
            self._feed(i, h_end, before, done)
            system.step(i, t, h_end)
        stats.do_steps += len(self.late)
        for i in self.late:  # the early ones were read after their step
            system.read(i)
        end_values = list(system.values)  # read() replaces the inner lists
        system.exchange()
        return _Pass(h_end, frozenset(returned), end_values)

    # -- error estimate ----------------------------------------------------------------
    def _estimate(self, taken: _Pass, before: Readings) -> Estimate:
        """Error ratio of the pass just taken: the extrapolated mean against the
        trapezoidal mean of each held signal's actual start and end values, and each
        copy's mismatch against its source's travel.  An FMU that ended its step at its
        own event has its outputs of after the event there (they jump at it): its signals
        are not compared on that step."""
        ex, tol, held = self.extrapolation, self.settings.tolerance, self.held
        h, returned = taken.h, taken.returned
        start, end = before.values, taken.end_values
        worst = 0.0
        for s in self.averaged:
            i, k = s
            if i in returned:
                continue
            a, b = start[i][k], end[i][k]
            scale = held.scale[s] = max(held.scale[s], abs(a), abs(b))  # from its nominal
            if scale > 0.0:
                miss = abs(ex.mean(s, a, h) - 0.5 * (a + b))
                worst = max(worst, miss / (tol * scale))
        # Copies as the receiver ended its step; sources as they are after the exchange
        # at the end (a source that takes an impact from the receiver has taken it).  The
        # mismatch is measured against how far the source moves in the step at its
        # largest rate so far (error per unit step): the mismatches of the steps add up
        # to at most the tolerance times the source's travel at that rate.
        now = self.system.values
        smooth = not returned  # an event's jump is no rate
        for s, (j, k), speed in self.judged:
            a, b = start[s[0]][s[1]], now[s[0]][s[1]]
            rate = max(self.rate.get(s, 0.0), abs(b - a) / h)
            if smooth:
                self.rate[s] = rate
            travel = max(abs(b - a), self.travel_floor * rate * h)
            if travel > 0.0:
                miss = abs(end[j][k] - b)
                # The angle a speed mismatch moves the copy by; not when the source ended
                # the step at its own event (its speed jumps there: a handover's impact).
                if speed is not None and s[0] not in returned:
                    (vs, (vj, vk)) = speed
                    miss = max(miss, abs(end[vj][vk] - now[vs[0]][vs[1]]) * h)
                worst = max(worst, miss / (tol * travel))
        unannotated = held.change_ratio(before, held.unsloped, tol) if held.unsloped else 0.0
        return Estimate(max(worst, unannotated), unannotated > worst or not ex.second_order)
