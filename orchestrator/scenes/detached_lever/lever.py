"""The lever a detached-lever scene is about: its instance, SI parameters, held drive torque
and the [report.options] the family reads."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from components.detached_lever_data import TABLE_I
from components.detached_lever_design import SEGMENTS
from orchestrator.errors import ScenarioError
from orchestrator.scene_model import Scene
from orchestrator.units import to_si

LEVER_FMU = "DetachedLever"


@dataclass(frozen=True)
class LeverScene:
    """The lever instance of a scene, its SI parameters and its held drive torque."""

    path: Path
    instance: str
    params: dict[str, float]
    drive_torque: float  # N.m, the input's start value
    driven_from_scene: bool  # the input is connected to another FMU's output
    start: float
    stop: float
    nominal: float | None  # s, stated nominal period for the rate
    load_step: float | None  # N.m, drive torque of one Table I load multiple

    @property
    def mode(self) -> int:
        return int(self.params["switching_mode"])

    @property
    def omega1(self) -> float:
        """Damped natural frequency [rad/s] of balance and hairspring."""
        p = self.params
        w0sq = p["stiffness"] / p["inertia"]
        half_c = 0.5 * p["viscous"] / p["inertia"]
        return math.sqrt(w0sq - half_c * half_c)

    @property
    def free_period(self) -> float:
        return 2.0 * math.pi / self.omega1

    @property
    def nominal_period(self) -> float:
        return self.nominal if self.nominal is not None else self.free_period

    def map_args(self) -> dict[str, Any]:
        """Arguments of ``deck_cycle_map``: the deck per unit inertia, F(n) = R(n) + X(n) of
        each segment (Monday 1965, Table III, p. 112)."""
        p = self.params
        i = p["inertia"]
        forcing = tuple(
            p[s.coulomb] / i + (p[s.ratio] * self.drive_torque / i if s.ratio else 0.0)
            for s in SEGMENTS
        )
        return {
            "c": p["viscous"] / i,
            "omega0": math.sqrt(p["stiffness"] / i),
            "forcing": forcing,
            "alpha": p["alpha"],
            "epsilon": p["epsilon"],
            "beta": p["beta"],
            "gamma": p["gamma"],
            "mu": p["mu"],
            "sigma": p["sigma"],
        }

    def component_params(self) -> dict[str, float]:
        return dict(self.params)

    def table_i_unit(self) -> int | None:
        """The Table I unit whose omega0, C/omega0 and angles the lever has, if any."""
        p = self.params
        omega0 = math.sqrt(p["stiffness"] / p["inertia"])
        c_over = p["viscous"] / p["inertia"] / omega0
        for unit, u in TABLE_I.items():
            same = (
                math.isclose(omega0, u.omega0, rel_tol=1e-9)
                and math.isclose(c_over, u.c_over_omega0, rel_tol=1e-9)
                and all(math.isclose(p[k], u.alpha) for k in ("alpha", "beta", "gamma", "mu"))
                and all(math.isclose(p[k], u.epsilon) for k in ("epsilon", "sigma"))
            )
            if same:
                return unit
        return None

    def load_multiple(self) -> float | None:
        return None if self.load_step is None else self.drive_torque / self.load_step

    def table_i_k(self) -> float | None:
        """K of the thesis's computed unit curve at this load: Table I's value at its loads,
        linear between and beyond them (Monday 1965, p. 56); None unless unit and load step are
        known."""
        unit, m = self.table_i_unit(), self.load_multiple()
        if unit is None or m is None:
            return None
        loads = [float(r.load_multiple) for r in TABLE_I[unit].rows]
        ks = [r.k for r in TABLE_I[unit].rows]
        j = 0 if m <= loads[1] else 1  # the segment that holds m, or the nearest end one
        return ks[j] + (ks[j + 1] - ks[j]) * (m - loads[j]) / (loads[j + 1] - loads[j])


_OPTIONS = ("lever", "nominal_period", "load_step")


def lever_scene(scene: Scene) -> LeverScene:
    """The scene's lever: ``[report.options] lever`` or its only DetachedLever instance."""
    options = scene.report_options
    unknown = sorted(set(options) - set(_OPTIONS))
    if unknown:
        raise ScenarioError(
            scene.path, f"report.options.{unknown[0]}", f"unknown key; expected one of {_OPTIONS}"
        )
    if "lever" in options:
        name = options["lever"]
        if name not in scene.fmus or scene.fmus[name].component != LEVER_FMU:
            levers = sorted(n for n, s in scene.fmus.items() if s.fmu_name == LEVER_FMU)
            raise ScenarioError(
                scene.path, "report.options.lever", f"expected one of the levers {levers}"
            )
    else:
        levers = [n for n, s in scene.fmus.items() if s.fmu_name == LEVER_FMU]
        if len(levers) != 1:
            raise ScenarioError(
                scene.path,
                "report.options.lever",
                f"the scene has {len(levers)} DetachedLever instances {levers}; name the one "
                "the analysis is about",
            )
        name = levers[0]
    spec = scene.fmus[name]
    cls = scene.component_class(name)
    params = {v.name: float(v.start) for v in cls.variables("parameter")}
    params.update(spec.parameters)
    drive = spec.inputs.get("drive_torque", cls.variable("drive_torque").start)
    connected = any(c.target == (name, "drive_torque") for c in scene.connections)
    return LeverScene(
        scene.path,
        name,
        params,
        float(drive),
        connected,
        scene.start,
        scene.stop,
        _positive_option(scene, "nominal_period", "s"),
        _positive_option(scene, "load_step", "N.m"),
    )


def _positive_option(scene: Scene, key: str, unit: str) -> float | None:
    if key not in scene.report_options:
        return None
    try:
        value = to_si(scene.report_options[key], unit)
    except ValueError as exc:
        raise ScenarioError(scene.path, f"report.options.{key}", str(exc)) from None
    if not value > 0.0:
        raise ScenarioError(scene.path, f"report.options.{key}", f"must be positive, got {value}")
    return value
