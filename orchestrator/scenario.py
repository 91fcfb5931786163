"""Scenario files (TOML): schema, validation, conversion to SI.

Everything a run needs is checked here, before any FMU is built or loaded.  Every error
names the file, the key and what was expected.  The schema is documented in
``scenarios/README.md``.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path
from typing import Any

from fmus.build import BuildError, build_fmu
from fmus.ports import PortError, PortSide, join_ports
from fmus.registry import FMU_RECORDS
from orchestrator.errors import ScenarioError
from orchestrator.lazy import resolve
from orchestrator.master_settings import (
    COMMON_KEYS,
    FixedStepSettings,
    SettingError,
    read_options,
)
from orchestrator.masters.registry import (
    ALGORITHMS,
    setting_kinds,
    settings_of,
    step_key,
    step_keys,
)
from orchestrator.model_info import ModelInfo, ModelInfoError, VariableInfo, model_info
from orchestrator.regular_files import (
    ARCHIVE_LIMIT,
    TOML_LIMIT,
    NotARegularFile,
    check_regular,
    read_regular,
)
from orchestrator.scene_model import (
    Connection,
    FmuSpec,
    HeadlineSpec,
    MasterSpec,
    Scene,
    StopCondition,
    SweepSeries,
    SweepSpec,
)
from orchestrator.scenes import ANALYSES, FAMILY_NAMES, REFERENCES, family, shared_parameters
from orchestrator.scenes.family import Option, SharedParameter
from orchestrator.setting_limits import MAX_RUN_STEPS as MAX_STEPS
from orchestrator.signals import (
    Reader,
    Signal,
    is_signal,
    merge_signal_overrides,
    read_signal,
    split_signal_key,
)
from orchestrator.studies.study_table import StudySpec, parse_study
from orchestrator.units import to_si

#: FMI types a run can record (a Boolean as 0 or 1; a String is no number)
RECORDED_TYPES = ("Real", "Integer", "Enumeration", "Boolean")

REDUCTIONS = ("final", "initial", "max", "min", "maxabs", "mean")

#: What each master's step key sets (its message when the scene gives none).
STEP_MEANING = {
    "step": "macro step, e.g. '0.1 ms'",
    "first_step": "first step (and the step after a switch), e.g. '1 us'",
}


def load_scene(
    path: str | Path,
    overrides: dict[str, Any] | None = None,
    cache_dir: Path | None = None,
    force: bool = False,
) -> Scene:
    """Read, validate and convert a scenario file; ``overrides`` patch the raw TOML first.

    Overrides use dotted keys, e.g. {"master.step": "1 ms", "fmus.a.parameters.J": 2e-3};
    a variable name after ``parameters.`` or ``inputs.`` may itself hold dots
    ("fmus.c.parameters.inertia1.J").  The FMUs the scene names are built (ours, into
    ``cache_dir``) or read, so that everything is checked against their model descriptions.
    ``force`` accepts a run of more than ``MAX_STEPS`` macro steps.
    """
    path = Path(path)
    return scene_from_table(path, read_toml(path), overrides, cache_dir, force)


def scene_from_table(
    path: Path,
    raw: dict[str, Any],
    overrides: dict[str, Any] | None = None,
    cache_dir: Path | None = None,
    force: bool = False,
) -> Scene:
    """A scene from its parsed table (as read from a TOML file, or made from another
    format); ``path`` names the source in messages and anchors relative FMU paths."""
    for dotted, value in (overrides or {}).items():
        _set_dotted(raw, dotted, value)
    return _Loader(Path(path), raw, cache_dir, force).scene()


def read_toml(path: Path) -> dict[str, Any]:
    """The parsed file, or a ScenarioError saying in one line why it cannot be read."""
    try:
        text = read_regular(path, TOML_LIMIT).decode("utf-8")
    except FileNotFoundError:
        raise ScenarioError(path, "", "file not found") from None
    except IsADirectoryError:
        raise ScenarioError(path, "", "is a directory; expected a scenario file (.toml)") from None
    except UnicodeDecodeError as exc:
        raise ScenarioError(
            path, "", f"not UTF-8 text (byte {exc.start}): expected a TOML scenario file"
        ) from None
    except NotARegularFile as exc:
        raise ScenarioError(path, "", str(exc.strerror)) from None
    except OSError as exc:
        raise ScenarioError(path, "", f"cannot read: {exc.strerror or exc}") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(path, "", f"not valid TOML: {exc}") from None
    except RecursionError:
        raise ScenarioError(
            path, "", "not a scenario: tables or arrays nested too deeply"
        ) from None


def _set_dotted(raw: dict[str, Any], dotted: str, value: Any) -> None:
    parts = _split_key(dotted)
    if not all(parts):
        raise ScenarioError("--set", dotted, "expected a dotted key such as master.step")
    *parents, last = parts
    node = raw
    for depth, key in enumerate(parents):
        node = node.setdefault(key, {})
        if not isinstance(node, dict):
            where = ".".join(parents[: depth + 1])
            raise ScenarioError(
                "--set", dotted, f"{where} is a value ({node!r}), not a table: cannot set {last!r}"
            )
    node[last] = value


def _split_key(dotted: str) -> list[str]:
    """Split a dotted key; an FMU variable's own name (after parameters/inputs) stays whole."""
    parts = dotted.split(".")
    if len(parts) > 4 and parts[0] == "fmus" and parts[2] in ("parameters", "inputs"):
        return [*parts[:3], ".".join(parts[3:])]
    return parts


class _Loader:
    def __init__(
        self, path: Path, raw: dict[str, Any], cache_dir: Path | None, force: bool = False
    ) -> None:
        self.path, self.raw, self.cache_dir, self.force = path, raw, cache_dir, force
        self.span = (0.0, math.inf)  # the run's (start, stop), once [scene] is read
        self.shared = shared_parameters(_families(raw))  # what the scene's families share

    def fail(self, key: str, message: str) -> ScenarioError:
        return ScenarioError(self.path, key, message)

    def table(self, node: Any, key: str) -> dict[str, Any]:
        if not isinstance(node, dict):
            raise self.fail(key, f"expected a table, got {type(node).__name__}")
        return node

    def check_keys(self, node: dict[str, Any], key: str, allowed: set[str]) -> None:
        unknown = sorted(set(node) - allowed)
        if unknown:
            where = f"{key}.{unknown[0]}" if key else unknown[0]
            raise self.fail(where, f"unknown key; expected one of {sorted(allowed)}")

    def quantity(self, value: Any, key: str, unit: str, exact: bool = False) -> float:
        try:
            si = to_si(value, unit, exact)
        except (ValueError, TypeError, ArithmeticError) as exc:
            raise self.fail(key, f"{exc} (expected a value in {unit})") from None
        if not math.isfinite(si):
            raise self.fail(key, f"expected a finite value, got {value!r}")
        return si

    def string(
        self, node: dict[str, Any], key: str, dotted: str, default: str | None = None
    ) -> str:
        if key not in node:
            if default is None:
                raise self.fail(dotted, "missing; expected a string")
            return default
        if not isinstance(node[key], str):
            raise self.fail(dotted, f"expected a string, got {node[key]!r}")
        return node[key]

    def scene_name(self, name: str) -> str:
        """A scene's name names its results directory (runs/<name>): a name, not a path."""
        if not name.strip():
            raise self.fail("scene.name", "empty; expected a name such as 'm739_run1'")
        bad = [c for c in ("/", "\\", "\0") if c in name]
        if bad or name in (".", "..") or any(ord(c) < 32 for c in name):
            raise self.fail(
                "scene.name",
                f"{name!r} is not a name: no path separators, control characters, '.' or '..'",
            )
        return name

    # -- sections ---------------------------------------------------------------------
    def scene(self) -> Scene:
        raw = self.table(self.raw, "")
        self.check_keys(
            raw,
            "",
            {
                "scene",
                "parameters",
                "fmus",
                "connections",
                "master",
                "output",
                "report",
                "sweep",
                "study",
            },
        )
        for section in ("scene", "fmus", "master"):
            if section not in raw:
                raise self.fail(section, "missing section")
        head = self.table(raw["scene"], "scene")
        self.check_keys(
            head, "scene", {"name", "description", "start", "stop", "stop_when", "design"}
        )
        name = self.scene_name(self.string(head, "name", "scene.name"))
        description = head.get("description", "")
        if not isinstance(description, str):
            raise self.fail("scene.description", f"expected text, got {description!r}")
        start = self.quantity(head.get("start", 0.0), "scene.start", "s")
        if "stop" not in head:
            raise self.fail("scene.stop", "missing; expected the stop time, e.g. '0.1 s'")
        stop = self.quantity(head["stop"], "scene.stop", "s")
        if not stop > start:
            raise self.fail("scene.stop", f"must be later than scene.start ({start} s), got {stop}")
        self.span = (start, stop)  # a signal refuses a run past its span
        shared = self.table(raw.get("parameters", {}), "parameters")
        # A design file gives the mechanism's quantities; the scene's own [parameters]
        # (its operating point: spin, friction, ...) win over the file's.
        self.design_keys = {n: (self.path, f"parameters.{n}") for n in shared}
        design = self.design(head["design"]) if "design" in head else {}
        shared = {**design, **shared}
        fmus = self.fmus(self.table(raw["fmus"], "fmus"), shared)
        stop_when = self.stop_when(head["stop_when"], fmus) if "stop_when" in head else None
        connections = self.connections(raw.get("connections", []), fmus)
        self.signals_not_connected(connections, fmus)
        master = self.master(self.table(raw["master"], "master"), fmus, stop - start)
        record, every, out_dir = self.output(
            self.table(raw.get("output", {}), "output"), fmus, name
        )
        report = self.table(raw.get("report", {}), "report")
        headline, family_name, options, reference, error_bound = self.report(report, fmus)
        self.report_needs(headline, family_name, reference, options, fmus, record)
        sweep = self.sweep(raw["sweep"], fmus) if "sweep" in raw else None
        study = self.study(raw["study"], fmus) if "study" in raw else None
        scene = Scene(
            path=self.path,
            name=name,
            description=description,
            start=start,
            stop=stop,
            fmus=fmus,
            connections=connections,
            master=master,
            record=record,
            record_every=every,
            output_dir=out_dir,
            headline=headline,
            family=family_name,
            report_options=options,
            reference=reference,
            stop_when=stop_when,
            error_bound=error_bound,
            sweep=sweep,
            study=study,
        )
        self.check_design(scene)
        return scene

    def design(self, text: Any) -> dict[str, Any]:
        """The quantities of a design file (``scene.design``, relative to the scene): its
        [design] table, whose sub-tables (e.g. one per input card) only group them."""
        if not isinstance(text, str) or not text.strip():
            raise self.fail("scene.design", f"expected the path of a design file, got {text!r}")
        path = (self.path.parent / text).resolve()
        if path == self.path.resolve():
            raise self.fail("scene.design", "names the scene file itself; expected a design file")
        raw = read_toml(self.path.parent / text)  # an error names the file as written
        if not isinstance(raw.get("design"), dict):
            raise ScenarioError(path, "design", "missing; expected a [design] table")
        out: dict[str, Any] = {}

        def take(node: dict[str, Any], key: str) -> None:
            for name, value in node.items():
                dotted = f"{key}.{name}"
                if name in ("name", "description", "source") and key == "design":
                    if not isinstance(value, str):
                        raise ScenarioError(path, dotted, f"expected text, got {value!r}")
                    continue
                if isinstance(value, dict):
                    take(value, dotted)
                    continue
                if name in out:
                    raise ScenarioError(
                        path, dotted, f"{name} is stated twice ({self.design_keys[name][1]})"
                    )
                out[name] = value
                self.design_keys[name] = (path, dotted)

        take(raw["design"], "design")
        return out

    def check_design(self, scene: Scene) -> None:
        """The family's consistency rules of the scene's design (the first broken one)."""
        if scene.family is None:
            return
        check = family(scene.family).design_check
        if check is None:
            return
        problems = resolve(check)(scene)
        if problems:
            more = f" (and {len(problems) - 1} more)" if len(problems) > 1 else ""
            raise self.fail("parameters", f"{problems[0]}{more}")

    def stop_when(self, node: Any, fmus: dict[str, FmuSpec]) -> StopCondition:
        key = "scene.stop_when"
        node = self.table(node, key)
        self.check_keys(node, key, {"signal", "above", "below"})
        if "signal" not in node:
            raise self.fail(f"{key}.signal", "missing; expected '<instance>.<variable>'")
        signal = self.signal(node["signal"], f"{key}.signal", fmus, "output")
        if ("above" in node) == ("below" in node):
            raise self.fail(key, "expected exactly one of 'above' or 'below' (the threshold)")
        side = "above" if "above" in node else "below"
        var = fmus[signal[0]].model.variables[signal[1]]
        if var.type != "Real":
            raise self.fail(f"{key}.signal", f"{signal[1]!r} is not a Real output")
        threshold = self.quantity(node[side], f"{key}.{side}", var.unit or "1")
        return StopCondition(signal, threshold, rising=side == "above")

    def fmus(self, node: dict[str, Any], shared: dict[str, Any]) -> dict[str, FmuSpec]:
        """The [fmus.<instance>] tables, each given the [parameters] its component shares."""
        if not node:
            raise self.fail("fmus", "no FMU given; expected at least one [fmus.<instance>] table")
        specs = {}
        for instance, entry in node.items():
            key = f"fmus.{instance}"
            if not instance.isidentifier():
                raise self.fail(key, "an instance name is a plain identifier (no dots or spaces)")
            entry = self.table(entry, key)
            self.check_keys(entry, key, {"component", "fmu", "parameters", "inputs"})
            component, path = self.fmu_file(entry, key)
            try:
                model = model_info(path)
            except ModelInfoError as exc:
                raise self.fail(f"{key}.fmu", str(exc)) from None
            params = self.values(entry.get("parameters", {}), f"{key}.parameters", model)
            for name, value in shared.items():
                if _takes(component, model, self.shared.get(name)) or _designs(component, name):
                    if name in params and not _takes(component, model, self.shared.get(name)):
                        raise self.fail(
                            f"{key}.parameters.{name}",
                            f"{name} is a quantity of the design, stated for the scene "
                            f"({self.design_keys[name][1]}): state it once",
                        )
                    params[name] = self.shared_value(name, value, model.variables[name])
            inputs = self.values(entry.get("inputs", {}), f"{key}.inputs", model)
            signals = {n: inputs.pop(n) for n, v in list(inputs.items()) if isinstance(v, Signal)}
            # Initialization sees each signal's value at the start (before a jump there).
            inputs.update({n: s.value(self.span[0], left=True) for n, s in signals.items()})
            name = component or model.model_name
            specs[instance] = FmuSpec(
                instance, name, path, model, params, inputs, component, signals
            )
        self.check_shared(node, shared, specs)
        return specs

    def shared_value(self, name: str, value: Any, var: VariableInfo) -> Any:
        """A [parameters] or design-file value, its error naming the file it came from."""
        path, key = self.design_keys.get(name, (self.path, f"parameters.{name}"))
        try:
            return self.value(value, key, var)
        except ScenarioError as exc:
            raise ScenarioError(path, key, exc.message) from None

    def check_shared(
        self, node: dict[str, Any], shared: dict[str, Any], fmus: dict[str, FmuSpec]
    ) -> None:
        """A shared parameter is stated once, in [parameters], and some FMU takes it."""
        taken = {
            p.name: p
            for p in self.shared.values()
            for spec in fmus.values()
            if _takes(spec.component, spec.model, p)
        }
        for instance, entry in node.items():
            for name in entry.get("parameters", {}):
                if name in taken and _takes(
                    fmus[instance].component, fmus[instance].model, taken[name]
                ):
                    raise self.fail(
                        f"fmus.{instance}.parameters.{name}",
                        f"{name} is {taken[name].meaning}, shared by "
                        f"{', '.join(sorted(taken[name].components))}: state it once for the "
                        f"scene as parameters.{name} (a [parameters] table)",
                    )
        designed = {n for spec in fmus.values() for n in shared if _designs(spec.component, n)}
        for name in shared:
            if name not in taken and name not in designed:
                path, key = self.design_keys.get(name, (self.path, f"parameters.{name}"))
                if path != self.path:
                    raise ScenarioError(
                        path,
                        key,
                        "no FMU of the scene takes it (a design quantity of another "
                        "mechanism, or a misspelt name)",
                    )
                raise self.fail(
                    f"parameters.{name}",
                    "not a parameter the scene's FMUs share (set it in [fmus.<instance>] "
                    f"parameters); expected one of {sorted(taken)}"
                    if taken
                    else "no FMU of the scene shares a parameter: set it in "
                    "[fmus.<instance>] parameters",
                )

    def key_variables(self, dotted: str, fmus: dict[str, FmuSpec]) -> list[tuple[str, str, str]]:
        """The FMU variables a dotted key sets, as (instance, "parameters" or "inputs",
        variable); [] for a key that sets none (master.*, scene.*)."""
        parts = _split_key(dotted)
        if len(parts) == 4 and parts[0] == "fmus" and parts[2] in ("parameters", "inputs"):
            return [(parts[1], parts[2], parts[3])]
        if len(parts) == 2 and parts[0] == "parameters":
            shared = self.shared.get(parts[1])
            return [
                (instance, "parameters", parts[1])
                for instance, spec in fmus.items()
                if _takes(spec.component, spec.model, shared) or _designs(spec.component, parts[1])
            ]
        return []

    def fmu_file(self, entry: dict[str, Any], key: str) -> tuple[str | None, Path]:
        """(registry name or None, FMU file) of one [fmus.<instance>] table."""
        if ("component" in entry) == ("fmu" in entry):
            raise self.fail(
                key,
                f"expected exactly one of 'component' (one of {sorted(FMU_RECORDS)}) or "
                "'fmu' (the path of an FMI 2.0 co-simulation FMU, relative to the scene file)",
            )
        if "fmu" in entry:
            text = self.string(entry, "fmu", f"{key}.fmu")
            path = (self.path.parent / text).resolve()
            if not path.exists():
                raise self.fail(f"{key}.fmu", f"no FMU file at {path}")
            try:
                check_regular(path, ARCHIVE_LIMIT)  # a pipe or a device would hang the unzip
            except IsADirectoryError:
                why = f"{path} is a directory; expected an FMU file"
                raise self.fail(f"{key}.fmu", why) from None
            except NotARegularFile as exc:
                raise self.fail(f"{key}.fmu", f"{path} {exc.strerror}") from None
            return None, path
        component = self.string(entry, "component", f"{key}.component")
        if component not in FMU_RECORDS:
            raise self.fail(
                f"{key}.component",
                f"unknown {component!r}; expected one of {sorted(FMU_RECORDS)}",
            )
        try:
            return component, build_fmu(component, self.cache_dir)
        except BuildError as exc:
            raise self.fail(f"{key}.component", str(exc)) from None
        except OSError as exc:
            raise self.fail(
                f"{key}.component", f"cannot build into the FMU cache: {exc.strerror or exc}"
            ) from None

    def values(self, node: Any, key: str, model: ModelInfo) -> dict[str, Any]:
        """Values given for parameters or inputs (``key`` ends in which), in SI, checked
        against the variable's type, unit and range."""
        causality = "parameter" if key.endswith(".parameters") else "input"
        node = self.table(node, key)
        declared = {v.name: v for v in model.of(causality)}
        if causality == "input":
            node = merge_signal_overrides(node, set(declared))
        self.check_keys(node, key, set(declared))
        return {name: self.value(v, f"{key}.{name}", declared[name]) for name, v in node.items()}

    def signals_not_connected(self, connections: tuple[Connection, ...], fmus) -> None:
        for c in connections:
            instance, name = c.target
            if name in fmus[instance].signals:
                raise self.fail(
                    f"fmus.{instance}.inputs.{name}",
                    f"a signal drives it and so does {'.'.join(c.source)}; give it one driver",
                )

    def value(self, raw: Any, key: str, var: VariableInfo) -> Any:
        if var.causality == "input" and is_signal(raw):
            return read_signal(
                Reader(self.path, self.fail, self.quantity), raw, key, var, self.span
            )
        if var.type == "Boolean":
            if not isinstance(raw, bool):
                raise self.fail(key, f"expected true or false, got {raw!r}")
            return raw
        if var.type == "String":
            raise self.fail(key, "String variables cannot be set from a scene")
        if var.is_integer:
            if isinstance(raw, bool) or not isinstance(raw, int):
                raise self.fail(key, f"expected an integer ({var.type}), got {raw!r}")
            value: float = raw
        else:
            # The SANDA2V deck's masses and inertias in the report's units convert with the
            # factors its built-in data were made with (a deck typed from the report runs
            # to the bit as the built-in one); every other value as pint converts it.
            exact = "[SANDA2V: " in var.description
            value = self.quantity(raw, key, var.unit or "1", exact)
            if not math.isfinite(value):
                raise self.fail(key, f"expected a finite value, got {raw!r}")
        low = var.min if var.min is not None else -math.inf
        high = var.max if var.max is not None else math.inf
        if not low <= value <= high:
            unit = f" {var.unit}" if var.unit else ""
            raise self.fail(
                key, f"{value:g}{unit} is outside the valid range [{low:g}, {high:g}]{unit}"
            )
        return value

    def signal(
        self, text: Any, key: str, fmus: dict[str, FmuSpec], causality: str | None
    ) -> tuple[str, str]:
        if not isinstance(text, str) or "." not in text:
            raise self.fail(key, f"expected '<instance>.<variable>', got {text!r}")
        instance, var = text.split(".", 1)  # a variable's own name may hold dots
        if instance not in fmus:
            raise self.fail(key, f"no FMU instance {instance!r}; expected one of {sorted(fmus)}")
        variables = fmus[instance].model.variables
        if var not in variables or (causality and variables[var].causality != causality):
            wanted = [
                v.name for v in variables.values() if not causality or v.causality == causality
            ]
            kind = f"{causality} " if causality else ""
            owner = f"{instance!r} ({fmus[instance].fmu_name})"
            raise self.fail(key, f"{owner} has no {kind}variable {var!r}; expected one of {wanted}")
        return instance, var

    def connections(self, node: Any, fmus: dict[str, FmuSpec]) -> tuple[Connection, ...]:
        if not isinstance(node, list):
            raise self.fail("connections", "expected an array of tables ([[connections]])")
        result: list[Connection] = []
        for i, entry in enumerate(node):
            key = f"connections[{i}]"
            entry = self.table(entry, key)
            if "ports" in entry:
                self.check_keys(entry, key, {"ports"})
                for c in self.port_connection(entry["ports"], f"{key}.ports", fmus):
                    self.check_connection(c, fmus, f"{key}.ports")
                    result.append(c)
            else:
                self.check_keys(entry, key, {"from", "to"})
                for side in ("from", "to"):
                    if side not in entry:
                        raise self.fail(
                            f"{key}.{side}", "missing; expected '<instance>.<variable>'"
                        )
                src = self.signal(entry["from"], f"{key}.from", fmus, "output")
                dst = self.signal(entry["to"], f"{key}.to", fmus, "input")
                self.check_connection(Connection(src, dst), fmus, key)
                result.append(Connection(src, dst))
        targets = [c.target for c in result]
        for t in targets:
            if targets.count(t) > 1:
                raise self.fail(
                    "connections", f"input {'.'.join(t)} is driven by more than one output"
                )
        return tuple(result)

    def port_connection(self, ports: Any, key: str, fmus: dict[str, FmuSpec]) -> list[Connection]:
        if not (
            isinstance(ports, list) and len(ports) == 2 and all(isinstance(p, str) for p in ports)
        ):
            raise self.fail(key, "expected two ports, e.g. ['train.escape_wheel', 'verge.wheel']")
        sides = []
        for port in ports:
            if "." not in port or port.split(".", 1)[0] not in fmus:
                raise self.fail(
                    key, f"expected '<instance>.<port>' with a known instance, got {port!r}"
                )
            instance, name = port.split(".", 1)
            model = fmus[instance].model
            if name not in model.ports:
                known = sorted(model.ports) or "none: it declares no ports, connect variables"
                raise self.fail(key, f"{instance!r} has no port {name!r}; expected one of {known}")
            variables = model.variables
            sides.append(
                PortSide(instance, name, model.ports[name], lambda v, vs=variables: vs[v].causality)
            )
        try:
            links = join_ports(*sides)
        except PortError as exc:
            raise self.fail(key, str(exc)) from None
        return [Connection(link.source, link.target) for link in links]

    def check_connection(self, c: Connection, fmus: dict[str, FmuSpec], key: str) -> None:
        """Types must match (Real to Real, Integer or Enumeration to either) and units agree
        in dimension and scale; a side that declares no unit is accepted."""
        (si, sv), (ti, tv) = c.source, c.target
        src, dst = fmus[si].model.variables[sv], fmus[ti].model.variables[tv]
        text = f"{si}.{sv} -> {ti}.{tv}"
        if src.type not in ("Real", "Integer", "Enumeration"):
            raise self.fail(key, f"{text}: {src.type} connections are not supported")
        if (src.type == "Real") != (dst.type == "Real"):
            raise self.fail(key, f"{text} joins a {src.type} output to a {dst.type} input")
        if src.unit is None or dst.unit is None or src.unit == dst.unit:
            return
        a = fmus[si].model.base_unit(src.unit)
        b = fmus[ti].model.base_unit(dst.unit)
        if a is None or b is None:
            raise self.fail(key, f"{text}: cannot compare units {src.unit!r} and {dst.unit!r}")
        if a[0] != b[0] or not math.isclose(a[1], b[1], rel_tol=1e-12):
            raise self.fail(
                key, f"{text} joins {src.unit!r} to {dst.unit!r}: the units do not agree"
            )

    def master(self, node: dict[str, Any], fmus: dict[str, FmuSpec], duration: float) -> MasterSpec:
        kinds = setting_kinds()
        self.check_keys(node, "master", {*COMMON_KEYS, *step_keys(), *kinds})
        if "algorithm" not in node:
            raise self.fail("master.algorithm", "missing")
        algorithm = self.string(node, "algorithm", "master.algorithm")
        if algorithm not in ALGORITHMS:
            raise self.fail(
                "master.algorithm", f"unknown {algorithm!r}; expected one of {list(ALGORITHMS)}"
            )
        steps = {}
        for k in step_keys():
            if k in node:
                steps[k] = value = self.quantity(node[k], f"master.{k}", "s")
                if not value > 0.0:
                    raise self.fail(f"master.{k}", f"must be positive, got {value} s")
                if value > duration:
                    raise self.fail(
                        f"master.{k}", f"{value} s is longer than the run ({duration} s)"
                    )
        own = step_key(algorithm)
        if not steps:
            raise self.fail(f"master.{own}", f"missing; expected the {STEP_MEANING[own]}")
        used = own if own in steps else next(iter(steps))  # another master's key is lent
        step, used_key = steps[used], f"master.{used}"
        order = node.get("order", list(fmus))
        if not (
            isinstance(order, list)
            and all(isinstance(n, str) for n in order)
            and sorted(order) == sorted(fmus)
        ):
            raise self.fail("master.order", f"expected every instance once, from {sorted(fmus)}")
        fixed_step = steps.get(FixedStepSettings.STEP_KEY, step)
        try:
            options = read_options(node, self.quantity, kinds)
            settings = settings_of(algorithm, step, duration, options, fixed_step)
        except SettingError as exc:
            raise self.fail(f"master.{exc.key}", str(exc)) from None
        largest = getattr(settings, "longest_step", None)  # a master that varies its step
        if largest is None and duration / step > MAX_STEPS and not self.force:
            raise self.fail(
                used_key,
                f"{step:g} s over {duration:g} s is {duration / step:.3g} macro steps, more "
                f"than the limit {MAX_STEPS:.0e}: the run would not finish (--force to run it)",
            )
        if largest is not None:
            if duration / largest > MAX_STEPS and not self.force:
                raise self.fail(
                    "master.max_step" if "max_step" in options else used_key,
                    f"steps of at most {largest:g} s over {duration:g} s are at least "
                    f"{duration / largest:.3g} macro steps, more than the limit "
                    f"{MAX_STEPS:.0e}: the run would not finish (--force to run it)",
                )
        return MasterSpec(algorithm, fixed_step, tuple(order), options, settings)

    def output(self, node: dict[str, Any], fmus: dict[str, FmuSpec], name: str):
        self.check_keys(node, "output", {"directory", "record", "every"})
        record_raw = node.get("record")
        if record_raw is None:  # default: every output of every FMU
            record = tuple(
                (inst, v.name)
                for inst, spec in fmus.items()
                for v in spec.model.of("output")
                if v.type in RECORDED_TYPES
            ) + tuple((inst, n) for inst, spec in fmus.items() for n in spec.signals)
        else:
            if not isinstance(record_raw, list):
                raise self.fail("output.record", "expected a list of '<instance>.<variable>'")
            record = tuple(self.signal(s, "output.record", fmus, None) for s in record_raw)
            for inst, var in record:
                kind = fmus[inst].model.variables[var].type
                if kind not in RECORDED_TYPES:
                    raise self.fail(
                        "output.record",
                        f"{inst}.{var} is a {kind}: only {', '.join(RECORDED_TYPES)} "
                        "variables are recorded (Booleans as 0/1)",
                    )
        every = node.get("every", 1)
        if not isinstance(every, int) or isinstance(every, bool) or every < 1:
            raise self.fail("output.every", f"expected a positive integer, got {every!r}")
        directory = node.get("directory", f"runs/{name}")
        if not isinstance(directory, str):
            raise self.fail("output.directory", f"expected a path string, got {directory!r}")
        if not directory.strip() or "\0" in directory:
            raise self.fail("output.directory", f"expected a directory path, got {directory!r}")
        return record, every, Path(directory)

    def report(self, node: dict[str, Any], fmus: dict[str, FmuSpec]):
        if "analysis" in node:
            raise self.fail(
                "report.analysis",
                f"renamed: the scene family whose analysis and plot run is report.family "
                f"(family = {node['analysis']!r})",
            )
        self.check_keys(
            node, "report", {"headline", "family", "options", "reference", "error_bound"}
        )
        headline: dict[str, HeadlineSpec] = {}
        for hname, entry in self.table(node.get("headline", {}), "report.headline").items():
            key = f"report.headline.{hname}"
            entry = self.table(entry, key)
            self.check_keys(entry, key, {"signal", "reduce"})
            if "signal" not in entry:
                raise self.fail(f"{key}.signal", "missing; expected '<instance>.<variable>'")
            signal = self.signal(entry["signal"], f"{key}.signal", fmus, None)
            reduce = entry.get("reduce", "final")
            if not isinstance(reduce, str) or reduce not in REDUCTIONS:
                raise self.fail(
                    f"{key}.reduce", f"unknown {reduce!r}; expected one of {list(REDUCTIONS)}"
                )
            unit = fmus[signal[0]].model.variables[signal[1]].unit or "1"
            headline[hname] = HeadlineSpec(signal, reduce, unit)
        family_name = node.get("family")
        if family_name is not None:
            if not isinstance(family_name, str) or family_name not in ANALYSES:
                raise self.fail(
                    "report.family",
                    f"unknown {family_name!r}; expected one of {sorted(ANALYSES)}",
                )
        options = self.table(node.get("options", {}), "report.options")
        reference = node.get("reference")
        if reference is not None:
            if not isinstance(reference, str) or reference not in REFERENCES:
                known = sorted(REFERENCES)
                raise self.fail(
                    "report.reference", f"unknown {reference!r}; expected one of {known}"
                )
        bound = node.get("error_bound", math.inf)
        if isinstance(bound, bool) or not isinstance(bound, int | float) or not bound > 0:
            raise self.fail("report.error_bound", f"expected a positive number, got {bound!r}")
        return headline, family_name, dict(options), reference, float(bound)

    def report_needs(
        self,
        headline: dict[str, HeadlineSpec],
        family_name: str | None,
        reference: str | None,
        options: dict[str, Any],
        fmus: dict[str, FmuSpec],
        record: tuple[tuple[str, str], ...],
    ) -> None:
        """What the report reads is recorded, and its options are ones it knows."""
        recorded = {f"{i}.{v}" for i, v in record}
        for hname, spec in headline.items():
            if ".".join(spec.signal) not in recorded:
                raise self.fail(
                    f"report.headline.{hname}.signal",
                    f"{'.'.join(spec.signal)} is not recorded; add it to output.record",
                )
        users = [n for n in dict.fromkeys((family_name, reference)) if n is not None]
        needs = [family(n).needs for n in users]
        known = sorted({o.name for need in needs for o in need.options})
        for key in options:
            if key not in known:
                if not users:
                    raise self.fail(
                        f"report.options.{key}",
                        "options are read by report.family or report.reference; none named",
                    )
                raise self.fail(
                    f"report.options.{key}",
                    f"unknown key for {' and '.join(map(repr, users))}; expected one of {known}",
                )
        for need in needs:
            for option in need.options:
                if option.name in options:
                    self.report_option(option, options[option.name], fmus)
        if family_name is None:
            return
        need = family(family_name).needs
        missing = need.missing_signals(fmus, options, recorded)
        if missing:
            raise self.fail(
                "output.record",
                f"the analysis of {family_name!r} needs {', '.join(missing)} recorded; add "
                f"{'it' if len(missing) == 1 else 'them'} to output.record",
            )

    def report_option(self, option: Option, value: Any, fmus: dict[str, FmuSpec]) -> None:
        """One [report.options] value against the kind its family declares."""
        key = f"report.options.{option.name}"
        if option.kind == "instance":
            if not isinstance(value, str) or value not in fmus:
                raise self.fail(
                    key,
                    f"expected an FMU instance of the scene, one of {sorted(fmus)}; got {value!r}",
                )
        elif option.kind == "count":
            if isinstance(value, bool) or not isinstance(value, int) or value < 0:
                raise self.fail(key, f"expected a whole number >= 0, got {value!r}")
        elif option.kind == "flag":
            if not isinstance(value, bool):
                raise self.fail(key, f"expected true or false, got {value!r}")
        elif option.kind == "quantity":
            if not self.quantity(value, key, option.unit) > 0.0:
                raise self.fail(
                    key, f"expected a positive quantity in {option.unit}, got {value!r}"
                )

    def sweep(self, node: Any, fmus: dict[str, FmuSpec]) -> SweepSpec:
        node = self.table(node, "sweep")
        self.check_keys(node, "sweep", {"parameter", "values", "label", "quantities", "series"})
        parameter = self.string(node, "parameter", "sweep.parameter")
        unit = self.swept_unit(parameter, fmus)
        values = node.get("values")
        if not isinstance(values, list) or not values:
            raise self.fail("sweep.values", "expected a non-empty array of values")
        si = tuple(
            self.quantity(v, f"sweep.values[{k}]", unit) if unit else self.number(v, k)
            for k, v in enumerate(values)
        )
        quantities = node.get("quantities", [])
        if not isinstance(quantities, list) or not all(isinstance(q, str) for q in quantities):
            raise self.fail("sweep.quantities", "expected an array of headline quantity names")
        series = []
        entries = node.get("series", [])
        if not isinstance(entries, list):
            raise self.fail("sweep.series", "expected an array of tables [[sweep.series]]")
        for k, entry in enumerate(entries):
            key = f"sweep.series[{k}]"
            entry = self.table(entry, key)
            self.check_keys(entry, key, {"label", "set"})
            label = self.string(entry, "label", f"{key}.label")
            overrides = self.table(entry.get("set", {}), f"{key}.set")
            for dotted in overrides:
                self.swept_unit(dotted, fmus, f"{key}.set.{dotted}")
            series.append(SweepSeries(label, dict(overrides)))
        label = self.string(node, "label", "sweep.label", default=parameter)
        return SweepSpec(
            parameter, tuple(values), si, unit or "1", label, tuple(quantities), tuple(series)
        )

    def study(self, node: Any, fmus: dict[str, FmuSpec]) -> StudySpec:
        """The [study] table (orchestrator.studies.study_table)."""
        return parse_study(self, node, fmus)

    def swept_unit(self, dotted: str, fmus: dict[str, FmuSpec], key: str = "sweep.parameter"):
        """SI unit of a key a sweep may set (None: a plain value); fails on unknown keys."""
        parts = _split_key(dotted)
        if len(parts) == 4 and parts[0] == "fmus" and parts[2] in ("parameters", "inputs"):
            instance, kind, name = parts[1], parts[2], parts[3]
            if instance not in fmus:
                raise self.fail(key, f"unknown FMU instance {instance!r} in {dotted!r}")
            causality = "parameter" if kind == "parameters" else "input"
            var = fmus[instance].model.variables.get(name)
            inputs = {v.name for v in fmus[instance].model.of("input")}
            shorthand = split_signal_key(inputs, name) if kind == "inputs" else None
            if shorthand is not None and shorthand[0] in fmus[instance].signals:
                var = fmus[instance].model.variables[shorthand[0]]
                return "s" if shorthand[1] == "step" else var.unit or "1"
            if var is None or var.causality != causality:
                raise self.fail(key, f"{fmus[instance].fmu_name} has no {causality} {name!r}")
            return var.unit or "1"
        if len(parts) == 2 and parts[0] == "parameters":
            targets = self.key_variables(dotted, fmus)
            if not targets:
                raise self.fail(key, f"no FMU of the scene shares a parameter {parts[1]!r}")
            instance, _, name = targets[0]
            return fmus[instance].model.variables[name].unit or "1"
        kinds = setting_kinds()
        if len(parts) == 2 and parts[0] == "master" and parts[1] in kinds:
            if kinds[parts[1]].choices:
                raise self.fail(key, f"cannot sweep {dotted!r}: it is a word, not a number")
            return kinds[parts[1]].unit
        if len(parts) == 2 and parts[0] == "master" and parts[1] in COMMON_KEYS:
            return None
        if len(parts) == 2 and parts[0] == "scene" and parts[1] in ("start", "stop"):
            return "s"
        raise self.fail(
            key,
            f"cannot sweep {dotted!r}; expected fmus.<instance>.parameters.<name>, "
            "fmus.<instance>.inputs.<name>, parameters.<shared name>, master.<setting> or "
            "scene.start/stop",
        )

    def number(self, value: Any, k: int) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.fail(f"sweep.values[{k}]", f"expected a number, got {value!r}")
        return float(value)


def _families(raw: dict[str, Any]) -> tuple[str, ...]:
    """The families a scene names ([report] family and reference), before [report] is
    checked: a misspelt or missing name shares nothing, and is refused with [report]."""
    report = raw.get("report")
    if not isinstance(report, dict):
        return ()
    named = (report.get("family"), report.get("reference"))
    return tuple(dict.fromkeys(n for n in named if isinstance(n, str) and n in FAMILY_NAMES))


def _designs(component: str | None, name: str) -> bool:
    """Whether one of our FMUs (``component``) declares ``name`` a design quantity."""
    if component is None or component not in FMU_RECORDS:
        return False
    return any(v.name == name and v.design for v in FMU_RECORDS[component].variables)


def _takes(component: str | None, model: ModelInfo, shared: SharedParameter | None) -> bool:
    """Whether one of our FMUs (``component``) takes a shared parameter."""
    if shared is None or component not in shared.components:
        return False
    var = model.variables.get(shared.name)
    return var is not None and var.causality == "parameter"
