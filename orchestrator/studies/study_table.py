"""The ``[study]`` table of a scene: what a tolerance study varies, how, and what it collects.

Read once at load (``mechcosim check`` validates it) into a ``StudySpec`` whose numbers are
SI.  Each varied input is one distribution setting one or more dotted keys to the same value
(a quantity shared by several FMUs, such as the spin, is one input):

    band = "±0.001 in"            a drawing tolerance: truncated normal, 3 sigma at the band
                                  edge (``distribution = "uniform"``: uniform over the band);
                                  "±5 %" is relative; ``nominal`` defaults to the scene's value
    distribution = "normal"       mean, sd
    distribution = "uniform"      low, high
    distribution = "lognormal"    median, sigma (of the natural logarithm, dimensionless)
    values = [a, b, ...]          discrete, each equally likely

Every error names the file and the key (``ScenarioError``), as the rest of the scene's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Protocol

from orchestrator.setting_limits import MIN_SAMPLES
from orchestrator.signals import SETTABLE, signal_setting


class SceneChecks(Protocol):
    """What the [study] table is read with: the scene loader's checks
    (``orchestrator.scenario``), each failure a ScenarioError naming the file and the key."""

    def fail(self, key: str, message: str) -> Exception: ...

    def table(self, node: Any, key: str) -> dict[str, Any]: ...

    def check_keys(self, node: dict[str, Any], key: str, allowed: set[str]) -> None: ...

    def quantity(self, value: Any, key: str, unit: str) -> float: ...

    def swept_unit(self, dotted: str, fmus: dict[str, Any], key: str = ...) -> str | None:
        """The SI unit of a key a study may set (None: a plain value)."""
        ...

    def key_variables(self, dotted: str, fmus: dict[str, Any]) -> list[tuple[str, str, str]]:
        """The (instance, "parameters" or "inputs", variable) a key sets."""
        ...


SAMPLING_METHODS = ("sobol", "monte-carlo")
DISTRIBUTIONS = ("band", "normal", "uniform", "lognormal", "discrete")
#: A band is read as a normal truncated at this many standard deviations.
BAND_SIGMAS = 3.0
#: Samples above this need --force-like intent: refuse typos such as 5000000.
MAX_SAMPLES = 100_000

_INPUT_KEYS = {
    "key",
    "name",
    "label",
    "distribution",
    "nominal",
    "band",
    "mean",
    "sd",
    "low",
    "high",
    "median",
    "sigma",
    "values",
}


@dataclass(frozen=True)
class StudyInput:
    """One varied quantity: its distribution (SI numbers) and the keys it sets."""

    name: str  # column name in samples.csv and the tables
    label: str
    keys: tuple[str, ...]  # dotted keys, as with --set
    unit: str  # SI unit ("1" when plain)
    distribution: str  # one of DISTRIBUTIONS
    params: tuple[float, ...]  # band: (nominal, half width, uniform?); normal: (mean, sd);
    # uniform: (low, high); lognormal: (median, sigma); discrete: the values

    @property
    def support(self) -> tuple[float, float]:
        """Smallest and largest value a sample can take (infinite for normal/lognormal)."""
        kind, p = self.distribution, self.params
        if kind == "band":
            return p[0] - p[1], p[0] + p[1]
        if kind == "uniform":
            return p[0], p[1]
        if kind == "discrete":
            return min(p), max(p)
        if kind == "lognormal":
            return 0.0, math.inf
        return -math.inf, math.inf

    def describe(self) -> str:
        """The distribution in words, for the study's report."""
        kind, p = self.distribution, self.params
        u = "" if self.unit == "1" else self.unit
        if kind == "band":
            shape = "uniform" if p[2] else f"truncated normal, ±{BAND_SIGMAS:g}σ"
            return f"{p[0]:.6g} ± {p[1]:.3g} {u} ({shape})".replace("  ", " ")
        if kind == "normal":
            return f"normal, mean {p[0]:.6g} {u}, sd {p[1]:.3g} {u}".replace(" ,", ",").strip()
        if kind == "uniform":
            return f"uniform {p[0]:.6g} … {p[1]:.6g} {u}".strip()
        if kind == "lognormal":
            return f"lognormal, median {p[0]:.6g} {u}, σ(ln) {p[1]:.3g}".replace(" ,", ",")
        return f"one of {', '.join(f'{v:.6g}' for v in p)} {u}".strip()


@dataclass(frozen=True)
class AcceptanceLimit:
    """Bounds a headline quantity must keep; a sample outside either violates the limit."""

    quantity: str
    low: float | None
    high: float | None
    low_text: str  # what falling below means, e.g. "must not arm before"
    high_text: str


@dataclass(frozen=True)
class StudySpec:
    inputs: tuple[StudyInput, ...]
    samples: int
    seed: int
    sampling: str  # one of SAMPLING_METHODS
    quantities: tuple[str, ...]  # headline quantities collected
    limits: tuple[AcceptanceLimit, ...]


def parse_study(loader: SceneChecks, node: Any, fmus: dict[str, Any]) -> StudySpec:
    """The ``[study]`` table, checked against the scene's FMUs.  ``loader`` is the scene
    loader (``fail``, ``table``, ``check_keys``, ``quantity``, ``swept_unit``)."""
    node = loader.table(node, "study")
    loader.check_keys(
        node, "study", {"samples", "seed", "sampling", "quantities", "inputs", "limits"}
    )
    samples = _positive_int(loader, node, "samples", 64)
    if samples > MAX_SAMPLES:
        raise loader.fail("study.samples", f"{samples} is more than {MAX_SAMPLES}")
    if samples < MIN_SAMPLES:  # one sample has no spread to state
        raise loader.fail(
            "study.samples", f"expected at least {MIN_SAMPLES} samples, got {samples}"
        )
    seed = node.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise loader.fail("study.seed", f"expected a non-negative integer, got {seed!r}")
    sampling = node.get("sampling", "sobol")
    if sampling not in SAMPLING_METHODS:
        raise loader.fail(
            "study.sampling", f"expected one of {list(SAMPLING_METHODS)}, got {sampling!r}"
        )
    quantities = node.get("quantities")
    if (
        not isinstance(quantities, list)
        or not quantities
        or not all(isinstance(q, str) and q for q in quantities)
    ):
        raise loader.fail(
            "study.quantities", "expected a non-empty array of headline quantity names"
        )
    if len(set(quantities)) != len(quantities):
        raise loader.fail("study.quantities", "a quantity is named twice")
    entries = node.get("inputs")
    if not isinstance(entries, list) or not entries:
        raise loader.fail("study.inputs", "expected one [[study.inputs]] table or more")
    inputs = tuple(_input(loader, e, f"study.inputs[{k}]", fmus) for k, e in enumerate(entries))
    names = [i.name for i in inputs]
    for k, name in enumerate(names):
        if name in names[:k]:
            raise loader.fail(f"study.inputs[{k}].name", f"{name!r} is used by an earlier input")
    keys = [key for i in inputs for key in i.keys]
    for k, key in enumerate(keys):
        if key in keys[:k]:
            raise loader.fail("study.inputs", f"{key!r} is set by two inputs")
    limits = _limits(loader, node.get("limits", {}), quantities)
    return StudySpec(inputs, samples, seed, sampling, tuple(quantities), limits)


def _positive_int(loader: SceneChecks, node: dict[str, Any], key: str, default: int) -> int:
    value = node.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise loader.fail(f"study.{key}", f"expected a positive integer, got {value!r}")
    return value


def _input(loader: SceneChecks, entry: Any, where: str, fmus: dict[str, Any]) -> StudyInput:
    entry = loader.table(entry, where)
    loader.check_keys(entry, where, _INPUT_KEYS)
    keys = entry.get("key")
    if isinstance(keys, str):
        keys = [keys]
    if not isinstance(keys, list) or not keys or not all(isinstance(k, str) for k in keys):
        raise loader.fail(
            f"{where}.key", "expected a dotted key (or an array of them set to the same value)"
        )
    units = [loader.swept_unit(k, fmus, f"{where}.key") for k in keys]
    units = [u or "1" for u in units]
    if len(set(units)) > 1:
        raise loader.fail(
            f"{where}.key", f"the keys have different units {units}: one value cannot set them all"
        )
    unit = units[0]
    name = entry.get("name", keys[0].rsplit(".", 1)[-1])
    if not isinstance(name, str) or not name.isidentifier():
        raise loader.fail(f"{where}.name", f"expected a plain identifier, got {name!r}")
    label = entry.get("label", name)
    if not isinstance(label, str):
        raise loader.fail(f"{where}.label", f"expected a string, got {label!r}")
    kind, params = _distribution(loader, entry, where, unit, keys[0], fmus)
    spec = StudyInput(name, label, tuple(keys), unit, kind, params)
    _check_range(loader, spec, where, fmus)
    return spec


def _distribution(
    loader: SceneChecks,
    entry: dict[str, Any],
    where: str,
    unit: str,
    key: str,
    fmus: dict[str, Any],
) -> tuple[str, tuple[float, ...]]:
    def q(k: str) -> float:
        if k not in entry:
            raise loader.fail(f"{where}.{k}", f"missing; expected a value in {unit}")
        return loader.quantity(entry[k], f"{where}.{k}", unit)

    def only(allowed: set[str]) -> None:
        extra = sorted(set(entry) - allowed - {"key", "name", "label", "distribution"})
        if extra:
            raise loader.fail(
                f"{where}.{extra[0]}", f"not used by a {kind} input; expected {sorted(allowed)}"
            )

    if "values" in entry:
        kind = entry.get("distribution", "discrete")
        if kind != "discrete":
            raise loader.fail(
                f"{where}.distribution", f"'values' makes a discrete input, not {kind!r}"
            )
        only({"values"})
        values = entry["values"]
        if not isinstance(values, list) or not values:
            raise loader.fail(f"{where}.values", "expected a non-empty array of values")
        return "discrete", tuple(
            loader.quantity(v, f"{where}.values[{k}]", unit) for k, v in enumerate(values)
        )
    if "band" in entry:
        kind = entry.get("distribution", "normal")
        if kind not in ("normal", "uniform"):
            raise loader.fail(
                f"{where}.distribution",
                f"a band is read as 'normal' (truncated at ±{BAND_SIGMAS:g}σ) or 'uniform', "
                f"got {kind!r}",
            )
        only({"band", "nominal"})
        nominal = q("nominal") if "nominal" in entry else _scene_value(loader, key, fmus, where)
        half = _band(loader, entry["band"], f"{where}.band", unit, nominal)
        return "band", (nominal, half, 1.0 if kind == "uniform" else 0.0)
    kind = entry.get("distribution")
    if kind == "normal":
        only({"mean", "sd"})
        mean, sd = q("mean"), q("sd")
        if not sd > 0.0:
            raise loader.fail(f"{where}.sd", f"must be positive, got {sd}")
        return "normal", (mean, sd)
    if kind == "uniform":
        only({"low", "high"})
        low, high = q("low"), q("high")
        if not high > low:
            raise loader.fail(f"{where}.high", f"must be above low ({low:g}), got {high:g}")
        return "uniform", (low, high)
    if kind == "lognormal":
        only({"median", "sigma"})
        median = q("median")
        if not median > 0.0:
            raise loader.fail(f"{where}.median", f"must be positive, got {median}")
        sigma = entry.get("sigma")
        if isinstance(sigma, bool) or not isinstance(sigma, int | float) or not sigma > 0:
            raise loader.fail(
                f"{where}.sigma", f"expected a positive number (σ of ln), got {sigma!r}"
            )
        return "lognormal", (median, float(sigma))
    raise loader.fail(
        f"{where}.distribution",
        f"expected 'band', 'values', or distribution one of ['normal', 'uniform', 'lognormal'], "
        f"got {kind!r}",
    )


def _band(loader: SceneChecks, text: Any, key: str, unit: str, nominal: float) -> float:
    """Half width of a symmetric band "±0.001 in" / "+-0.001 in" / "±5 %", in SI."""
    if not isinstance(text, str):
        raise loader.fail(key, f"expected a string such as '±0.001 in' or '±5 %', got {text!r}")
    body = text.strip()
    for sign in ("±", "+-", "+/-"):
        if body.startswith(sign):
            body = body[len(sign) :].strip()
            break
    else:
        raise loader.fail(key, f"expected a symmetric band such as '±0.001 in', got {text!r}")
    if body.endswith("%"):
        try:
            half = abs(nominal) * float(body[:-1]) / 100.0
        except ValueError:
            raise loader.fail(key, f"cannot read {text!r} as a percentage") from None
    else:
        half = loader.quantity(body, key, unit)
    if not half > 0.0 or not math.isfinite(half):
        raise loader.fail(key, f"expected a positive half width, got {text!r}")
    return half


def _scene_value(loader: SceneChecks, key: str, fmus: dict[str, Any], where: str) -> float:
    """The scene's own value of an FMU parameter or input (the nominal of a band)."""
    for instance, kind, name in loader.key_variables(key, fmus)[:1]:
        spec = fmus[instance]
        given = spec.parameters if kind == "parameters" else spec.inputs
        shorthand = signal_setting(spec, name) if kind == "inputs" else None
        if shorthand is not None:  # a signal's key, e.g. a step's height "u_s.to"
            value = shorthand[2].settings.get(shorthand[1])
        else:
            value = given.get(name, spec.model.variables[name].start)
        try:
            return float(value)
        except (TypeError, ValueError):
            pass
    raise loader.fail(
        f"{where}.nominal", f"missing: {key!r} has no value in the scene to centre the band on"
    )


def _check_range(loader: SceneChecks, spec: StudyInput, where: str, fmus: dict[str, Any]) -> None:
    """A distribution bounded on a side stays within the range the FMU declares there (an
    unbounded one may reach past it: those samples fail, and are counted, at run time)."""
    low, high = spec.support
    targets = [(key, *target) for key in spec.keys for target in loader.key_variables(key, fmus)]
    for key, instance, kind, name in targets:
        shorthand = signal_setting(fmus[instance], name) if kind == "inputs" else None
        if shorthand is not None and SETTABLE[shorthand[1]] != "value":
            continue  # a signal's time: the run checks it
        var = fmus[instance].model.variables[shorthand[0] if shorthand is not None else name]
        if var.min is not None and math.isfinite(low) and low < var.min:
            raise loader.fail(
                where, f"reaches {low:.6g} {spec.unit}, below {key}'s minimum {var.min:g}"
            )
        if var.max is not None and math.isfinite(high) and high > var.max:
            raise loader.fail(
                where, f"reaches {high:.6g} {spec.unit}, above {key}'s maximum {var.max:g}"
            )


def _limits(loader: SceneChecks, node: Any, quantities: list[str]) -> tuple[AcceptanceLimit, ...]:
    node = loader.table(node, "study.limits")
    out = []
    for quantity, entry in node.items():
        key = f"study.limits.{quantity}"
        if quantity not in quantities:
            raise loader.fail(key, f"not a collected quantity; expected one of {quantities}")
        entry = loader.table(entry, key)
        loader.check_keys(entry, key, {"min", "max", "min_means", "max_means"})
        bounds = []
        for side in ("min", "max"):
            value = entry.get(side)
            if value is not None and (
                isinstance(value, bool)
                or not isinstance(value, int | float)
                or not math.isfinite(value)
            ):
                raise loader.fail(f"{key}.{side}", f"expected a finite number, got {value!r}")
            bounds.append(None if value is None else float(value))
        if bounds == [None, None]:
            raise loader.fail(key, "expected 'min', 'max' or both")
        if None not in bounds and not bounds[1] > bounds[0]:
            raise loader.fail(f"{key}.max", f"must be above min ({bounds[0]:g})")
        texts = []
        for side, default in (
            ("min_means", "below the minimum"),
            ("max_means", "above the maximum"),
        ):
            text = entry.get(side, default)
            if not isinstance(text, str):
                raise loader.fail(f"{key}.{side}", f"expected a string, got {text!r}")
            texts.append(text)
        out.append(AcceptanceLimit(quantity, bounds[0], bounds[1], texts[0], texts[1]))
    return tuple(out)
