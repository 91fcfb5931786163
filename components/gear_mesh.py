"""One gear pair driven at a set speed against a load torque, with the mesh friction losses.

Quasi-static (Tepper 1981, ARLCD-TR-81020, App. B, eq. B18): rigid teeth, no inertia.  The driver
turns at the set speed, so its angle is exact, theta1 = theta1(t0) + omega (t - t0); the driven
member follows the mesh kinematics, theta2 = f(theta1), with the instantaneous speed ratio
R = d theta2 / d theta1.  The load torque T_L on the driven member (an input: another FMU may
supply it) is balanced through R and the point efficiency eps(theta1) of the contact in force:

    driver torque  T_1 = T_L R / eps,   input power T_1 omega,   output power T_L R omega.

Mesh models (parameter ``model``):

0. ideal: the kinematics and contact phases of involute mesh ``mesh``, eps = 1;
1. involute mesh ``mesh`` = k of Tepper 1981 (Table k + 4, k = 1..9; the Appendix E mesh is k = 2)
   with friction ``mu`` at the teeth and both pivots: eqs. 46/47 (dual contact, equal load
   sharing) and A-26 (single contact), components.mesh_efficiency;
2. clock mesh ``clock_mesh`` (1 or 2: M739_MESH1 / M739_MESH2 of
   components.clock_train_kinematics) with the
   derived round-on-round / round-on-flank efficiency (mesh_efficiency.train_mesh_efficiency,
   the statics of ClockMeshModel), pivot radii of the M739 input data.

A user pair (components.mesh_design): ``mesh = 0`` takes the involute pair from the design
parameters (every ISAD input, Tepper 1981 Apps. C-D, and which member drives), ``clock_mesh = 0``
the clock mesh in the form of Tables 1-4 (mesh_efficiency.ClockMeshModel, the gear drives).  Their
defaults are Table 6 as published and Table 1; initialization refuses a pair that breaks a
consistency rule (mesh_design.check_mesh_design).

Angles are counted in each member's own sense of rotation (both increase; the meshes are
external, so the members turn opposite ways), R > 0, and the load torque is positive when it
resists the driven member's motion.  Involute: the driver angle is the driver roll angle alpha_1
of the report (a cycle starts at ALIN, where a new pair enters).  Clock: the gear angle of
clock_train's mesh-1 convention (mesh 2 is its mirror image); a cycle starts at the handover.

Work: the output work T_L dtheta2 is exact over a step (load held, theta2 exact); the input
work T_L * integral of R / eps dtheta1 is integrated by 8-point Gauss-Legendre on each smooth
piece between the contact-phase changes, which the step is split at (the integrand jumps there),
so it is exact to rounding for the involute (a rational function with a distant pole) and for
the smooth clock pieces.  dissipated_work = input_work - output_work; nothing is stored.
``external_work`` is the input work: when the load is a scene input rather than another FMU,
the output work leaves the scene too, and the scene analysis balances it (input = output +
dissipated).  ``cycle_efficiency`` is output work / input work since the start (with no work
yet, the same ratio of the angle integrals, which any constant load gives).

Contact phases (``regime``, REGIME_NAMES) change at the entry of a new pair, at the end of dual
contact (involute) or round-on-round -> round-on-flank (clock), and where the sliding reverses
at the pitch point (approach -> recess).  ``t_event`` gives the first of them in the last step
exactly (the motion is prescribed); ``ind_contact`` and ``ind_pitch_point`` are continuous and
change sign at each of them, so any master can land on them.  Back-driving (a load that aids
the motion) and a self-locking mesh (eps <= 0) are not modelled: the component stops with a
ComponentError.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Mapping
from functools import cache

import numpy as np

from .base import COMMON_OUTPUTS, Component, ComponentError, SnapshotPlan, Variable
from .clock_train_kinematics import M739_MESH1, M739_MESH2, ClockMesh
from .design_rules import raise_first
from .event_integration import STEP_BUDGET_VARIABLE, StepBudgetSpent
from .m739_data import M739
from .mesh_design import (
    CLOCK_DESIGN,
    INVOLUTE_DESIGN,
    check_clock_design,
    check_involute_design,
    clock_pair,
    design_defaults,
    involute_pair,
)
from .mesh_efficiency import (
    LEGACY_PI,
    ClockMeshModel,
    InvoluteGeometry,
    clock_table_breaks,
    contact_efficiency,
    involute_efficiency_at,
    involute_geometry,
    involute_phase_breaks,
    train_contact_efficiency,
    train_mesh_breaks,
    train_mesh_contact,
    train_mesh_efficiency,
    train_mesh_window,
)
from .mesh_efficiency_data import (
    ALFIN_ANOMALY_TABLES,
    INVOLUTE_MESHES,
    PRINTED_RUNS,
    ClockMeshData,
    InvoluteMesh,
)

MODEL_IDEAL, MODEL_INVOLUTE, MODEL_CLOCK = 0, 1, 2

# Contact phases.  Dual contact: trailing pair, leading pair.
SINGLE_APPROACH, SINGLE_RECESS = 0, 1
DUAL_APPROACH, DUAL_MIXED, DUAL_RECESS = 2, 3, 4
ROR_APPROACH, ROR_RECESS, ROF_APPROACH, ROF_RECESS = 5, 6, 7, 8
FOR_APPROACH, FOR_RECESS = 9, 10  # pinion round on the gear flank (Tables 1-4 meshes)
REGIME_NAMES = {
    SINGLE_APPROACH: "single-approach",
    SINGLE_RECESS: "single-recess",
    DUAL_APPROACH: "dual-approach",
    DUAL_MIXED: "dual-approach-recess",
    DUAL_RECESS: "dual-recess",
    ROR_APPROACH: "round-on-round-approach",
    ROR_RECESS: "round-on-round-recess",
    ROF_APPROACH: "round-on-flank-approach",
    ROF_RECESS: "round-on-flank-recess",
    FOR_APPROACH: "flank-on-round-approach",
    FOR_RECESS: "flank-on-round-recess",
}

#: Clock meshes of the M739-like train and (gear, pinion) pivot radii of the M739 input data:
#: mesh 1 rotor gear 1 -> pinion 2, mesh 2 gear 2 -> pinion 3 (escape wheel).
CLOCK_MESHES: dict[int, tuple[ClockMesh, float, float]] = {
    1: (M739_MESH1, M739.rho1, M739.rho2),
    2: (M739_MESH2, M739.rho2, M739.rho3),
}

_GAUSS_X, _GAUSS_W = (tuple(float(v) for v in a) for a in np.polynomial.legendre.leggauss(8))


# ------------------------------------------------------------------------------------------
# Mesh models: kinematics, point efficiency, contact phases over one cycle
# ------------------------------------------------------------------------------------------
class MeshModel:
    """What the component needs of a mesh: a cycle of driver angle with its phase changes.

    breaks: driver angles in [cycle_start, cycle_start + cycle) where the phase changes, the
    first being cycle_start (a new pair takes over); kinds: "pair", "contact" or "pitch" for
    each; regimes: the regime of the piece that each break opens.
    """

    name: str
    cycle: float  # rad of driver rotation per mesh cycle
    cycle_start: float  # rad
    breaks: tuple[float, ...]
    kinds: tuple[str, ...]
    regimes: tuple[int, ...]

    def efficiency(self, theta: float) -> float:
        raise NotImplementedError

    def ratio(self, theta: float) -> float:
        """d theta2 / d theta1 > 0."""
        raise NotImplementedError

    def driven(self, theta: float) -> float:
        """Driven angle [rad] (own sense of rotation) up to a constant."""
        raise NotImplementedError

    def evaluate(self, theta: float) -> tuple[float, float, float]:
        """(driven angle, ratio, point efficiency) at driver angle theta."""
        return self.driven(theta), self.ratio(theta), self.efficiency(theta)

    def _finish(self) -> None:
        order = sorted(range(len(self.breaks)), key=lambda i: self.breaks[i])
        self.breaks = tuple(self.breaks[i] for i in order)
        self.kinds = tuple(self.kinds[i] for i in order)
        self.offsets = tuple(b - self.cycle_start for b in self.breaks)
        ends = [*self.breaks, self.cycle_start + self.cycle]
        pieces = zip(ends[:-1], ends[1:], strict=True)
        self.regimes = tuple(self._phase(0.5 * (a + b)) for a, b in pieces)

    def _phase(self, theta: float) -> int:
        """Regime at an angle inside a piece (not at a break)."""
        raise NotImplementedError

    def regime(self, theta: float) -> int:
        local = (theta - self.cycle_start) % self.cycle
        return self.regimes[max(bisect.bisect_right(self.offsets, local) - 1, 0)]

    def next_break(self, theta: float) -> float:
        """The first break angle strictly after theta."""
        base = self.cycle_start + math.floor((theta - self.cycle_start) / self.cycle) * self.cycle
        for shift in (0.0, self.cycle, 2.0 * self.cycle):
            for b in self.breaks:
                if base + shift + (b - self.cycle_start) > theta:
                    return base + shift + (b - self.cycle_start)
        raise AssertionError("unreachable: a cycle always holds a break")

    def lowest_efficiency(self) -> float:
        """Lowest point efficiency over a cycle: a 64-point grid and both sides of each phase
        change (the involute efficiency is monotone between them)."""
        eps = 1e-9 * self.cycle
        grid = [self.cycle_start + self.cycle * (k + 0.5) / 64 for k in range(64)]
        probes = grid + [b + s * eps for b in self.breaks for s in (-1.0, 1.0)]
        return min(self.efficiency(x) for x in probes)

    def indicator(self, theta: float, kinds: tuple[str, ...]) -> float:
        """Product of sin(pi (theta - b) / cycle) over the breaks of those kinds: continuous,
        with a sign change at each such break."""
        g = 1.0
        for b, kind in zip(self.breaks, self.kinds, strict=True):
            if kind in kinds:
                g *= math.sin(math.pi * (theta - b) / self.cycle)
        return g


class InvoluteModel(MeshModel):
    """Involute mesh of Tepper 1981: a stored one (Tables 5-13 as published, driver as run)
    or a user pair (``InvoluteModel.of_pair``)."""

    def __init__(
        self,
        mesh: InvoluteMesh,
        name: str,
        mu: float,
        printed_run: bool,
        ideal: bool = False,
        alpha_fin: float | None = None,
        rasfact: float = 0.883,
        points: int = 25,
    ) -> None:
        self.pair = mesh
        self.geometry: InvoluteGeometry = involute_geometry(
            mesh, alpha_fin=alpha_fin, legacy=printed_run, rasfact=rasfact
        )
        g = self.geometry
        self.mu = 0.0 if ideal else mu
        self.ideal = ideal
        self.points = points  # K of the report's cycle efficiency
        self.name = f"{'ideal ' if ideal else ''}{name}"
        self.cycle, self.cycle_start = g.cycle_angle, g.alpha_in
        self._ratio = g.driver_base_radius / g.driven_base_radius
        self._tan_op = math.tan(g.op_pressure_angle)
        self.breaks = involute_phase_breaks(g)
        self.kinds = ("pair", "contact", "pitch")
        self._finish()

    @classmethod
    def stored(cls, k: int, mu: float, printed_run: bool, ideal: bool = False) -> InvoluteModel:
        """Involute mesh k = Table k + 4; printed_run: the printed ALFIN of Tables 15-21."""
        table = k + 4
        mesh = INVOLUTE_MESHES[table]
        alpha_fin = None
        if printed_run and table in ALFIN_ANOMALY_TABLES:  # the 1981 program's ALFIN (Tables 15-21)
            alpha_fin = PRINTED_RUNS[table].alfin_deg * LEGACY_PI / 180.0
        name = f"involute mesh {k} (Table {table}, {mesh.name})"
        return cls(mesh, name, mu, printed_run, ideal, alpha_fin)

    @classmethod
    def of_pair(
        cls, design: Mapping[str, float], mu: float, printed_run: bool, ideal: bool = False
    ) -> InvoluteModel:
        """The user pair of the design parameters (the end of dual contact as the physics
        gives it: a printed ALFIN belongs to a stored run, not to its inputs)."""
        return cls(
            involute_pair(design), "user involute pair", mu, printed_run, ideal,
            rasfact=design["undercut_factor"], points=int(design["points_per_cycle"]),
        )  # fmt: skip

    def _phase(self, theta: float) -> int:
        g = self.geometry
        alpha = g.alpha_in + (theta - g.alpha_in) % g.cycle_angle
        s1 = alpha < self._tan_op
        if alpha > g.alpha_fin:
            return SINGLE_APPROACH if s1 else SINGLE_RECESS
        s2 = alpha + g.cycle_angle < self._tan_op
        return DUAL_APPROACH if s1 and s2 else (DUAL_MIXED if s1 else DUAL_RECESS)

    def efficiency(self, theta: float) -> float:
        return 1.0 if self.ideal else involute_efficiency_at(self.geometry, self.mu, theta)

    def ratio(self, theta: float) -> float:
        return self._ratio

    def driven(self, theta: float) -> float:
        return self._ratio * theta


class ClockModel(MeshModel):
    """Clock mesh of the M739-like train with the derived efficiency (gear drives)."""

    def __init__(self, k: int, mu: float) -> None:
        self.mesh, self.rho_gear, self.rho_pinion = CLOCK_MESHES[k]
        self.mu = mu
        self.name = (
            f"clock mesh {k} of the M739-like train ({self.mesh.n_gear}:{self.mesh.n_pinion})"
        )
        self.cycle_start, self.cycle = train_mesh_window(self.mesh)
        found = _clock_breaks(k)
        self.breaks = tuple(b for b, _ in found)
        self.kinds = tuple(kind for _, kind in found)
        self._transition = self.mesh.transition()[0]
        self._finish()

    def _phase(self, theta: float) -> int:
        local = self.cycle_start + (theta - self.cycle_start) % self.cycle
        reversals = sum(
            1
            for b, kind in zip(self.breaks, self.kinds, strict=True)
            if kind == "pitch" and b < local
        )
        approach = reversals % 2 == 0
        if local < self._transition:
            return ROR_APPROACH if approach else ROR_RECESS
        return ROF_APPROACH if approach else ROF_RECESS

    def efficiency(self, theta: float) -> float:
        return train_mesh_efficiency(self.mesh, self.mu, theta, self.rho_gear, self.rho_pinion)[0]

    def ratio(self, theta: float) -> float:
        return -train_mesh_contact(self.mesh, theta).ratio

    def driven(self, theta: float) -> float:
        return -train_mesh_contact(self.mesh, theta).pinion_angle

    def evaluate(self, theta: float) -> tuple[float, float, float]:
        c = train_mesh_contact(self.mesh, theta)  # one contact solution for all three
        eff = train_contact_efficiency(c, self.mu, self.rho_gear, self.rho_pinion)
        return -c.pinion_angle, -c.ratio, eff


class ClockTableModel(MeshModel):
    """Clock mesh in the form of Tepper 1981, Tables 1-4 (mesh_efficiency.ClockMeshModel,
    derived statics), the gear driving counter-clockwise."""

    def __init__(self, mesh: ClockMeshData, center_distance: float, mu: float) -> None:
        self.model = ClockMeshModel(mesh, center_distance)
        self.mu = mu
        self.rho_gear, self.rho_pinion = mesh.gear_pivot_radius, mesh.pinion_pivot_radius
        self.name = f"{mesh.name} ({mesh.n_gear}:{mesh.n_pinion}, Tables 1-4 form)"
        found = _clock_table_breaks(mesh, center_distance)
        self.cycle_start, self.cycle = found[0][0], self.model.pitch_g
        self.breaks = tuple(b for b, _, _, _ in found)
        self.kinds = tuple(kind for _, kind, _, _ in found)
        self._phases = {b: (phase, approach) for b, _, phase, approach in found}
        self._finish()

    def _phase(self, theta: float) -> int:
        local = self.cycle_start + (theta - self.cycle_start) % self.cycle
        opening = max(b for b in self.breaks if b <= local)
        phase, approach = self._phases[opening]
        a, r = {"ror": (ROR_APPROACH, ROR_RECESS), "rof": (ROF_APPROACH, ROF_RECESS),
                "for": (FOR_APPROACH, FOR_RECESS)}[phase]  # fmt: skip
        return a if approach else r

    def evaluate(self, theta: float) -> tuple[float, float, float]:
        c = self.model.contact(theta)
        eff, ratio = contact_efficiency(
            _ORIGIN, self.model.o_p, c.contact, c.normal, self.mu, self.rho_gear, self.rho_pinion
        )
        return -c.pinion_angle, -ratio, eff

    def efficiency(self, theta: float) -> float:
        return self.evaluate(theta)[2]

    def ratio(self, theta: float) -> float:
        return self.evaluate(theta)[1]

    def driven(self, theta: float) -> float:
        return -self.model.contact(theta).pinion_angle


_ORIGIN = np.zeros(2)


@cache
def _clock_breaks(k: int) -> tuple[tuple[float, str], ...]:
    """Phase changes of clock mesh k, found once per process (root finding)."""
    return train_mesh_breaks(CLOCK_MESHES[k][0])


@cache
def _clock_table_breaks(mesh: ClockMeshData, center_distance: float):  # noqa: ANN202
    """Phase changes of a Tables 1-4 clock mesh, found once per design (root finding)."""
    return clock_table_breaks(ClockMeshModel(mesh, center_distance))


def build_mesh(
    model: int,
    mesh: int,
    clock_mesh: int,
    mu: float,
    printed_run: int,
    design: Mapping[str, float] | None = None,
) -> MeshModel:
    """The mesh model the parameters select; ComponentError naming the parameter if invalid.

    design: the design parameters (mesh_design; missing ones take their defaults), read when
    ``mesh = 0`` or ``clock_mesh = 0`` selects the user pair, whose consistency rules are
    checked first (DesignError on the first broken one).
    """

    def choice(name: str, value: float, allowed: range) -> int:
        if value != int(value) or int(value) not in allowed:
            raise ComponentError(
                f"GearMesh: {name} must be one of {list(allowed)}, got {value!r}"
                + (
                    " (involute mesh k is Table k + 4 of Tepper 1981, 0 the user pair)"
                    if name == "mesh"
                    else ""
                )
            )
        return int(value)

    m = choice("model", model, range(3))
    if not (math.isfinite(mu) and mu >= 0.0):
        raise ComponentError(f"GearMesh: mu must be >= 0, got {mu!r}")
    if m == MODEL_CLOCK:
        c = choice("clock_mesh", clock_mesh, range(3))
        if c > 0:
            return ClockModel(c, mu)
        p = design_defaults() | dict(design or {})
        raise_first(check_clock_design(clock_pair(p), p["clock_center_distance"]))
        return ClockTableModel(clock_pair(p), p["clock_center_distance"], mu)
    k = choice("mesh", mesh, range(10))
    legacy = choice("printed_run", printed_run, range(2)) == 1
    if k > 0:
        return InvoluteModel.stored(k, mu, legacy, ideal=m == MODEL_IDEAL)
    p = design_defaults() | dict(design or {})
    for name in ("n_pinion", "points_per_cycle", "gear_drives"):
        if p[name] != int(p[name]):
            raise ComponentError(f"GearMesh: {name} must be a whole number, got {p[name]!r}")
    choice("gear_drives", p["gear_drives"], range(2))
    raise_first(check_involute_design(involute_pair(p), p["undercut_factor"]))
    return InvoluteModel.of_pair(p, mu, legacy, ideal=m == MODEL_IDEAL)


# ------------------------------------------------------------------------------------------
# The component
# ------------------------------------------------------------------------------------------
class GearMesh(Component):
    """A gear pair: driver at a set speed, driven member against a load torque (quasi-static)."""

    REGIME_NAMES = REGIME_NAMES

    # Angles and speeds out, torque in, each in the member's own sense of rotation; the load
    # torque resists the driven member's motion.
    PORTS = {
        "driver": {"angle": "driver_angle", "speed": "driver_speed", "torque": "driver_torque"},
        "driven": {"angle": "driven_angle", "speed": "driven_speed", "torque": "load_torque"},
    }

    SNAPSHOT = SnapshotPlan()  # scalars (and caches of parameters): shared, not pickled
    VARIABLES = (
        Variable(
            "model", "parameter", "1", MODEL_INVOLUTE,
            "mesh model: 0 ideal, 1 involute mesh of Tepper 1981, 2 clock mesh (derived)",
            "Integer", min=MODEL_IDEAL, max=MODEL_CLOCK,
        ),
        Variable(
            "mesh", "parameter", "1", 2,
            "involute mesh k = 1..9: Table k + 4 of Tepper 1981 (2: the Appendix E mesh); "
            "0: the user pair of the design parameters",
            "Integer", min=0, max=9,
        ),
        Variable(
            "clock_mesh", "parameter", "1", 1,
            "clock mesh 1 or 2 of the M739-like two-pass train (M739_MESH1 / M739_MESH2); "
            "0: the user clock mesh (Tables 1-4 form) of the design parameters",
            "Integer", min=0, max=2,
        ),
        Variable(
            "printed_run", "parameter", "1", 0,
            "1: as the 1981 program ran (pi = 3.14159, printed ALFIN of Tables 15, 16, 18, 21)",
            "Integer", min=0, max=1,
        ),
        Variable(
            "mu", "parameter", "1", 0.1, "Coulomb friction at the teeth and both pivots", min=0.0
        ),
        Variable("speed", "parameter", "rad/s", 10.0, "set speed of the driver (> 0)", min=0.0),
        Variable(
            "phase0", "parameter", "1", 0.0,
            "start within the mesh cycle, as a fraction of it (0: a new pair enters)",
            min=0.0, max=1.0,
        ),
        *INVOLUTE_DESIGN,
        *CLOCK_DESIGN,
        Variable(
            "load_torque", "input", "N.m", 0.1,
            "torque resisting the driven member's motion (>= 0)",
        ),
        Variable("driver_angle", "output", "rad", 0.0, "driver angle (involute: roll angle)"),
        Variable("driven_angle", "output", "rad", 0.0, "driven rotation since the start"),
        Variable("driver_speed", "output", "rad/s", 0.0, "driver speed (the set speed)"),
        Variable("driven_speed", "output", "rad/s", 0.0, "driven member speed"),
        Variable("speed_ratio", "output", "1", 0.0, "instantaneous speed ratio driven/driver"),
        Variable("efficiency", "output", "1", 1.0, "point (instantaneous) efficiency"),
        Variable(
            "driver_torque", "output", "N.m", 0.0, "torque driving the driver",
            depends_on=("load_torque",),
        ),
        Variable(
            "input_power", "output", "W", 0.0, "power into the driver",
            depends_on=("load_torque",),
        ),
        Variable(
            "output_power", "output", "W", 0.0, "power delivered to the load",
            depends_on=("load_torque",),
        ),
        Variable("input_work", "output", "J", 0.0, "work done on the driver since the start"),
        Variable("output_work", "output", "J", 0.0, "work delivered to the load since the start"),
        Variable("external_work", "output", "J", 0.0, "work brought in by the drive"),
        Variable("cycle_efficiency", "output", "1", 1.0, "output work / input work so far"),
        Variable("mesh_cycles", "output", "1", 0.0, "driver rotation in mesh cycles"),
        Variable("t_event", "output", "s", -1.0, "first contact-phase change in the last step"),
        Variable("ind_contact", "output", "1", 1.0, "changes sign where a pair enters or leaves"),
        Variable("ind_pitch_point", "output", "1", 1.0, "changes sign where the sliding reverses"),
        *COMMON_OUTPUTS,
        STEP_BUDGET_VARIABLE,
    )  # fmt: skip

    # -- life cycle -------------------------------------------------------------------
    def initialize(self, t0: float) -> None:
        design = {v.name: getattr(self, v.name) for v in INVOLUTE_DESIGN + CLOCK_DESIGN}
        self._cache_model = build_mesh(
            self.model, self.mesh, self.clock_mesh, self.mu, self.printed_run, design
        )
        m = self._cache_model
        if not (math.isfinite(self.speed) and self.speed > 0.0):
            raise ComponentError(f"GearMesh: speed must be positive, got {self.speed!r}")
        if not 0.0 <= self.phase0 < 1.0:
            raise ComponentError(f"GearMesh: phase0 must be in [0, 1), got {self.phase0!r}")
        self._t0 = self._t = float(t0)
        self._theta0 = m.cycle_start + self.phase0 * m.cycle
        self._driven0 = m.driven(self._theta0)
        # Angle integrals of R and R / eps since the start (work per unit constant load).
        self._int_ratio = self._int_ratio_eff = 0.0
        self.input_work = self.output_work = 0.0
        self.t_event = -1.0
        lowest = m.lowest_efficiency()
        if not lowest > 0.0:
            raise ComponentError(self._locked(None, lowest))
        self.update_outputs()

    def _locked(self, theta: float | None, eff: float) -> str:
        where = "in the mesh cycle" if theta is None else f"at driver angle {theta:.6g} rad"
        return (
            f"GearMesh: point efficiency {eff:.4g} <= 0 {where} with mu = {self.mu}: "
            "the mesh locks (self-locking is not modelled); expected a smaller mu"
        )

    def _angle(self, t: float) -> float:
        # From the time, not accumulated: the same bits as any reference computing it so.
        return self._theta0 + self.speed * (t - self._t0)

    def update_outputs(self) -> None:
        m = self._cache_model
        theta = self._angle(self._t)
        driven, ratio, eff = m.evaluate(theta)
        self.driver_angle = theta
        self.driven_angle = driven - self._driven0
        self.driver_speed = self.speed
        self.driven_speed = ratio * self.speed
        self.speed_ratio = ratio
        self.efficiency = eff
        self.driver_torque = self.load_torque * ratio / eff
        self.input_power = self.driver_torque * self.speed
        self.output_power = self.load_torque * ratio * self.speed
        self.external_work = self.input_work
        self.dissipated_work = self.input_work - self.output_work
        self.stored_energy = 0.0
        if self.input_work > 0.0:
            self.cycle_efficiency = self.output_work / self.input_work
        elif self._int_ratio_eff > 0.0:
            self.cycle_efficiency = self._int_ratio / self._int_ratio_eff
        else:
            self.cycle_efficiency = eff  # the limit as the run begins
        self.mesh_cycles = (theta - m.cycle_start) / m.cycle
        self.regime = m.regime(theta)
        self.ind_contact = m.indicator(theta, ("pair", "contact"))
        self.ind_pitch_point = m.indicator(theta, ("pitch",))

    def step(self, t: float, h: float) -> None:
        if self.load_torque < 0.0:
            raise ComponentError(
                f"GearMesh: load_torque {self.load_torque:.6g} N.m < 0 aids the motion; "
                "back-driving the mesh is not modelled"
            )
        m = self._cache_model
        a, b = self._angle(t), self._angle(t + h)
        first_event = None
        int_r = int_re = 0.0
        lo = a
        pieces, budget = 0, int(self.max_internal_steps)
        while lo < b:
            pieces += 1
            if pieces > budget:  # nothing of the step is kept yet
                raise StepBudgetSpent(
                    f"GearMesh: the step from t = {t:.9g} s over {h:.6g} s spent its budget "
                    f"of {budget} internal steps (max_internal_steps): smooth pieces between "
                    "contact changes; take shorter communication steps or give a larger budget"
                )
            nxt = m.next_break(lo)
            hi = min(nxt, b)
            if nxt <= b and first_event is None:
                first_event = self._t0 + (nxt - self._theta0) / self.speed
            # Gauss-Legendre on the smooth piece [lo, hi]
            mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
            for x, w in zip(_GAUSS_X, _GAUSS_W, strict=True):
                theta = mid + half * x
                _, r, eff = m.evaluate(theta)
                if eff <= 0.0:
                    raise ComponentError(self._locked(theta, eff))
                int_r += w * half * r
                int_re += w * half * r / eff
            lo = hi
        driven_before = self.driven_angle
        self._t = t + h
        self._int_ratio += int_r
        self._int_ratio_eff += int_re
        self.input_work += self.load_torque * int_re
        # Output work from the exact driven rotation (not the quadrature of R).
        driven_after = m.driven(b) - self._driven0
        self.output_work += self.load_torque * (driven_after - driven_before)
        if first_event is not None:
            self.t_event = first_event
        self.update_outputs()
