"""Master settings: one typed dataclass per master, with its defaults and checks.

A scene's ``[master]`` table is read into the settings of its algorithm here and nowhere
else.  Every key a scene may write is a field of some master's settings, declared with
``setting`` (its kind: an SI quantity, a positive count or one of a few words); the
scenario loader only converts what the scene wrote into those kinds.  A key that another
master uses is accepted and ignored (``--set master.algorithm=jacobi`` on a regime-aware
scene keeps working).

Each master reads its step from its own key: ``master.step`` is the macro step of the
fixed-step masters, ``master.first_step`` the regime-aware master's first step (and the
step after a switch).  A scene that gives only the other master's key (one switched with
``--set master.algorithm=...``) lends it: Jacobi on a regime-aware scene steps at its
first step, the regime-aware master on a Jacobi scene starts at its macro step.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, ClassVar, Protocol

#: Keys every master has; the others are its step (its settings' STEP_KEY) and fields of
#: its settings.
COMMON_KEYS = ("algorithm", "order")
#: The smallest master.tolerance taken: relative coupling errors of 1e-12 over steps of
#: 1e-14 s (master.min_step's default) are already near double precision's 2.2e-16.
MIN_TOLERANCE = 1e-12
#: The largest: an error as large as the quantity itself controls nothing.
MAX_TOLERANCE = 1.0
#: Settings where 0 means "none" rather than being out of range.
OFF_AT_ZERO = ("call_timeout",)
#: How long one FMI call may take before the run's supervisor ends it [s] (README, "A
#: crashing FMU"): an FMU stuck in an endless loop ends its run "timed out".
CALL_TIMEOUT = 60.0


class SettingError(ValueError):
    """A master setting out of range: ``key`` (without ``master.``) and what is wrong."""

    def __init__(self, key: str, message: str) -> None:
        super().__init__(message)
        self.key = key


@dataclass(frozen=True)
class SettingKind:
    """How a scene writes a setting: a quantity in ``unit``, a count, or a word."""

    unit: str | None = None  # SI unit of a quantity ("1" for a plain number)
    choices: tuple[str, ...] = ()  # the words it takes

    @property
    def is_count(self) -> bool:
        return self.unit is None and not self.choices


def setting(default: Any, unit: str | None = None, choices: tuple[str, ...] = ()) -> Any:
    """A field a scene may set as ``master.<name>`` (no unit and no choices: a count)."""
    return field(default=default, metadata={"kind": SettingKind(unit, choices)})


def kinds_of(cls: type) -> dict[str, SettingKind]:
    return {f.name: f.metadata["kind"] for f in dataclasses.fields(cls) if "kind" in f.metadata}


class Settings(Protocol):
    """What every master's settings are: a frozen dataclass read from the scene."""

    STEP_KEY: ClassVar[str]  # the key the master reads its step from
    call_timeout: float  # read by the run's supervisor

    @classmethod
    def from_options(
        cls, step: float, duration: float, options: dict[str, Any], fixed_step: float
    ) -> Settings:
        """The settings of a scene: its step (its own key, else the one it lends), the run's
        duration, the options read_options gives, and the fixed step (master.step, else
        the step the scene gives)."""


def as_record(settings: Any) -> dict[str, Any]:
    """Every field of ``settings`` as it ran, nested controls included (for the summary)."""
    return dataclasses.asdict(settings)


@dataclass(frozen=True)
class FixedStepSettings:
    """Jacobi and Gauss–Seidel: one macro step, nothing else to set."""

    STEP_KEY: ClassVar[str] = "step"
    step: float  # master.step: the macro step [s]
    call_timeout: float = setting(CALL_TIMEOUT, "s")  # 0: no limit (read by the supervisor)

    @classmethod
    def from_options(
        cls, step: float, duration: float, options: dict[str, Any], fixed_step: float = 0.0
    ) -> FixedStepSettings:
        return cls(step, **{k: v for k, v in options.items() if k in kinds_of(cls)})


@dataclass(frozen=True)
class MasterStepControl:
    """The regime-aware master's step-size controller: its constants, named, each with the
    reason for its value (the measurements behind them: docs/measurements.md)."""

    max_growth: float = 4.0  # largest factor a step grows by after an accepted one
    max_shrink: float = 0.2  # smallest factor a rejected step shrinks by
    safety_first_order: float = 0.9  # factor = safety / ratio for a first-order estimate
    safety_second_order: float = 0.8  # factor = (safety / ratio) ** 0.5 for second order
    max_trials: int = 200  # trials from one instant before the run is given up
    jump_shrinks: int = 2  # shrinks in a row that leave the change as large: a jump
    jump_ratio: float = 0.5  # "as large": the ratio fell by less than this factor
    event_time_slack: float = 1e-12  # relative: a reported event time this past the end counts
    settle_window: float = 10.0  # switches within this many event tolerances: one instant
    # Midpoint hold: restart in regimes of zero coupling error at this fraction of their step.
    zero_error_restart: float = 0.25

    def factor(self, ratio: float, first_order: bool) -> float:
        """Step factor for an error ratio: the held-start estimate is first order in h,
        the predictor's error (midpoint hold) second order."""
        if first_order:
            return self.safety_first_order / ratio
        return (self.safety_second_order / ratio) ** 0.5

    def shrink(self, ratio: float, first_order: bool) -> float:
        """Factor for a rejected step (never below ``max_shrink``)."""
        return max(self.max_shrink, self.factor(ratio, first_order))

    def grow(self, ratio: float, first_order: bool, safety: float = 1.0) -> float:
        """Factor for the step after an accepted one (between the two bounds), ``safety``
        times less than the estimate allows."""
        if ratio == 0.0:
            return self.max_growth
        return min(self.max_growth, self.shrink(ratio, first_order) * safety)


@dataclass(frozen=True)
class SinglePassControl:
    """The single pass's own constants (masters/single_pass.py), each with its reason (the
    measurements behind them: docs/measurements.md)."""

    # The next step is this times what the estimate allows: a too long pass is retaken whole.
    growth_safety: float = 0.8
    # Restart after a switch at this fraction of the last step proposed in the regimes entered.
    restart: float = 0.25
    # Previous points of the input extrapolation: linear; quadratic had several times the error.
    extrapolation_points: int = 1
    # Passes over one step when FMUs that end at their first event stop before one another.
    early_return_rounds: int = 4
    # A copied source travels at least this fraction of its fastest travel (one at rest too).
    travel_floor: float = 0.1
    # FMUs integrate to this fraction of the coupling tolerance: below its error, not far below.
    fmu_tolerance_fraction: float = 0.1
    # ... at most this: integrated at 5e-5 or looser the escapement leaves its path.
    fmu_tolerance_max: float = 1e-5

    def fmu_tolerance(self, tolerance: float) -> float:
        """The integration tolerance asked of the FMUs for a coupling ``tolerance``."""
        return min(self.fmu_tolerance_max, self.fmu_tolerance_fraction * tolerance)


@dataclass(frozen=True)
class RegimeAwareSettings:
    """Error-controlled steps that land on every regime switch (masters/regime_aware.py)."""

    STEP_KEY: ClassVar[str] = "first_step"
    first_step: float  # master.first_step: the first step, and the step after a switch [s]
    tolerance: float = setting(1e-4, "1")  # coupling error per step, relative to scale
    event_tolerance: float = setting(1e-10, "s")  # how closely a step lands on a switch
    min_step: float = setting(1e-14, "s")
    max_step: float | None = setting(None, "s")  # None: the scheme's own (longest_step)
    max_iterations: int = setting(10)  # exchange rounds at a switching instant
    max_events_per_step: int = setting(50)  # switches at (nearly) one instant: chattering
    input_hold: str = setting("auto", choices=("auto", "start", "midpoint", "extrapolated"))
    call_timeout: float = setting(CALL_TIMEOUT, "s")  # 0: no limit (read by the supervisor)
    control: MasterStepControl = MasterStepControl()
    single_pass_control: SinglePassControl = SinglePassControl()
    run_duration: float = math.inf  # not a scene key: the run's length (longest_step)
    #: not a scene key: the macro step of the Jacobi run where rollbacks are impossible
    #: (master.step, else first_step)
    fixed_step: float = 0.0

    @property
    def midpoint(self) -> bool:
        """Corrector with held inputs at their step mean (else held at the step start);
        ``"auto"`` is resolved to a scheme before a master is made of these settings."""
        return self.input_hold == "midpoint"

    @property
    def longest_step(self) -> float:
        """master.max_step, else the scheme's own, at most the run: the midpoint hold's
        (and "auto" before it is resolved) 100 first steps; the single pass's the run, as
        its steps end at the first event of an FMU that returns early and its copies'
        mismatch holds them to the tolerance: a cap tied to the first step only adds
        passes."""
        if self.max_step is not None:
            return self.max_step
        if self.single_pass:
            return self.run_duration
        return min(100.0 * self.first_step, self.run_duration)

    def jacobi(self) -> FixedStepSettings:
        """The fixed-step Jacobi run instead where the FMUs cannot be rolled back."""
        return FixedStepSettings(self.fixed_step, self.call_timeout)

    def jacobi_words(self) -> str:
        """That Jacobi run, in words."""
        return (
            f"fixed-step Jacobi in steps of {self.fixed_step:g} s (no error control, switches "
            "seen only at communication points)"
        )

    @property
    def single_pass(self) -> bool:
        """One pass per macro step with extrapolated inputs (masters/single_pass.py)."""
        return self.input_hold == "extrapolated"

    @classmethod
    def from_options(
        cls, step: float, duration: float, options: dict[str, Any], fixed_step: float = 0.0
    ) -> RegimeAwareSettings:
        """The settings of a scene: ``options`` as read_options gives them, the rest
        defaults."""
        values = {k: v for k, v in options.items() if k in kinds_of(cls)}
        fixed = fixed_step or step
        settings = cls(first_step=step, run_duration=duration, fixed_step=fixed, **values)
        if settings.tolerance < MIN_TOLERANCE:
            raise SettingError(
                "tolerance",
                f"must be at least {MIN_TOLERANCE:g} (a smaller one asks for steps below the "
                f"resolution of the time in double precision), got {settings.tolerance:g}",
            )
        if settings.tolerance > MAX_TOLERANCE:
            raise SettingError(
                "tolerance",
                f"must be at most {MAX_TOLERANCE:g} (an error as large as the quantity "
                f"controls nothing), got {settings.tolerance:g}",
            )
        if "min_step" in options and settings.min_step > step:
            raise SettingError(
                "min_step", f"{settings.min_step:g} s is longer than the first step ({step:g} s)"
            )
        return settings


def read_options(
    node: dict[str, Any],
    to_si: Callable[[Any, str, str], float],
    kinds: dict[str, SettingKind],
) -> dict[str, Any]:
    """The settings a scene's [master] table writes, checked and in SI: those of ``kinds``
    (every master's, orchestrator/masters/registry.py).

    ``to_si(raw, key, unit)`` converts a quantity (and reports a bad one itself); a value
    of the wrong kind or out of range raises SettingError.
    """
    options: dict[str, Any] = {}
    for k, kind in kinds.items():
        if k not in node:
            continue
        raw = node[k]
        if kind.choices:
            if raw not in kind.choices:
                raise SettingError(k, f"expected one of {list(kind.choices)}, got {raw!r}")
            options[k] = raw
        elif kind.is_count:
            if not isinstance(raw, int) or isinstance(raw, bool) or raw < 1:
                raise SettingError(k, f"expected a positive integer, got {raw!r}")
            options[k] = raw
        else:
            value = to_si(raw, f"master.{k}", kind.unit)
            if k in OFF_AT_ZERO and value == 0.0:
                pass
            elif not value > 0.0:
                off = " (0 for none)" if k in OFF_AT_ZERO else ""
                raise SettingError(k, f"must be positive{off}, got {value}")
            options[k] = value
    low, high = options.get("min_step"), options.get("max_step")
    if low is not None and high is not None and high < low:
        raise SettingError("max_step", f"{high:g} s is less than master.min_step ({low:g} s)")
    return options
