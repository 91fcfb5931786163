"""Inputs that vary in time: tables, CSV files, steps and ramps driving an FMU input.

A signal is a table of (time, value) rows in SI.  Between rows it is linear or held; a
time written twice is a jump (the first row is the value just before, the second the
value at and after that time, as FMPy reads an input table); outside its span it holds
its end values.  Jumps and kinks are *breakpoints*: instants every master ends a macro
step on.  Between breakpoints an FMU is given the signal's value at the step start.

The scene forms (keys of one entry of ``[fmus.<instance>].inputs``)::

    u = { table = [["0 s", 0.0], ["1 ms", 1.0]], interpolation = "hold" }
    u = { file = "torque.csv", column = "tau", interpolation = "linear", outside = "error" }
    u = { step = "1 ms", from = 0.0, to = "2 N*m" }
    u = { ramp = ["0 s", "10 ms"], from = 0.0, to = "2 N*m" }
"""

from __future__ import annotations

import bisect
import csv
import hashlib
import math
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from orchestrator.errors import ScenarioError
from orchestrator.regular_files import CSV_LIMIT, NotARegularFile, read_regular
from orchestrator.units import pint_unit, ureg

INTERPOLATIONS = ("linear", "hold")
OUTSIDE = ("hold", "error")
#: keys of each form; the form is told by the one of table/file/step/ramp present
FORMS = {
    "table": {"table", "interpolation", "outside"},
    "file": {"file", "column", "interpolation", "outside"},
    "step": {"step", "from", "to"},
    "ramp": {"ramp", "from", "to"},
}
#: shorthand keys a sweep or study may set ("fmus.c.inputs.u_s.to"), and what they hold
SETTABLE = {"step": "time", "from": "value", "to": "value"}
#: rows closer than this (relative to the time, at least 1 s scale) and not equal are
#: refused: write the time twice for a jump.  Also how close a master's time must be to
#: a breakpoint to be taken as on it (floating-point sums of steps miss it by ulps).
SNAP = 1e-12


def _snap_tolerance(t: float) -> float:
    return SNAP * max(1.0, abs(t))


def _snap(breaks: list[float], t: float) -> float:
    """``t``, or the breakpoint in ``breaks`` (sorted) it is within rounding of."""
    k = bisect.bisect_left(breaks, t)
    for j in (k - 1, k):
        if 0 <= j < len(breaks) and abs(breaks[j] - t) <= _snap_tolerance(t):
            return breaks[j]
    return t


@dataclass(frozen=True)
class Signal:
    """A table of (time, value) rows in SI, with its interpolation and its origin."""

    times: tuple[float, ...]
    values: tuple[float, ...]
    interpolation: str = "linear"
    outside: str = "hold"
    #: how the scene wrote it, for provenance: form, and file and sha256 of a CSV
    source: dict[str, Any] = field(default_factory=dict)
    #: SI values of the shorthand keys (step/from/to), the nominal of a study
    settings: dict[str, float] = field(default_factory=dict)

    def __post_init__(self) -> None:
        breaks, jumps = _breakpoints(self.times, self.values, self.interpolation)
        object.__setattr__(self, "_breaks", breaks)
        object.__setattr__(self, "_jumps", frozenset(jumps))

    # -- values -----------------------------------------------------------------------
    def snap(self, t: float) -> float:
        """``t``, or the breakpoint it is within floating-point rounding of."""
        return _snap(self._breaks, t)

    def value(self, t: float, left: bool = False) -> float:
        """The value at t (at a jump, the value after it; ``left``: the value before)."""
        ts, vs = self.times, self.values
        t = self.snap(t)
        if left:
            if t <= ts[0]:
                return vs[0]
            if t > ts[-1]:
                return vs[-1]
            i = bisect.bisect_left(ts, t)  # ts[i-1] < t <= ts[i]
            if self.interpolation == "hold" or t == ts[i]:
                return vs[i - 1] if self.interpolation == "hold" else vs[i]
            return _lerp(ts[i - 1], vs[i - 1], ts[i], vs[i], t)
        if t < ts[0]:
            return vs[0]
        if t >= ts[-1]:
            return vs[-1]
        i = bisect.bisect_right(ts, t) - 1  # ts[i] <= t < ts[i+1]
        if self.interpolation == "hold" or t == ts[i]:
            return vs[i]
        return _lerp(ts[i], vs[i], ts[i + 1], vs[i + 1], t)

    def slope(self, t: float) -> float:
        """d value / dt just after t (0 where held, and outside the span)."""
        ts, vs = self.times, self.values
        t = self.snap(t)
        if self.interpolation == "hold" or t < ts[0] or t >= ts[-1]:
            return 0.0
        i = bisect.bisect_right(ts, t) - 1
        return (vs[i + 1] - vs[i]) / (ts[i + 1] - ts[i])

    # -- breakpoints ------------------------------------------------------------------
    def breakpoints(self, t0: float = -math.inf, t1: float = math.inf) -> list[float]:
        """Jumps and kinks in [t0, t1]."""
        breaks = self._breaks
        return list(breaks[bisect.bisect_left(breaks, t0) : bisect.bisect_right(breaks, t1)])

    def next_breakpoint(self, t: float) -> float | None:
        """The first breakpoint later than t (t on a breakpoint: the one after it)."""
        t = self.snap(t)
        k = bisect.bisect_right(self._breaks, t)
        return self._breaks[k] if k < len(self._breaks) else None

    def is_jump(self, t: float) -> bool:
        return self.snap(t) in self._jumps

    @property
    def jumps(self) -> list[float]:
        return sorted(self._jumps)

    @property
    def scale(self) -> float:
        """The largest magnitude the signal takes."""
        return max(abs(v) for v in self.values)

    @property
    def span(self) -> tuple[float, float]:
        return self.times[0], self.times[-1]

    def as_linear_table(self) -> tuple[list[float], list[float]]:
        """The same signal as a linearly interpolated table with repeated times at jumps
        (how FMPy's ``simulate_fmu(input=...)`` and a libcosim scenario read it)."""
        if self.interpolation == "linear":
            return list(self.times), list(self.values)
        times, values = [self.times[0]], [self.values[0]]
        for t, v in zip(self.times[1:], self.values[1:], strict=True):
            if v != values[-1]:
                times += [t, t]
                values += [values[-1], v]
        if times[-1] != self.times[-1]:
            times.append(self.times[-1])
            values.append(values[-1])
        return times, values


def _lerp(t0: float, v0: float, t1: float, v1: float, t: float) -> float:
    return v0 + (v1 - v0) * ((t - t0) / (t1 - t0))


def _breakpoints(
    ts: tuple[float, ...], vs: tuple[float, ...], interpolation: str
) -> tuple[list[float], list[float]]:
    """(every jump and kink, the jumps) of a table, in time order."""
    jumps = []
    kinks = []
    n = len(ts)
    if interpolation == "hold":
        jumps = [ts[i] for i in range(1, n) if vs[i] != vs[i - 1]]
        return sorted(set(jumps)), jumps
    slopes = [0.0]  # held before the first row
    for i in range(n - 1):
        if ts[i + 1] == ts[i]:
            slopes.append(math.nan)  # a jump
        else:
            slopes.append((vs[i + 1] - vs[i]) / (ts[i + 1] - ts[i]))
    slopes.append(0.0)  # held after the last row
    for i in range(n):
        before, after = slopes[i], slopes[i + 1]
        if math.isnan(after):
            if vs[i + 1] != vs[i]:
                jumps.append(ts[i])
        elif math.isnan(before):
            continue
        elif before != after:
            kinks.append(ts[i])
    return sorted(set(jumps) | set(kinks)), jumps


# -- reading a scene entry ------------------------------------------------------------
class Reader:
    """What the scene loader gives to read one signal: its messages and unit conversion."""

    def __init__(
        self,
        scene_path: Path,
        fail: Callable[[str, str], ScenarioError],
        quantity: Callable[[Any, str, str], float],
    ) -> None:
        self.scene_path, self.fail, self.quantity = scene_path, fail, quantity


def is_signal(raw: Any) -> bool:
    """A scene input entry is a signal when it is a table (a constant is a value)."""
    return isinstance(raw, dict)


def merge_signal_overrides(node: dict[str, Any], declared: set[str]) -> dict[str, Any]:
    """Fold keys such as ``u_s.to`` (set by --set, a sweep or a study) into the signal
    table of input ``u_s``; a declared variable's own dotted name stays as it is."""
    out = dict(node)
    for key in list(out):
        if key in declared or "." not in key:
            continue
        name, sub = key.rsplit(".", 1)
        if name in declared and is_signal(out.get(name)):
            out[name] = {**out[name], sub: out.pop(key)}
    return out


def split_signal_key(declared: set[str], name: str) -> tuple[str, str] | None:
    """('u_s', 'to') for a shorthand key ``u_s.to`` of a declared input, else None."""
    if name in declared or "." not in name:
        return None
    var, sub = name.rsplit(".", 1)
    return (var, sub) if var in declared and sub in SETTABLE else None


def signal_setting(spec: Any, name: str) -> tuple[str, str, Signal] | None:
    """(input, key, signal) when ``name`` is a shorthand key of one of the FmuSpec's
    signals (``u_s.to``), else None."""
    declared = {v.name for v in spec.model.of("input")}
    split = split_signal_key(declared, name)
    if split is None or split[0] not in spec.signals:
        return None
    return split[0], split[1], spec.signals[split[0]]


def read_signal(
    reader: Reader, raw: dict[str, Any], key: str, var: Any, span: tuple[float, float]
) -> Signal:
    """The signal an input entry describes, checked against the FMU input ``var`` (its
    type, unit and min/max) and the run's (start, stop)."""
    if var.type != "Real":
        raise reader.fail(key, f"a signal drives a Real input; {var.name!r} is {var.type}")
    forms = [f for f in FORMS if f in raw]
    if len(forms) != 1:
        raise reader.fail(
            key,
            "expected exactly one of 'table' (rows of [time, value]), 'file' (a CSV file), "
            f"'step' or 'ramp'; got keys {sorted(raw)}",
        )
    form = forms[0]
    unknown = sorted(set(raw) - FORMS[form])
    if unknown:
        raise reader.fail(
            f"{key}.{unknown[0]}",
            f"unknown key for a {form}; expected one of {sorted(FORMS[form])}",
        )
    unit = var.unit or "1"
    interpolation = _choice(reader, raw, key, "interpolation", INTERPOLATIONS)
    outside = _choice(reader, raw, key, "outside", OUTSIDE)
    settings: dict[str, float] = {}
    source: dict[str, Any] = {"form": form}
    where: Path = reader.scene_path
    if form == "table":
        times, values, rows = _table(reader, raw["table"], f"{key}.table", unit)
        row_key = [f"{key}.table[{r}]" for r in rows]
        row_text = [""] * len(rows)  # the key names the row
    elif form == "file":
        where, times, values, lines, digest, column, note = _csv(reader, raw, key, var)
        source.update(file=str(where), sha256=digest, column=column)
        source.update({"units": note} if note else {})
        row_key = [f"{key}.file"] * len(lines)
        row_text = [f"line {n}" for n in lines]
    else:
        for k in ("from", "to"):
            if k not in raw:
                raise reader.fail(f"{key}.{k}", f"missing; expected the {form}'s {k} value")
            settings[k] = reader.quantity(raw[k], f"{key}.{k}", unit)
        if form == "step":
            at = settings["step"] = reader.quantity(raw["step"], f"{key}.step", "s")
            times, values = [at, at], [settings["from"], settings["to"]]
        else:
            ends = raw["ramp"]
            if not (isinstance(ends, list) and len(ends) == 2):
                raise reader.fail(f"{key}.ramp", "expected [start time, end time]")
            t0 = reader.quantity(ends[0], f"{key}.ramp[0]", "s")
            t1 = reader.quantity(ends[1], f"{key}.ramp[1]", "s")
            if not t1 > t0:
                raise reader.fail(f"{key}.ramp", f"the end {t1:g} s must be later than {t0:g} s")
            times, values = [t0, t1], [settings["from"], settings["to"]]
        row_key = [f"{key}.{k}" for k in ("from", "to")]
        row_text = ["", ""]
    _check_rows(reader, where, times, values, row_key, row_text, var)
    if outside == "error":
        start, stop = span
        if start < times[0] or stop > times[-1]:
            raise reader.fail(
                f"{key}.outside",
                f"the run ({start:g} s to {stop:g} s) goes past the signal's span "
                f'({times[0]:g} s to {times[-1]:g} s) and outside = "error"',
            )
    return Signal(tuple(times), tuple(values), interpolation, outside, source, settings)


def _choice(reader: Reader, raw: dict[str, Any], key: str, name: str, allowed: tuple) -> str:
    value = raw.get(name, allowed[0])
    if value not in allowed:
        raise reader.fail(f"{key}.{name}", f"unknown {value!r}; expected one of {list(allowed)}")
    return value


def _table(
    reader: Reader, rows: Any, key: str, unit: str
) -> tuple[list[float], list[float], list[int]]:
    if not isinstance(rows, list) or not rows:
        raise reader.fail(key, 'expected an array of rows [time, value], e.g. [["0 s", 0.0]]')
    times, values = [], []
    for r, row in enumerate(rows):
        if not (isinstance(row, list) and len(row) == 2):
            raise reader.fail(f"{key}[{r}]", f"expected a row [time, value], got {row!r}")
        times.append(reader.quantity(row[0], f"{key}[{r}]", "s"))
        values.append(reader.quantity(row[1], f"{key}[{r}]", unit))
    return times, values, list(range(len(rows)))


def _check_rows(
    reader: Reader,
    where: Path,
    times: list[float],
    values: list[float],
    row_key: list[str],
    row_text: list[str],
    var: Any,
) -> None:
    """Monotone time, at most two rows per time, values within the input's range."""

    def fail(r: int, message: str) -> ScenarioError:
        text = f"{row_text[r]}: {message}" if row_text[r] else message
        return ScenarioError(where, row_key[r], text)

    low = var.min if var.min is not None else -math.inf
    high = var.max if var.max is not None else math.inf
    unit = f" {var.unit}" if var.unit not in (None, "1") else ""
    for r, (t, v) in enumerate(zip(times, values, strict=True)):
        if not (math.isfinite(t) and math.isfinite(v)):
            raise fail(r, f"expected a finite time and value, got {t!r}, {v!r}")
        if not low <= v <= high:
            raise fail(
                r, f"{v:g}{unit} is outside {var.name}'s valid range [{low:g}, {high:g}]{unit}"
            )
        if r == 0:
            continue
        previous = times[r - 1]
        if t < previous:
            raise fail(r, f"time {t:g} s is earlier than the row before ({previous:g} s)")
        if t == previous and r >= 2 and times[r - 2] == t:
            raise fail(r, f"time {t:g} s is written three times; a jump is two rows")
        if 0.0 < t - previous <= _snap_tolerance(t):
            raise fail(
                r,
                f"time {t!r} s is {t - previous:.1e} s after the row before: write the "
                "same time twice for a jump",
            )


_HEADER = re.compile(r"^\s*(?P<name>[^\[\]]+?)\s*\[(?P<unit>[^\]]*)\]\s*$")


def _csv(reader: Reader, raw: dict[str, Any], key: str, var: Any):
    """(file, times, values, line numbers, sha256, column) of a CSV signal file."""
    text = raw["file"]
    if not isinstance(text, str) or not text.strip():
        raise reader.fail(f"{key}.file", f"expected a CSV file path, got {text!r}")
    path = (reader.scene_path.parent / text).resolve()
    fkey = f"{key}.file"
    try:
        data = read_regular(path, CSV_LIMIT)
    except FileNotFoundError:
        raise reader.fail(fkey, f"no CSV file at {path}") from None
    except NotARegularFile as exc:
        raise reader.fail(fkey, f"{reader.scene_path.parent / text} {exc.strerror}") from None
    except OSError as exc:
        raise reader.fail(fkey, f"cannot read {path}: {exc.strerror or exc}") from None
    try:
        text_lines = data.decode("utf-8-sig").splitlines()
        header = text_lines[0] if text_lines else ""
        # Comma, or what a spreadsheet writes where the comma is the decimal mark.
        delimiter = next((d for d in ",;\t" if d in header), ",")
        lines = list(csv.reader(text_lines, delimiter=delimiter))
    except (UnicodeDecodeError, csv.Error) as exc:
        raise ScenarioError(path, fkey, f"not a UTF-8 CSV file ({exc})") from None
    if not lines or not any(cell.strip() for cell in lines[0]):
        raise ScenarioError(path, fkey, "line 1: expected a header such as 'time [s], tau [N*m]'")
    names, units, note = [], [], ""
    if fmpy_header(lines[0]):  # FMPy's input file: the time in s, values in declared units
        names = [cell.strip() for cell in lines[0]]
        units = ["s" if n == "time" else var.unit or "1" for n in names]
        note = (
            "a header without units (FMPy's input format): time in s, values in the "
            f"input's declared unit {var.unit or '1'}"
        )
    for cell in lines[0] if not note else ():
        match = _HEADER.match(cell)
        if match is None:
            raise ScenarioError(
                path, fkey, f"line 1: column {cell.strip()!r} has no unit; expected 'name [unit]'"
            )
        names.append(match["name"])
        units.append(match["unit"].strip() or "1")
    if "time" not in names:
        raise ScenarioError(path, fkey, f"line 1: no 'time [unit]' column among {names}")
    column = raw.get("column")
    others = [n for n in names if n != "time"]
    if column is None:
        if len(others) != 1:
            raise reader.fail(
                f"{key}.column", f"missing; the file has columns {others}: name the one to use"
            )
        column = others[0]
    if not isinstance(column, str) or column not in others:
        raise reader.fail(f"{key}.column", f"no column {column!r} in {path.name}; has {others}")
    it, iv = names.index("time"), names.index(column)
    to_time = _affine(units[it], "s", path, fkey, "time")
    to_value = _affine(units[iv], var.unit or "1", path, fkey, column)
    times, values, numbers = [], [], []
    for n, cells in enumerate(lines[1:], start=2):
        if not any(c.strip() for c in cells):
            continue
        if len(cells) != len(names):
            raise ScenarioError(
                path, fkey, f"line {n}: {len(cells)} cells, the header names {len(names)}"
            )
        try:
            t, v = float(cells[it]), float(cells[iv])
        except ValueError:
            raise ScenarioError(
                path, fkey, f"line {n}: expected numbers, got {cells[it]!r}, {cells[iv]!r}"
            ) from None
        times.append(to_time(t))
        values.append(to_value(v))
        numbers.append(n)
    if not times:
        raise ScenarioError(path, fkey, "no data rows after the header")
    return path, times, values, numbers, hashlib.sha256(data).hexdigest(), column, note


def fmpy_header(cells: list[str]) -> bool:
    """A header as FMPy's ``simulate_fmu`` reads an input file: ``time`` first, names
    only, not one unit."""
    names = [cell.strip() for cell in cells]
    return (
        len(names) >= 2
        and names[0] == "time"
        and all(n and "[" not in n and "]" not in n for n in names)
    )


def _affine(unit: str, target: str, path: Path, key: str, column: str) -> Callable[[float], float]:
    """Conversion of one column's numbers to the SI unit (offsets such as degC kept)."""
    try:
        a = float(ureg().Quantity(0.0, unit).to(pint_unit(target)).magnitude)
        b = float(ureg().Quantity(1.0, unit).to(pint_unit(target)).magnitude)
    except Exception as exc:  # pint raises several unrelated types
        raise ScenarioError(
            path, key, f"line 1: column {column!r} in [{unit}] is not in {target} ({exc})"
        ) from None
    scale = b - a
    return (lambda x: x * scale) if a == 0.0 else (lambda x: a + x * scale)


# -- what masters use -----------------------------------------------------------------
class InputSignals:
    """The scene's signals bound to the FMU instances they drive.

    Masters need three things: where the next breakpoint is (``next_breakpoint``,
    ``land``, ``clip``), whether an instant is a jump (``jump_at``), and to feed each
    instance its signal values at a time (``apply``; the coupled system calls it around
    every doStep, so that a rolled-back FMU is fed again).
    """

    def __init__(self, driven: dict[tuple[str, str], Signal]) -> None:
        self.driven = dict(driven)
        self.signals = list(self.driven.values())
        times = sorted({t for s in self.signals for t in s.breakpoints()})
        self._breaks = times
        self._jumps = sorted({t for s in self.signals for t in s.jumps})
        self._jump_set = frozenset(self._jumps)
        self._setters: list[tuple[Callable[[list], None], list[Signal]] | None] = []

    def __bool__(self) -> bool:
        return bool(self.driven)

    def bind(self, names: list[str], setter: Callable[[str, list[str]], Any]) -> None:
        """Prepare one setter per instance (``setter(instance, variables)``)."""
        self._setters = []
        for name in names:
            variables = [v for (i, v) in self.driven if i == name]
            if not variables:
                self._setters.append(None)
                continue
            signals = [self.driven[(name, v)] for v in variables]
            self._setters.append((setter(name, variables), signals))

    def apply(self, i: int, t: float) -> None:
        """Set instance i's signal-driven inputs to their values at t (after a jump)."""
        bound = self._setters[i] if i < len(self._setters) else None
        if bound is not None:
            set_values, signals = bound
            set_values([s.value(t) for s in signals])

    def next_breakpoint(self, t: float) -> float | None:
        """The first jump or kink of any signal later than t."""
        k = bisect.bisect_right(self._breaks, _snap(self._breaks, t))
        return self._breaks[k] if k < len(self._breaks) else None

    def land(self, t: float, end: float) -> float:
        """Where a step from t meant to reach ``end`` ends: the first breakpoint in
        (t, end], or end; an end within rounding of a breakpoint is moved onto it."""
        if not self._breaks:
            return end
        nxt = self.next_breakpoint(t)
        if nxt is not None and (nxt < end or abs(nxt - end) <= _snap_tolerance(end)):
            return nxt
        return end

    def clip(self, t: float, h: float, tolerance: float | None = None) -> float:
        """The step from t: h, or shorter to end on the next breakpoint; with a
        ``tolerance``, also short enough that no sloped signal, held at its step-start
        value, changes by more than ``tolerance`` times its largest magnitude over the step
        (the first-order hold error an error-controlled master must see)."""
        if not self._breaks:
            return h
        if tolerance is not None:
            for s in self.signals:
                slope = abs(s.slope(t))
                if slope > 0.0:
                    h = min(h, tolerance * s.scale / slope)
        end = self.land(t, t + h)
        return h if end == t + h else end - t

    def jump_at(self, t: float) -> bool:
        """Whether some signal jumps at t (within rounding)."""
        return bool(self._jumps) and _snap(self._jumps, t) in self._jump_set

    def provenance(self) -> dict[str, Any]:
        """Per driven input, how the scene gave it (a CSV file with its sha256)."""
        return {
            f"{i}.{v}": {
                **s.source,
                "interpolation": s.interpolation,
                "outside": s.outside,
                "rows": len(s.times),
                "breakpoints": len(s.breakpoints()),
            }
            for (i, v), s in self.driven.items()
        }


def scene_signals(scene: Any) -> InputSignals:
    """Every signal of a scene, keyed (instance, input)."""
    return InputSignals(
        {
            (instance, name): signal
            for instance, spec in scene.fmus.items()
            for name, signal in getattr(spec, "signals", {}).items()
        }
    )


# -- export ---------------------------------------------------------------------------
def refuse_signals(scene: Any, fmt: str, why: str) -> None:
    """A format that cannot carry inputs that vary in time refuses the scene, in one line
    naming the first such input."""
    signals = scene_signals(scene)
    if signals:
        instance, name = next(iter(signals.driven))
        raise ScenarioError(
            scene.path, f"fmus.{instance}.inputs.{name}", f"a signal drives it: {fmt} {why}"
        )


def libcosim_scenario(scene: Any, step: float) -> dict[str, Any] | None:
    """The scene's signals as a libcosim scenario (JSON: events that override an input's
    value from a given time on, timed from the start), or None without signals.

    A libcosim scenario sets values at instants, and its fixed-step algorithm takes them
    at its communication points: a signal with a slope, or a jump off the base step's
    grid, cannot be carried and is refused naming it.
    """
    signals = scene_signals(scene)
    if not signals:
        return None
    events = []
    for (instance, name), signal in signals.driven.items():
        key = f"fmus.{instance}.inputs.{name}"
        if signal.breakpoints() != signal.jumps:
            raise ScenarioError(
                scene.path,
                key,
                "a signal with a slope cannot be written as libcosim scenario events "
                '(they set a value at an instant); use interpolation = "hold"',
            )
        for t in signal.jumps:
            if not scene.start <= t < scene.stop:
                continue  # before the start: in the initial value; after the stop: unused
            k = (t - scene.start) / step
            if abs(k - round(k)) > 1e-6:
                raise ScenarioError(
                    scene.path,
                    key,
                    f"its jump at {t:g} s is not on libcosim's base step grid "
                    f"({step:g} s from {scene.start:g} s): libcosim would take it late",
                )
            events.append(
                {
                    "time": round(k) * step,
                    "model": instance,
                    "variable": name,
                    "action": "override",
                    "value": signal.value(t),
                }
            )
    events.sort(key=lambda e: e["time"])
    return {
        "description": f"input signals of scene {scene.name!r}, times from the start",
        "events": events,
        "end": scene.stop - scene.start,
    }
