"""The regime-aware master with one pass per macro step (``input_hold = "extrapolated"``).

Each FMU is stepped once per macro step; a step is retaken only when its error estimate
exceeds the tolerance.

Inputs.  A held input is set to the mean over the step of its source's linear
extrapolation from the last exchange point of the same regime (after a regime switch the
first step holds the start values; over an FMU's internal event the slopes go on).  A
source stepped earlier in the same pass that gives its step mean (an output named after
the connected one with ``_mean``: the verge's escapement torque whose impulse its wheel
took) gives that instead, so its receiver takes the very impulse of the step; so does its
rate over the step (``T_esc_rate_mean``, from the torque's first moment), so the train ramps
its load and takes the impulse's first moment too (M739's coupling mismatch in the coupled
phases was 98 % that moment's).  The other way, the train sends its response with its
slopes in the wheel state (a reduced model of the train, sampled at the step start), so
the verge's copy of the wheel follows the train over the step rather than held values:
the copy's mismatch then falls so far that M739's macro steps are bounded by its switches,
not by the tolerance (1334 doSteps at 1e-2, 2010 at 1e-5; no longest step but the run
unless the scene sets one: ``RegimeAwareSettings.longest_step``).

Error.  Where a receiver reports its own copy of a sampled input (an output named after
the input with ``_own``: the verge's copy of the escape wheel), the estimate is the copy's
mismatch with the source at the step end against the source's travel in the step: it
measures the held inputs' effect on the motion, and the mismatches of all steps add up to
at most the tolerance times the whole travel (the tolerance bounds the relative error in
turns).  A speed copy (its unit the angle's per second) counts as the angle its mismatch
moves the copy by in the step, except where the source ended the step at its own event
(its speed jumps there); a source at rest counts as travelling a tenth of its travel at
its largest rate so far.
Elsewhere it is each held signal's extrapolated mean against the trapezoidal mean of its
actual start and end values, relative to its running scale, as in Schierz, Arnold &
Clauß, "Co-simulation with communication step size control in an FMI compatible master
algorithm", 9th International Modelica Conference (2012).

Switches.  An FMU with an Integer input ``early_return`` (``components.early_return``)
ends its step at its first event and says where in ``t_reached``; such FMUs are stepped
first (those giving step means before their receivers), each to where the earliest so far
stopped, and the others once to that instant: landing on a switch costs one doStep of
each FMU, none retaken.  When one stops before an instant the ones before it were stepped
to, those are stepped again to it (it stays where it stopped, with the inputs it had).
A switch that only an indicator or a reported event time of another FMU shows is located
and landed on as in the midpoint master.
"""

from __future__ import annotations

from typing import Any

from orchestrator.errors import RunError
from orchestrator.masters.macro_step import MacroStep
from orchestrator.masters.regime_aware import RegimeAwareMaster, _Readings
from orchestrator.observers import regime_changes

#: Name of the Integer input by which an FMU offers to end a step at its first event, and
#: of the output that says where it stopped.
EARLY_RETURN_INPUT = "early_return"
REACHED_OUTPUT = "t_reached"
#: Suffix of the output by which an FMU reports its own copy of a sampled input.
OWN_SUFFIX = "_own"
#: Suffix of the output that is the mean of another over the last step.
MEAN_SUFFIX = "_mean"


#: After a switch, restart at this fraction of the step proposed last in the regimes
#: entered (M739 at 1e-3: 3208 steps against 3493 restarting at master.first_step; at 0.5
#: and 1 fewer steps but a larger error for the same time).
RESTART = 0.25
#: Previous points of the extrapolation: 1, linear (2, quadratic, took 26 % fewer steps on
#: M739 at 1e-3 but tripled its turns error, 4.5e-4 against 1.4e-4).
ORDER = 1
#: Passes over one step when FMUs that end early stop before one another.
MAX_ROUNDS = 4
#: The step after an accepted one grows at most by MasterStepControl.max_growth, and by this
#: factor less than the estimate allows (M739 at 1e-3: 152 rejected passes against 544).
GROWTH_SAFETY = 0.8
#: A copied source's travel in a step is taken as at least this fraction of its travel at
#: its largest rate so far (a wheel at rest would otherwise allow no mismatch at all).
TRAVEL_FLOOR = 0.1


class InputExtrapolation:
    """Per exchanged Real signal: its values at the last exchange points where it was
    continuous, to extrapolate it over the next step by the polynomial through them
    (Newton form: linear through one previous point, quadratic through two)."""

    def __init__(self, signals: list[tuple[int, int]], points: int = ORDER) -> None:
        self.signals = signals
        self.points = points
        self.history: dict[tuple[int, int], list[tuple[float, float]]] = {s: [] for s in signals}
        #: per signal (first divided difference, second divided difference, t - t1)
        self.coefficients: dict[tuple[int, int], tuple[float, float, float]] = {}
        self.carried: dict[tuple[int, int], float] = {}

    def prepare(self, t: float, values: list[list[float]]) -> None:
        """The extrapolation for the step from t (values: those read at t)."""
        coefficients = {}
        for s, hist in self.history.items():
            v = values[s[0]][s[1]]
            if not hist or hist[-1][0] >= t:
                slope = self.carried.get(s)
                if slope is not None:
                    coefficients[s] = (slope, 0.0, 0.0)
                continue
            t1, v1 = hist[-1]
            d1 = (v - v1) / (t - t1)
            d2 = 0.0
            if len(hist) > 1:
                t0, v0 = hist[-2]
                d2 = (d1 - (v1 - v0) / (t1 - t0)) / (t - t0)
            coefficients[s] = (d1, d2, t - t1)
        self.coefficients = coefficients
        self.carried = {}

    def accepted(self, t: float, values: list[list[float]]) -> None:
        """The step from t was accepted without a switch: t is the last point now."""
        for s, hist in self.history.items():
            hist.append((t, values[s[0]][s[1]]))
            del hist[: -self.points]

    def switched(self, internal: bool) -> None:
        """The step ended on a switch.  At a regime change every signal starts anew.  At
        an FMU's internal event (a friction sign, a mesh piece) the signals go on at the
        slopes they had: a jump there would spoil a slope through it, and a kink (the
        others' rates change with the event) would spoil one kept across it (measured:
        keeping the points of the signals that did not jump doubled M739's error)."""
        for s, hist in self.history.items():
            hist.clear()
            c = self.coefficients.get(s)
            if internal and c is not None:
                self.carried[s] = c[0]

    def mean(self, source: tuple[int, int], start: float, h: float) -> float:
        """Mean over [t, t+h] of the extrapolated signal."""
        c = self.coefficients.get(source)
        if c is None:
            return start
        return start + c[0] * 0.5 * h + c[1] * (h * h / 3.0 + 0.5 * c[2] * h)

    @property
    def second_order(self) -> bool:
        return bool(self.coefficients)


Copy = tuple[tuple[int, int], tuple[int, int]]  # (source slot, receiver's copy slot)


def angles_with_speeds(
    copies: list[Copy], units: list[tuple[tuple[tuple[str, int], ...], float] | None]
) -> list[tuple[tuple[int, int], tuple[int, int], Copy | None]]:
    """The copies as the error estimate judges them: (source, copy, its speed's copy or
    None).  A copy whose unit is another's (same receiver, same source FMU) per second is
    that one's speed: its mismatch counts as the angle it moves the copy by in the step.
    Units: each copy's base unit (exponents, factor) as ``ModelInfo.base_unit`` gives it."""

    def per_second(unit):
        if unit is None:
            return None
        exponents = dict(unit[0])
        exponents["s"] = exponents.get("s", 0) - 1
        return tuple(sorted((k, v) for k, v in exponents.items() if v)), unit[1]

    speeds: dict[int, int] = {}  # index of an angle copy -> index of its speed copy
    for a, (ca, ua) in enumerate(zip(copies, units, strict=True)):
        rate = per_second(ua)
        for v, (cv, uv) in enumerate(zip(copies, units, strict=True)):
            same_pair = cv[0][0] == ca[0][0] and cv[1][0] == ca[1][0]
            if v != a and same_pair and rate is not None and uv == rate:
                speeds[a] = v
    judged_as_speed = set(speeds.values())
    return [
        (c[0], c[1], copies[speeds[a]] if a in speeds else None)
        for a, c in enumerate(copies)
        if a not in judged_as_speed
    ]


def copied_inputs(system: Any) -> list[tuple[tuple[int, int], int, str]]:
    """The sampled Real inputs whose receiver reports its own copy at the step end (an
    output named after the input with ``_own``): (source slot, receiver, input name)."""
    found = []
    for c, src in zip(system.connections, system.connection_sources, strict=True):
        j = system.index[c.target[0]]
        model = system.models[j]
        if src is not None and c.target[1] in model.sampled:
            if c.target[1] + OWN_SUFFIX in model.variables:
                found.append((src, j, c.target[1]))
    return found


def judged_by_copies(system: Any) -> bool:
    """Whether some FMU of the system reports its own copy of a sampled input (the error
    measure the single pass needs to take long steps; ``input_hold = "auto"``)."""
    return bool(copied_inputs(system))


class SinglePassMaster(RegimeAwareMaster):
    """One pass of every FMU per macro step, inputs extrapolated; see the module doc."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        system = self.system
        # Every averaged signal is extrapolated (for the feeds); not every one is judged.
        self.extrapolation = InputExtrapolation(
            sorted({src for inputs in self.held_inputs for src, avg in inputs if avg})
        )
        self.first_order = False
        # FMUs that end a step at their first event: set them to do so, stepped first.
        self.early: list[int] = []
        self.reached_slot: dict[int, int] = {}
        for i, (inst, model) in enumerate(zip(system.instances, system.models, strict=True)):
            var = model.variables.get(EARLY_RETURN_INPUT)
            out = model.variables.get(REACHED_OUTPUT)
            if var is None or out is None or var.causality != "input":
                continue
            if any(c.target == (self.names[i], EARLY_RETURN_INPUT) for c in system.connections):
                continue  # the scene drives it
            inst.setter(inst.refs([EARLY_RETURN_INPUT]), integer=True)([1])
            self.early.append(i)
            self.reached_slot[i] = system.real_output_slot(i, REACHED_OUTPUT)
        # Step means: an output named after a connected one with "_mean" is its mean over
        # the last step, what a receiver stepped after it should hold.
        self.means: dict[tuple[int, int], int] = {}
        for c, src in zip(system.connections, system.connection_sources, strict=True):
            mean = c.source[1] + MEAN_SUFFIX
            if src is not None and mean in system.models[src[0]].variables:
                self.means[src] = system.real_output_slot(src[0], mean)
        givers = {s for s, _ in self.means}
        self.early.sort(key=lambda i: i not in givers)
        self.late = [i for i in range(len(self.names)) if i not in self.early]
        # Sampled inputs whose receiver reports its own copy at the step end (an output
        # named after the input with "_own"): (source, receiver's copy).  The copy
        # follows the held inputs, the source the true ones: their difference at the step
        # end is the coupling error the next step start discards.
        copied = copied_inputs(system)
        self.copies: list[Copy] = [
            (src, (j, system.real_output_slot(j, name + OWN_SUFFIX))) for src, j, name in copied
        ]
        units = [
            system.models[j].base_unit(system.models[j].variables[n].unit) for _, j, n in copied
        ]
        self.judged = angles_with_speeds(self.copies, units)
        # The held inputs of FMUs joined by such a copy are judged by it (their effect on
        # the motion, not the size of their change); the others by their extrapolation.
        covered = {j for (_, (j, _)) in self.copies} | {s[0] for (s, _) in self.copies}
        self.averaged = sorted(
            {
                src
                for i, inputs in enumerate(self.held_inputs)
                if i not in covered
                for src, avg in inputs
                if avg
            }
        )
        self.internal = False  # the last pass ended at an event that switched no regime
        self.returned: set[int] = set()  # FMUs that ended the last pass at their own event
        self.end_values: list[list[float]] = []
        self.rate: dict[tuple[int, int], float] = {}  # largest rate of a copied source
        self.last_step: dict[tuple[int | None, ...], float] = {}
        self.h_tried = 0.0  # the step the last pass was asked to take
        self.pass_do_steps = 0  # doSteps of the last pass

    # -- one pass -----------------------------------------------------------------------
    def feed_row(
        self, i: int, h: float, before: _Readings, done: set[int] = frozenset()
    ) -> list[float]:
        """FMU i's Real inputs for a step h from ``before``: held signals at the mean of
        their extrapolation, sampled ones at their start values, and from a source already
        stepped over this very step (``done``) that gives its step mean, that."""
        start, now = before.values, self.system.values
        ex, means = self.extrapolation, self.means
        row = []
        for (s, k), averaged in self.held_inputs[i]:
            mean = means.get((s, k)) if s in done else None
            if mean is not None:
                row.append(now[s][mean])
            elif averaged:
                row.append(ex.mean((s, k), start[s][k], h))
            else:
                row.append(start[s][k])
        return row

    def one_pass(self, t: float, h: float, before: _Readings, state: list[Any]) -> float:
        """Step every FMU once from t, those that end at their first event first (the
        ones that give step means before their receivers), each to where the earliest so
        far stopped, then the others there.  When one stops before an instant the ones
        before it were stepped to, those are stepped again from t to it.  Returns the
        step taken."""
        system = self.system
        do_steps = self.stats.do_steps
        h_end = h
        returned = self.returned = set()
        for round_ in range(MAX_ROUNDS):
            # The one that ended at its event is at the instant the others are stepped
            # again to: kept, with the inputs it had (the copy's mismatch judges them).
            done: set[int] = set(returned)
            again = False
            for i in self.early:
                if i in done:
                    continue
                if round_ > 0:
                    system.instances[i].set_state(state[i])
                    self.stats.rollbacks += 1
                system.feed(i, self.feed_row(i, h_end, before, done), before.ints)
                system.step(i, t, h_end)
                self.stats.do_steps += 1
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
            system.feed(i, self.feed_row(i, h_end, before, done), before.ints)
            system.step(i, t, h_end)
        self.stats.do_steps += len(self.late)
        for i in self.late:  # the early ones were read after their step
            system.read(i)
        # The values at the step end with the inputs of the step (an impact not yet taken):
        # what the error estimate compares the extrapolation with.
        self.end_values = list(system.values)  # read() replaces the inner lists
        self.system.exchange()
        self.pass_do_steps = self.stats.do_steps - do_steps
        return h_end

    def estimate(self, h: float, before: _Readings) -> float:
        """Error ratio of the step just taken: the extrapolated mean against the
        trapezoidal mean of each held signal's actual start and end values.  An FMU that
        ended its step at its own event has its outputs of after the event there (they
        jump at it): its signals are not compared on that step."""
        ex, tol = self.extrapolation, self.cfg.tolerance
        start, end = before.values, self.end_values
        returned = self.returned
        worst = 0.0
        for s in self.averaged:
            i, k = s
            if i in returned:
                continue
            a, b = start[i][k], end[i][k]
            scale = self.scale[s] = max(self.scale[s], abs(a), abs(b))  # from its nominal
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
            travel = max(abs(b - a), TRAVEL_FLOOR * rate * h)
            if travel > 0.0:
                miss = abs(end[j][k] - b)
                # The angle a speed mismatch moves the copy by; not when the source ended
                # the step at its own event (its speed jumps there: a handover's impact).
                if speed is not None and s[0] not in returned:
                    (vs, (vj, vk)) = speed
                    miss = max(miss, abs(end[vj][vk] - now[vs[0]][vs[1]]) * h)
                worst = max(worst, miss / (tol * travel))
        unannotated = self.error_ratio(before, self.unannotated) if self.unannotated else 0.0
        self.first_order = unannotated > worst or not ex.second_order
        return max(worst, unannotated)

    # -- one macro step (the execution loop calls it) ---------------------------------
    def step(self, t: float, stop: float) -> MacroStep:
        """One accepted pass from t: onto the first switch inside it (or the first event an
        FMU ended its step at), or as long as the error estimate allows."""
        cfg, system, stats = self.cfg, self.system, self.stats
        # Ends on an input signal's breakpoint; its hold error within the tolerance.
        h = system.signals.clip(t, min(self.h, stop - t), cfg.tolerance)
        state = system.get_state()
        before = self.readings()
        self.extrapolation.prepare(t, before.values)
        do_steps = stats.do_steps
        try:
            h, te, ratio = self._attempt(t, h, before, state)
        finally:
            system.free_state(state)
        end = t + h
        if te is None:
            self.extrapolation.accepted(t, before.values)
            self._note_changes(before)
            self.h = min(cfg.longest_step, max(cfg.min_step, h * self._grow(ratio)))
            self._remember_step(tuple(before.regimes), ratio, self.h)
            self.same_instant = 0
            # A regime that changed without a located switch changed at the step start.
            return MacroStep(end, h, changes_at=t, regimes_before=before.regimes)
        stats.iterations += self.settle() - 1
        changes = regime_changes(system, before.regimes, system.regimes())
        self._note_changes(before)
        if not self.internal:
            self._count_landing(stats.do_steps - do_steps)
        # An FMU that ended its step at an internal event (a friction sign or a branch: an
        # output jumps) with no regime change: landed on, not counted as a switch.
        internal_only = not changes and self.internal
        if internal_only:
            stats.extra["internal_events"] = stats.extra.get("internal_events", 0) + 1
        self.extrapolation.switched(self.internal)
        failure = self._chattering(h, end)
        if self.internal:
            # The rates go on: so does the step.
            self.h = min(cfg.longest_step, max(cfg.min_step, self.h_tried))
        else:
            self.h = self._restart_step(tuple(system.regimes()))
        return MacroStep(
            end,
            h,
            switched=not internal_only,
            regimes_before=before.regimes,
            failure=failure,
        )

    def _count_landing(self, do_steps: int) -> None:
        """Step statistics of the steps that ended on a switch: how many, their doSteps
        (rejected passes included) in all and at most."""
        extra = self.stats.extra
        extra["landings"] = extra.get("landings", 0) + 1
        extra["landing_do_steps"] = extra.get("landing_do_steps", 0) + do_steps
        extra["landing_do_steps_max"] = max(extra.get("landing_do_steps_max", 0), do_steps)
        extra["landing_pass_do_steps_max"] = max(
            extra.get("landing_pass_do_steps_max", 0), self.pass_do_steps
        )

    def _shrink(self, ratio: float) -> float:
        c = self.control
        if self.first_order:
            return c.shrink(ratio, True)
        return max(c.max_shrink, (c.safety_second_order / ratio) ** 0.5)

    def _grow(self, ratio: float) -> float:
        c = self.control
        if ratio == 0.0:
            return c.max_growth
        return min(c.max_growth, self._shrink(ratio) * GROWTH_SAFETY)

    def _remember_step(self, regimes: tuple[int | None, ...], ratio: float, h: float) -> None:
        """The step proposed last in these regimes (the restart after a switch into them)."""
        self.last_step[regimes] = h

    def _restart_step(self, regimes: tuple[int | None, ...]) -> float:
        """After a switch: a fraction of the step proposed last in the regimes entered (a
        too long one costs one pass), at least master.first_step."""
        remembered = self.last_step.get(regimes, 0.0) * RESTART
        return max(self.cfg.first_step, remembered)

    def _attempt(
        self, t: float, h: float, before: _Readings, state: list[Any]
    ) -> tuple[float, float | None, float]:
        """Passes from t until one is accepted: (h, switch time or None, error ratio)."""
        cfg, control = self.cfg, self.control
        last_ratio = None
        stalled = 0
        for _ in range(control.max_trials):
            h_full = self.h_tried = h
            h = self.one_pass(t, h, before, state)
            early = h < h_full
            switch = self.switch_time(t, h, before)
            te, window = switch.at, self._landing_window(switch.located)
            self.internal = False
            if early and (te is None or te >= t + h - window):
                self.internal = te is None
                te = t + h  # an FMU ended its step on its own event
            ratio = self.estimate(h, before)
            if te is not None:
                if t + h - te <= window or h <= cfg.min_step:
                    if ratio > 1.0 and h > cfg.min_step:
                        # The step onto the switch must pass the error test as well.
                        h = max(cfg.min_step, h * self._shrink(ratio))
                        self._rollback(state, before)
                        last_ratio = None
                        continue
                    return h, te, ratio
                h = max(te - t + 0.5 * cfg.event_tolerance, cfg.min_step)
                self._rollback(state, before)
                last_ratio = None
                continue
            if ratio > 1.0 and h > cfg.min_step:
                as_large = last_ratio is not None and ratio > control.jump_ratio * last_ratio
                stalled = stalled + 1 if as_large else 0
                if stalled >= control.jump_shrinks:
                    self.stats.extra["jumps"] = self.stats.extra.get("jumps", 0) + 1
                    return h, t + h, ratio
                last_ratio = ratio
                h = max(cfg.min_step, h * self._shrink(ratio))
                self._rollback(state, before)
                continue
            return h, None, ratio
        raise RunError(
            f"no acceptable step from here after {control.max_trials} trials (last h = {h:.3e} s)",
            t,
        )
