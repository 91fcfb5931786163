"""The regime-aware master: steps that land on every regime switch, sized by an error test.

Each macro step starts from a saved state of every FMU (fmi2GetFMUstate), so any trial can
be rolled back.  How a trial step is taken and its error estimated is the trial scheme's
(``input_hold``): the midpoint hold's predictor and corrector (masters/midpoint_trial.py),
or the single pass (masters/single_pass.py).  Whatever the scheme, a trial is accepted when

* it switched nowhere inside it (no FMU changed regime, fired an internal event or crossed
  an event indicator), or it ends on the switch (masters/switches.py) — otherwise it is
  retaken to end just past the switch; and
* its coupling error estimate is within ``tolerance`` — otherwise it is retaken shorter
  (a step onto a switch too: the held-input error at an impact is the speed mismatch of
  the two sides, hence the energy).  A change that two shrinks in a row leave as large is
  a jump (an input signal's discontinuity without a reported event): the step containing
  it is accepted as a switch.

After a switch the master iterates the exchange at that instant to a fixed point (so an
impact's momentum exchange reaches the other FMU before anything moves), records the left
and right values, logs the switch, and restarts with a short step (``master.first_step``,
or the scheme's remembered step for the regimes entered).  A guard stops runs that keep
switching at one instant (chattering / Zeno) with a diagnosis.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, NamedTuple, Protocol

from orchestrator.errors import RunError
from orchestrator.master_settings import RegimeAwareSettings
from orchestrator.masters.held_back import HeldBack
from orchestrator.masters.macro_step import MacroStep
from orchestrator.masters.switches import (
    ChatteringGuard,
    Landing,
    StepStart,
    Switch,
    back_to_start,
    read,
    settle,
)
from orchestrator.recorder import StepStats
from orchestrator.system import CoupledSystem


@dataclass
class RegimeAwareStats(StepStats):
    """The regime-aware master's statistics: the counters, its scheme and its own counts."""

    input_hold: str | None = None  # the scheme that ran ("auto" resolved)
    landings: int = 0  # steps that ended on a switch (single pass)
    landing_do_steps: int = 0  # their doSteps, rejected passes included
    landing_do_steps_max: int = 0  # ... at most in one
    landing_pass_do_steps_max: int = 0  # the doSteps of the accepted pass, at most
    internal_events: int = 0  # steps that ended at an FMU's own event and switched nothing
    jumps: int = 0  # changes that shrinking the step left as large: landed on as switches
    #: FMUs not rolled back, their restore faulty (masters/held_back.py)
    not_rolled_back: list[str] = field(default_factory=list)

    def choices(self) -> dict[str, Any]:
        return {} if self.input_hold is None else {"input_hold": self.input_hold}

    #: the counts in the order each first happened (the summary's order)
    seen: dict[str, None] = field(default_factory=dict, repr=False)

    def landed(self, do_steps: int, pass_do_steps: int) -> None:
        """A step ended on a switch: ``do_steps`` in all, the accepted pass's among them."""
        self.seen.setdefault("landings")
        self.landings += 1
        self.landing_do_steps += do_steps
        self.landing_do_steps_max = max(self.landing_do_steps_max, do_steps)
        self.landing_pass_do_steps_max = max(self.landing_pass_do_steps_max, pass_do_steps)

    def internal_event(self) -> None:
        self.seen.setdefault("internal_events")
        self.internal_events += 1

    def jump(self) -> None:
        self.seen.setdefault("jumps")
        self.jumps += 1

    def counts(self) -> dict[str, Any]:
        groups = {
            "landings": ("landings", "landing_do_steps", "landing_do_steps_max",
                         "landing_pass_do_steps_max"),
            "internal_events": ("internal_events",),
            "jumps": ("jumps",),
        }  # fmt: skip
        d: dict[str, Any] = {k: getattr(self, k) for g in self.seen for k in groups[g]}
        if self.not_rolled_back:
            d["not_rolled_back"] = list(self.not_rolled_back)
        return d


class Estimate(NamedTuple):
    """Error estimate of a trial step relative to the tolerance (<= 1 accepts)."""

    ratio: float
    first_order: bool  # its order in h (sets how far the step shrinks or grows)


@dataclass(frozen=True)
class Trial:
    """One trial step from the step start, as its scheme took it."""

    h: float  # the step it reached (the single pass may stop early, at an FMU's event)
    h_asked: float  # the step it was asked to take
    switch: Switch | None  # the earliest switch inside it (or the event it stopped at)
    estimate: Estimate | None  # its error estimate (None: not needed to accept or reject it)
    do_steps: int  # doSteps it took
    #: it stopped at an FMU's own event that switched no regime (a friction sign): the
    #: rates go on, and so does the step
    internal: bool = False
    #: the end values its corrector averaged toward (midpoint hold: to retake the step)
    predicted: list[list[float]] | None = None
    #: the recorded values just before its switch, taken on the way (midpoint hold)
    left_row: list[float] | None = None


class TrialScheme(Protocol):
    """How trial steps are taken and judged (the midpoint hold, the single pass)."""

    growth_safety: float  # the step grows this much less than the estimate allows
    next_step_floor: float  # the shortest step proposed after an accepted one
    restart: RestartSteps  # the step after a switch

    def begin(self, start: StepStart) -> None:
        """A macro step starts here."""

    def trial(self, h: float, start: StepStart) -> Trial:
        """One trial step of h from ``start`` (the FMUs are there)."""

    def left_row(self, accepted: Trial, switch_at: float, start: StepStart) -> list[float] | None:
        """The recorded values just before the switch the accepted trial ends on; the
        FMUs end at the trial's end."""

    def accepted(self, start: StepStart) -> None:
        """The trial from ``start`` was accepted without a switch."""

    def switched(self, accepted: Trial, do_steps: int) -> None:
        """The accepted trial ended on a switch (``do_steps``: the macro step's)."""

    def end(self) -> None:
        """The macro step is over (free what it kept)."""


#: Makes a trial scheme: (system, settings, statistics, landing) -> TrialScheme.
SchemeFactory = Callable[
    [CoupledSystem, RegimeAwareSettings, "RegimeAwareStats", Landing], TrialScheme
]


class RestartSteps:
    """The first step after a switch, per combination of regimes entered: a ``fraction`` of
    the step proposed there before, at least master.first_step.  With ``zero_error_only``
    a step is remembered only while every accepted step in those regimes had exactly zero
    coupling error (the largest such), else the last one proposed."""

    def __init__(self, first_step: float, fraction: float, zero_error_only: bool) -> None:
        self.first_step, self.fraction, self.zero_error_only = first_step, fraction, zero_error_only
        self.remembered: dict[tuple[int | None, ...], float] = {}

    def remember(self, regimes: tuple[int | None, ...], ratio: float, h: float) -> None:
        """The step ``h`` proposed after one accepted in ``regimes`` with error ``ratio``."""
        if not self.zero_error_only:
            self.remembered[regimes] = h
        elif ratio == 0.0:
            self.remembered[regimes] = max(h, self.remembered.get(regimes, 0.0))
        else:
            self.remembered.pop(regimes, None)

    def step(self, regimes: tuple[int | None, ...]) -> float:
        """The first step after a switch into ``regimes``."""
        return max(self.first_step, self.remembered.get(regimes, 0.0) * self.fraction)


class RegimeAwareMaster:
    """Accepts, rejects and lands the trials of one scheme; see the module doc."""

    name = "regime-aware"

    def __init__(
        self,
        settings: RegimeAwareSettings,
        system: CoupledSystem,
        trials: SchemeFactory,
    ) -> None:
        """``trials`` makes the trial scheme (masters/midpoint_trial.py, single_pass.py) at
        the start."""
        self.system, self.settings, self.trials = system, settings, trials
        self.stats = RegimeAwareStats()
        self.h = settings.first_step  # the step the next macro step tries first
        self.scheme: TrialScheme | None = None  # made at the start (it reads the FMUs)
        self.landing = Landing.of(settings)
        self.guard = ChatteringGuard(system, self.landing.instant, settings.max_events_per_step)
        #: foreign FMUs whose restore does not reproduce their state: not rolled back
        self.held_back = HeldBack(system, settings, self.stats)
        self.stats.not_rolled_back = self.held_back.names

    def setup(self) -> None:
        """The single pass asks its FMUs to integrate below its own tolerance; the midpoint
        hold leaves them at theirs (their validated numbers stay as they are)."""
        if self.settings.single_pass:
            self.system.tolerance = self.settings.single_pass_control.fmu_tolerance(
                self.settings.tolerance
            )

    def start(self, t: float, stop: float) -> None:
        """Check the foreign FMUs' restores, then make the trial scheme."""
        self.held_back.start(t)
        self.stats.input_hold = self.settings.input_hold
        self.scheme = self.trials(self.system, self.settings, self.stats, self.landing)

    def step(self, t: float, stop: float) -> MacroStep:
        """One accepted macro step from t: onto the first switch inside it (then the
        exchange there is settled), or as long as the error test allows."""
        self.held_back.check(t)
        cfg, system, stats, scheme = self.settings, self.system, self.stats, self.scheme
        # Ends on an input signal's breakpoint; its hold error within the tolerance.
        h = system.signals.clip(t, min(self.h, stop - t), cfg.tolerance)
        start = StepStart(t, system.get_state(), read(system))  # every trial ends refreshed
        before = start.before
        scheme.begin(start)
        do_steps = stats.do_steps
        try:
            trial, switch_at = self._attempt(h, start)
            left = None if switch_at is None else scheme.left_row(trial, switch_at, start)
        finally:
            system.free_state(start.state)
            scheme.end()
        h = trial.h
        end = t + h
        # The FMUs not rolled back take their one step now; their change bounds the next.
        bound = self.held_back.step(t, h, before)
        if switch_at is None:
            ratio, first_order = trial.estimate
            scheme.accepted(start)
            self.guard.note_changes(before)
            grown = h * cfg.control.grow(ratio, first_order, scheme.growth_safety)
            self.h = min(cfg.longest_step, max(scheme.next_step_floor, grown), bound)
            scheme.restart.remember(tuple(before.regimes), ratio, self.h)
            self.guard.smooth_step()
            # A regime that changed without a located switch changed at the step start.
            return MacroStep(end, h, changes_at=t, regimes_before=before.regimes)
        if system.signals and system.signals.jump_at(end):
            system.jump_signals(end)  # held over the step, the signal jumps at its end
        stats.iterations += settle(system, cfg.max_iterations) - 1
        changes = self.guard.note_changes(before)
        scheme.switched(trial, stats.do_steps - do_steps)
        # An FMU that ended its step at an internal event (a friction sign or a branch: an
        # output jumps) with no regime change: landed on, not counted as a switch.
        internal_only = trial.internal and not changes
        if internal_only:
            stats.internal_event()
        failure = self.guard.switch_step(h, end)
        if trial.internal:
            # The rates go on: so does the step.
            self.h = min(cfg.longest_step, max(cfg.min_step, trial.h_asked), bound)
        else:
            self.h = min(scheme.restart.step(tuple(system.regimes())), bound)
        return MacroStep(
            end,
            h,
            switched=not internal_only,
            regimes_before=before.regimes,
            left_row=left,  # values just before the switch
            failure=failure,
        )

    def _attempt(self, h: float, start: StepStart) -> tuple[Trial, float | None]:
        """Trial steps from the step start until one is accepted: it, and the switch it
        ends on (None: none)."""
        cfg, control, landing = self.settings, self.settings.control, self.landing
        t = start.t
        last_ratio = None
        stalled = 0
        for _ in range(control.max_trials):
            trial = self.scheme.trial(h, start)
            h, switch, estimate = trial.h, trial.switch, trial.estimate
            if switch is not None:
                if landing.lands(t, h, switch):
                    ratio = estimate.ratio if estimate is not None else 0.0
                    if ratio > 1.0 and h > cfg.min_step:
                        # The step onto the switch must pass the error test as well.
                        h = max(cfg.min_step, h * control.shrink(ratio, estimate.first_order))
                        self._reject(start)
                        last_ratio = None
                        continue
                    return trial, switch.at
                # End the retaken step just past the switch.
                h = max(switch.at - t + 0.5 * cfg.event_tolerance, cfg.min_step)
                self._reject(start)
                last_ratio = None
                continue
            ratio, first_order = estimate
            if ratio > 1.0 and h > cfg.min_step:
                # Two shrinks in a row that leave the change as large: a jump, not a smooth
                # change (one shrink is not proof: a long step may span an oscillation).
                as_large = last_ratio is not None and ratio > control.jump_ratio * last_ratio
                stalled = stalled + 1 if as_large else 0
                if stalled >= control.jump_shrinks:
                    self.stats.jump()
                    # Land after the jump and treat it as a switch.
                    return trial, t + h
                last_ratio = ratio
                h = max(cfg.min_step, h * control.shrink(ratio, first_order))
                self._reject(start)
                continue
            return trial, None
        raise RunError(
            f"no acceptable step from here after {control.max_trials} trials (last h = {h:.3e} s)",
            t,
        )

    def _reject(self, start: StepStart) -> None:
        """Back to the step start after a rejected trial."""
        back_to_start(self.system, start)
        self.stats.rollbacks += 1
        self.stats.rejections += 1
