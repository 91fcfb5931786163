"""Press roll feed scenes (Xu 1993): analysis, plot and monolithic reference.

A press-feed scene holds one ``CrankCouplerDrive`` (crank, RSSR linkage, elastic coupler;
the rocker is the clutch's outer race), one ``SpragClutch`` and one ``BrakeLoad`` (roller
shaft, strip, brake).  The thesis regimes of a cycle (Part I §3f, p. 14) follow from the three
discrete states: 1 windup (engaged, shaft stuck, rocker forward), 2 feed (shaft slipping),
3 unwinding (engaged, stuck, rocker returning), 4 overrun (clutch disengaged).

Cycles are crank revolutions counted from the scene start, where the rocker is at its
extreme (start of Regime 1); the first one is the start-up cycle.  The reference
(``orchestrator.scenes.press_feed.monolithic``) is reduced with the same definitions, so its
headline values carry the same names as those of ``analyse``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from components.brake_load import REGIME_NAMES as BRAKE_NAMES
from components.brake_load import REGIME_SLIP_FORWARD, REGIME_STICK, BrakeLoad
from components.crank_coupler_drive import (
    REGIME_FORWARD,
    CrankCouplerDrive,
    build_drive_model,
    rocker_angles,
    with_inertia,
)
from components.crank_coupler_drive import REGIME_NAMES as DRIVE_NAMES
from components.press_feed_data import (
    C_NL,
    C_SP,
    K_SP,
    N_DAMP,
    BentCoupler,
    RSSRLinkage,
)
from components.rssr_kinematics import ExactRSSR, rocker_extremes
from components.sprag_clutch import MODEL_HERTZ, MODEL_LUMPED, REGIME_ENGAGED, SpragClutch
from components.sprag_clutch import REGIME_NAMES as CLUTCH_NAMES
from components.units import RPM
from orchestrator.plotting import (
    event_lines,
    of,
    pyplot,
    recorded,
    regime_colours,
    regime_names,
    regime_spans,
    regime_strip,
    run_events,
    save_figure,
    unit_label,
)
from orchestrator.scene_model import Scene
from orchestrator.scenes.family import Quantity, Reference, quantity
from orchestrator.scenes.press_feed.monolithic import (
    FeedOptions,
    peak_to_trough_ratios,
    simulate_feed,
)

WINDUP, FEED, UNWIND, OVERRUN = 1, 2, 3, 4
REGIME_LABELS = {WINDUP: "windup", FEED: "feed", UNWIND: "unwind", OVERRUN: "overrun"}
# The reference series is sampled at least this finely, so that interpolating it adds
# far less error than the coupling error it measures.
_REF_SAMPLE = 2.0e-5  # s
DECAY_PEAKS = 3  # Table 2 averages the first three ratios after the first amplitude


# -- the scene's instances and parameters ---------------------------------------------------
@dataclass(frozen=True)
class FeedScene:
    """Instance names and SI parameters of a press-feed scene."""

    drive: str
    clutch: str
    load: str
    p_drive: dict[str, float]
    p_clutch: dict[str, float]
    p_load: dict[str, float]

    @property
    def omega(self) -> float:
        """Crank speed [rad/s]."""
        cs = self.p_drive["crank_speed"]
        return cs if cs > 0.0 else self.p_drive["rpm"] * RPM

    @property
    def period(self) -> float:
        return 2.0 * math.pi / self.omega

    @property
    def rigid(self) -> bool:
        return self.p_drive["rigid"] > 0.5

    def linkage(self) -> RSSRLinkage:
        p = self.p_drive
        return RSSRLinkage(p["a1"], p["a3"], p["a4"], p["s1"], p["s2"], p["s3"])

    def coupler(self) -> BentCoupler:
        """The drive's coupler, with P1 and the factors it uses (given or computed)."""
        return self._inertia()[0]

    def f1(self) -> tuple[float, float, float]:
        """The F1 Fourier coefficients the drive uses (given or computed) [m^2]."""
        return self._inertia()[1]

    def _inertia(self) -> tuple[BentCoupler, tuple[float, float, float]]:
        p = self.p_drive
        given = BentCoupler(
            length=p["L"],
            alpha=p["alpha"],
            d_outer=p["d_outer"],
            d_inner=p["d_inner"],
            youngs=p["youngs"],
            density=p["density"],
            c_co=p["c_co"],
            p1=p["p1"],
            gauge_x1=p["gauge_x1"],
            lumped_mass=p["lumped_mass"],
        )
        f1 = (p["f1_a0"], p["f1_a1"], p["f1_b1"])
        return with_inertia(self.linkage(), given, f1, p["coupler_inertia"])

    def crank_start(self) -> float:
        """Crank angle at the scene start [rad], as the drive computes it."""
        if self.p_drive["start_at_max"] > 0.5:
            return rocker_extremes(ExactRSSR(self.linkage(), self.p_drive["alpha"]))[1]
        return self.p_drive["phi1_0"]


def _parameters(scene: Scene, instance: str, cls: type) -> dict[str, float]:
    values = {v.name: float(v.start) for v in cls.variables("parameter")}
    values.update(scene.fmus[instance].parameters)
    return values


def feed_scene(scene: Scene) -> FeedScene:
    """The drive, clutch and load instances of a scene (exactly one of each)."""
    found: dict[str, list[str]] = {"CrankCouplerDrive": [], "SpragClutch": [], "BrakeLoad": []}
    for name, spec in scene.fmus.items():
        if spec.component in found:
            found[spec.component].append(name)
    for fmu, names in found.items():
        if len(names) != 1:
            raise ValueError(f"press feed scene {scene.name}: needs one {fmu}, found {names}")
    d, c, b = (found[k][0] for k in ("CrankCouplerDrive", "SpragClutch", "BrakeLoad"))
    return FeedScene(
        d,
        c,
        b,
        _parameters(scene, d, CrankCouplerDrive),
        _parameters(scene, c, SpragClutch),
        _parameters(scene, b, BrakeLoad),
    )


# -- reductions shared by the run and the reference -------------------------------------------
def thesis_regime(drive: np.ndarray, clutch: np.ndarray, load: np.ndarray) -> np.ndarray:
    """Thesis regime number from the three discrete states (arrays of equal length)."""
    forward = np.where(np.asarray(drive) == REGIME_FORWARD, WINDUP, UNWIND)
    stuck = np.where(np.asarray(load) != REGIME_STICK, FEED, forward)
    return np.where(np.asarray(clutch) == REGIME_ENGAGED, stuck, OVERRUN).astype(int)


def transitions_from_samples(times: np.ndarray, regime: np.ndarray) -> list[tuple[float, int]]:
    """(time, regime entered) with the first sample's regime at its time.

    A switch seen between two samples is put at their midpoint: the fixed-step masters only
    know it happened inside that step, and the midpoint is the unbiased estimate.
    """
    out = [(float(times[0]), int(regime[0]))]
    for i in np.nonzero(np.diff(regime))[0]:
        out.append((0.5 * float(times[i] + times[i + 1]), int(regime[i + 1])))
    return out


def regime_timing(
    transitions: list[tuple[float, int]], t0: float, t1: float, omega: float, phi1_0: float
) -> dict[str, float]:
    """Regime timing of the cycle [t0, t1).

    Fractions of the cycle spent in each regime; crank angles of the first break-away
    (feed), of the first return with the shaft stuck (unwind), of the last disengagement
    (overrun; a clutch that unloads mid-feed, which the thesis
    excludes by its eq. (65), disengages more than once:
    ``disengagements`` counts them) and of the last engagement (``engage_angle``).

    ``transitions`` are (time, regime entered), in time order, starting at or before t0;
    crank angles are phi1 = phi1_0 + omega t (times relative to the scene start), mod 2 pi.
    """
    out: dict[str, float] = {}
    spent = dict.fromkeys(REGIME_LABELS, 0.0)
    disengagements = 0
    for k, (t, r) in enumerate(transitions):
        t_next = transitions[k + 1][0] if k + 1 < len(transitions) else math.inf
        lo, hi = max(t, t0), min(t_next, t1)
        if hi > lo:
            spent[r] += hi - lo
        if not (t0 <= t < t1 and k > 0):
            continue
        angle = (phi1_0 + omega * t) % (2.0 * math.pi)
        if r in (FEED, UNWIND) and f"{REGIME_LABELS[r]}_start_angle" not in out:
            out[f"{REGIME_LABELS[r]}_start_angle"] = angle  # first break-away, first return
        elif r == OVERRUN:
            out["overrun_start_angle"] = angle  # the disengagement that ends the stroke
            disengagements += 1
    for r, label in REGIME_LABELS.items():
        out[f"{label}_fraction"] = spent[r] / (t1 - t0)
    out["disengagements"] = float(disengagements)
    last = [
        t
        for k, (t, r) in enumerate(transitions)
        if k > 0 and r == WINDUP and transitions[k - 1][1] == OVERRUN
    ]
    if last:
        out["engage_angle"] = (phi1_0 + omega * last[-1]) % (2.0 * math.pi)
    return out


def regime_sequences(
    transitions: list[tuple[float, int]], period: float, n_cycles: int
) -> list[list[int]]:
    """Regimes entered within each crank cycle [k P, (k+1) P), in order (repeats merged)."""
    seqs: list[list[int]] = [[] for _ in range(n_cycles)]
    for t, r in transitions:
        c = int(math.floor(t / period + 1e-12))
        if 0 <= c < n_cycles and (not seqs[c] or seqs[c][-1] != r):
            seqs[c].append(r)
    return seqs


def decay_ratios(windup: np.ndarray, feeding: np.ndarray) -> list[float]:
    """App. K peak-to-trough ratios of the windup during the first feed in the samples."""
    idx = np.nonzero(feeding)[0]
    if len(idx) < 3:
        return []
    end = idx[0]
    while end + 1 < len(feeding) and feeding[end + 1]:
        end += 1
    return peak_to_trough_ratios(windup[idx[0] : end + 1])


def _complete_cycles(duration: float, period: float) -> int:
    return int(math.floor(duration / period + 1e-9))


def _normal_cycles(n: int, startup: int) -> range:
    """Cycles after start-up; all cycles when the run has no other."""
    return range(startup, n) if n > startup else range(n)


# -- analysis of a run ---------------------------------------------------------------------------
def analyse(
    scene: Scene, header: list[str], data: np.ndarray, options: dict[str, Any]
) -> dict[str, Quantity]:
    """Headline quantities of a press-feed run (see the module doc for the definitions).

    Needs recorded: drive.regime, clutch.regime, clutch.windup, load.regime,
    load.feed_length (and drive.q, drive.strain, drive.strain_b for an elastic coupler).
    Options: ``startup_cycles`` (default 1), cycles left out of the means;
    ``decay_ratios`` (default false), also report the mean App. K decay ratio of the windup
    over the first feed of the last cycle (Part II experiment).
    """
    fs = feed_scene(scene)
    col = {name: data[:, i] for i, name in enumerate(header)}
    t = col["time"] - scene.start
    n = _complete_cycles(t[-1], fs.period)
    out: dict[str, Quantity] = {}
    if n == 0:
        raise ValueError(_no_cycle(t[-1], fs.period))
    startup = int(options.get("startup_cycles", 1))
    normal = _normal_cycles(n, startup)
    regime = thesis_regime(
        col[f"{fs.drive}.regime"], col[f"{fs.clutch}.regime"], col[f"{fs.load}.regime"]
    )
    feed_len = col[f"{fs.load}.feed_length"]
    bounds = np.interp(np.arange(n + 1) * fs.period, t, feed_len)
    per_cycle = np.diff(bounds)
    out["feed_length_mean"] = quantity(np.mean(per_cycle[list(normal)]), "m")
    out["feed_length_last"] = quantity(per_cycle[-1], "m")
    windup = col[f"{fs.clutch}.windup"]
    in_run = t <= n * fs.period + 1e-12
    out["peak_windup"] = quantity(np.max(windup[in_run]), "rad")
    cycle_of = np.floor(t / fs.period + 1e-12).astype(int)
    sel = np.isin(cycle_of, list(normal)) & (col[f"{fs.load}.regime"] == REGIME_SLIP_FORWARD)
    if sel.any():
        out["mean_windup_feed"] = quantity(time_mean(t, windup, sel), "rad")
    if not fs.rigid:
        for name, signal, unit in (
            ("peak_deflection", "q", "m"),
            ("peak_strain", "strain", "1"),
            ("peak_strain_b", "strain_b", "1"),
        ):
            out[name] = quantity(np.max(np.abs(col[f"{fs.drive}.{signal}"][in_run])), unit)
    trans = transitions_from_samples(t, regime)
    timing = regime_timing(trans, (n - 1) * fs.period, n * fs.period, fs.omega, fs.crank_start())
    for name, value in timing.items():
        out[name] = quantity(value, "rad" if name.endswith("angle") else "1")
    if options.get("decay_ratios", False):
        ratios = decay_ratios(windup, (cycle_of == n - 1) & (regime == FEED))
        if ratios:
            out["decay_ratio"] = quantity(np.mean(ratios[:DECAY_PEAKS]), "1")
    ext = f"{fs.drive}.external_work"
    if ext in col:
        out["crank_work_per_cycle"] = quantity(
            np.diff(np.interp([0, n * fs.period], t, col[ext]))[0] / n, "J"
        )
    return out


def _no_cycle(duration: float, period: float) -> str:
    return (
        f"the run covers {duration:.6g} s, less than one crank cycle ({period:.6g} s): "
        "no per-cycle quantity to compute"
    )


def time_mean(t: np.ndarray, x: np.ndarray, sel: np.ndarray) -> float:
    """Time average of x over the intervals whose two ends are selected (trapezoids).

    The regime-aware master samples densely near switches; a plain mean of the samples
    would weight those instants far more than the rest.
    """
    both = sel[:-1] & sel[1:]
    dt = np.diff(t)[both]
    if dt.sum() <= 0.0:
        return float(np.mean(x[sel]))
    return float(np.sum(0.5 * (x[:-1] + x[1:])[both] * dt) / dt.sum())


def run_regime_sequences(scene: Scene, header: list[str], data: np.ndarray) -> list[list[int]]:
    """Thesis regimes entered in each complete crank cycle of a recorded run."""
    fs = feed_scene(scene)
    col = {name: data[:, i] for i, name in enumerate(header)}
    t = col["time"] - scene.start
    regime = thesis_regime(
        col[f"{fs.drive}.regime"], col[f"{fs.clutch}.regime"], col[f"{fs.load}.regime"]
    )
    return regime_sequences(
        transitions_from_samples(t, regime), fs.period, _complete_cycles(t[-1], fs.period)
    )


def sampled_events(
    scene: Scene, header: list[str], data: np.ndarray
) -> list[tuple[float, str, str, str]]:
    """Regime switches of each subsystem seen in the recorded regime signals.

    (t, instance, from, to) with the components' regime names, t the midpoint of the two
    samples around the switch: what a fixed-step master, which logs no events, can tell.
    """
    fs = feed_scene(scene)
    t = data[:, header.index("time")]
    out = []
    for inst, names in ((fs.drive, DRIVE_NAMES), (fs.clutch, CLUTCH_NAMES), (fs.load, BRAKE_NAMES)):
        r = data[:, header.index(f"{inst}.regime")].astype(int)
        for i in np.nonzero(np.diff(r))[0]:
            out.append((0.5 * (t[i] + t[i + 1]), inst, names[r[i]], names[r[i + 1]]))
    return sorted(out)


# -- plot ------------------------------------------------------------------------------------------
def plot(scene: Scene, header: list[str], data: np.ndarray, path: Path) -> None:
    """Over the crank cycles: the regimes of drive, clutch and load as named bands, the feed
    roll angle, the clutch windup and torque and the coupler strain, switches at their
    located times."""
    plt = pyplot()
    fs = feed_scene(scene)
    col = {name: data[:, i] for i, name in enumerate(header)}
    t = col["time"]
    events = run_events(path)
    strain = col.get(f"{fs.drive}.strain")
    panels = [
        (f"{fs.load}.angle", "feed roll angle", "deg", np.degrees),
        (f"{fs.clutch}.windup", "clutch windup", "mrad", lambda x: 1e3 * x),
        (f"{fs.clutch}.torque", "clutch torque", "N·m", lambda x: x),
    ]
    if strain is not None and not fs.rigid:
        panels.append((f"{fs.drive}.strain", "coupler strain at gauge", "µε", lambda x: 1e6 * x))
    panels = [p for p in panels if p[0] in col]
    fig, axes = plt.subplots(
        1 + len(panels),
        1,
        figsize=(11, 2.4 + 2.1 * len(panels)),
        sharex=True,
        height_ratios=(0.8, *(1.0,) * len(panels)),
        layout="constrained",
    )
    rows = []
    for k, (instance, label) in enumerate(
        ((fs.drive, "drive"), (fs.clutch, "clutch"), (fs.load, "load"))
    ):
        names = regime_names(scene, instance)
        spans = regime_spans(t, col[f"{instance}.regime"], names, of(events, instance))
        rows.append((label, spans, regime_colours(names, 2 * k)))
    regime_strip(axes[0], rows)
    for ax, (column, what, unit, convert) in zip(axes[1:], panels, strict=True):
        recorded(ax, t, convert(col[column]), color="C0")
        unit_label(ax, what, unit)
        ax.grid(True, alpha=0.3)
    event_lines(axes[1:], [e[0] for e in events], colour="0.5", style=":", width=0.7)
    cycles = np.arange(scene.start, t[-1], fs.period)
    cycles = cycles[cycles < t[-1] - 1e-9 * fs.period]  # the last row is no cycle's start
    event_lines(axes, cycles, colour="k", width=1.0)
    for k, tc in enumerate(cycles):
        axes[0].text(tc, 1.02, f" cycle {k + 1}", transform=axes[0].get_xaxis_transform())
    axes[-1].set_xlabel("time [s]")
    axes[-1].set_xlim(t[0], t[-1])
    axes[1].set_title(
        "black: crank cycle starts; dotted: regime switches (located times, events.csv)",
        fontsize=9,
        loc="left",
    )
    save_figure(fig, path, f"{scene.name}: press roll feed over {len(cycles)} crank cycles")


# -- monolithic reference --------------------------------------------------------------------------
def _same(a: float, b: float) -> bool:
    return math.isclose(a, b, rel_tol=1e-9, abs_tol=1e-15)


def feed_options(scene: Scene):
    """FeedOptions of the monolithic reference for a scene; ValueError if it cannot match."""
    fs = feed_scene(scene)
    pd, pc, pl = fs.p_drive, fs.p_clutch, fs.p_load
    defaults = {v.name: float(v.start) for v in CrankCouplerDrive.variables("parameter")}

    def need(ok: bool, what: str) -> None:
        if not ok:
            raise ValueError(f"press feed reference for {scene.name}: {what}")

    need(pd["start_at_max"] > 0.5, "the drive must start at the rocker extreme")
    run = 1
    coupler = None
    if not fs.rigid:
        coupler = fs.coupler()
        run = 3 if coupler.lumped_mass > 0.0 else 1
        # Any bent coupler of the standard shape (Runs 1-3, or a stiffer/denser tube).
        for name in ("j_o4", "f2_const"):
            need(_same(pd[name], defaults[name]), f"drive parameter {name} must keep its default")
    clutch_defaults = {v.name: float(v.start) for v in SpragClutch.variables("parameter")}
    if pc["model"] == MODEL_HERTZ:
        geometry = ("r_outer", "r_inner", "r_sprag", "sprag_offset", "n_sprags", "strut_inner",
                    "strut_outer", "youngs", "poisson")  # fmt: skip
        need(
            all(_same(pc[g], clutch_defaults[g]) for g in geometry),
            "clutch: the two-point Hertz model needs the Table 4 sprag geometry",
        )
    else:
        need(pc["model"] == MODEL_LUMPED and _same(pc["k"], K_SP), "clutch: lumped K = 2e5 lbf*in")
    need(pc["engaged0"] > 0.5 and _same(pc["n_damp"], N_DAMP), "clutch: engaged0 = 1, n = 1/4")
    if pc["c_lin"] == 0.0 and _same(pc["c_nl"], C_NL):
        damping = "nonlinear"
    elif pc["c_nl"] == 0.0 and _same(pc["c_lin"], C_SP):
        damping = "linear"
    else:
        raise ValueError(f"press feed reference for {scene.name}: clutch damping not C_nl or C_sp")
    need(pl["angle0"] == 0.0 and pl["speed0"] == 0.0, "the load must start at rest at angle 0")
    duration = scene.stop - scene.start
    return FeedOptions(
        run=run,
        damping=damping,
        coupler="rigid" if fs.rigid else "elastic",
        clutch="hertz" if pc["model"] == MODEL_HERTZ else "lumped",
        bent_coupler=coupler,
        cycles=max(1, math.ceil(duration / fs.period - 1e-9)),
        rpm=fs.omega / RPM,
        brake_torque=pl["brake_torque"],
        j5=pl["j"],
        linkage=fs.linkage(),
        f1=None if fs.rigid else fs.f1(),
        samples_per_cycle=max(1440, math.ceil(fs.period / _REF_SAMPLE)),
    )


def _subsystem_events(res, fs: FeedScene, duration: float) -> list[tuple[float, str, str, str]]:
    """Reference events as (t, instance, from, to) with the components' regime names.

    Each located event of the reference is classified by the thesis regimes on its two sides;
    an engagement at the rocker reversal is also the drive's return -> forward switch.
    """
    out: list[tuple[float, str, str, str]] = []
    forward = True
    stick, slip = BRAKE_NAMES[REGIME_STICK], BRAKE_NAMES[REGIME_SLIP_FORWARD]
    fwd, ret = DRIVE_NAMES[REGIME_FORWARD], DRIVE_NAMES[1 - REGIME_FORWARD]
    engaged, overrun = CLUTCH_NAMES[REGIME_ENGAGED], CLUTCH_NAMES[1 - REGIME_ENGAGED]
    for ev in res.events:
        t, a, b = ev["t"], ev["regime"], ev["after"]
        if t > duration:
            break
        if ev.get("source") == "brake" and ev["brake_before"] != REGIME_STICK:
            # The roller stops; while the clutch overruns this changes no thesis regime.
            out.append((t, fs.load, slip, stick))
            if a == FEED:
                forward = b == WINDUP
            continue
        if a == OVERRUN and b != OVERRUN:
            out.append((t, fs.clutch, overrun, engaged))
            if not forward:
                out.append((t, fs.drive, ret, fwd))
                forward = True
        elif b == OVERRUN and a != OVERRUN:
            out.append((t, fs.clutch, engaged, overrun))
        elif b == FEED and a != FEED:
            out.append((t, fs.load, stick, slip))
        elif a == FEED and b != FEED:
            out.append((t, fs.load, slip, stick))
            forward = b == WINDUP
        else:  # no thesis regime change, or windup <-> unwinding: a rocker reversal
            out.append((t, fs.drive, fwd if forward else ret, ret if forward else fwd))
            forward = not forward
    return out


def reference_quantities(res, fs: FeedScene, duration: float, options: dict[str, Any]) -> dict:
    """Headline values of a reference run under the names ``analyse`` uses."""
    startup = int(options.get("startup_cycles", 1))
    n = _complete_cycles(duration, fs.period)
    if n == 0:
        raise ValueError(_no_cycle(duration, fs.period))
    cycles = res.cycles[:n]
    normal = _normal_cycles(n, startup)
    s = res.series
    # Shaft advance between cycle starts (the shaft is stuck there; the samples hit them).
    # Not the reference's per-cycle feed_length: that one leaves out the travel while the
    # clutch is disengaged mid-feed (Run 2).
    theta5 = np.interp(np.arange(n + 1) * fs.period, s["t"], s["theta5"])
    per_cycle = fs.p_load["roller_radius"] * np.diff(theta5)
    out = {
        "feed_length_mean": float(np.mean(per_cycle[list(normal)])),
        "feed_length_last": float(per_cycle[-1]),
        "peak_windup": max(c["peak_windup"] for c in cycles),
    }
    feed_time = sum(cycles[c]["feed_time"] for c in normal)
    if feed_time > 0:
        out["mean_windup_feed"] = (
            sum(cycles[c]["mean_windup_feed"] * cycles[c]["feed_time"] for c in normal) / feed_time
        )
    if not fs.rigid:
        out["peak_deflection"] = max(c["peak_q"] for c in cycles)
        out["peak_strain"] = max(c["peak_strain"] for c in cycles)
        out["peak_strain_b"] = max(c["peak_strain_b"] for c in cycles)
    trans = [(0.0, WINDUP)] + [(t, b) for t, _, b in res.regime_log]
    out.update(regime_timing(trans, (n - 1) * fs.period, n * fs.period, fs.omega, res.phi1_0))
    if options.get("decay_ratios", False):
        last = (s["t"] >= (n - 1) * fs.period) & (s["t"] < n * fs.period)
        ratios = decay_ratios(s["windup"], last & _feeding_mask(s["t"], trans))
        if ratios:
            out["decay_ratio"] = float(np.mean(ratios[:DECAY_PEAKS]))
    return out


def _feeding_mask(times: np.ndarray, trans: list[tuple[float, int]]) -> np.ndarray:
    starts = np.array([t for t, _ in trans])
    regimes = np.array([r for _, r in trans])
    idx = np.searchsorted(starts, times, side="right") - 1
    return regimes[np.clip(idx, 0, len(regimes) - 1)] == FEED


def reference(scene: Scene) -> Reference:
    """Monolithic reference of a press-feed scene: same parameters, exact events."""
    fs = feed_scene(scene)
    opts = feed_options(scene)
    res = simulate_feed(opts)
    duration = scene.stop - scene.start
    headline = reference_quantities(res, fs, duration, scene.report_options)
    s = res.series
    drive = build_drive_model(opts.rpm, fs.linkage(), fs.coupler(), f1=fs.f1(), rigid=fs.rigid)
    theta4 = rocker_angles(drive, s["phi1"], s["q"])
    ref_t = s["t"]
    columns = {
        f"{fs.clutch}.windup": s["windup"],
        f"{fs.drive}.angle": theta4,
        f"{fs.load}.angle": s["theta5"],
    }

    def signals(times: np.ndarray) -> dict[str, np.ndarray]:
        rel = np.asarray(times, dtype=float) - scene.start
        return {name: np.interp(rel, ref_t, values) for name, values in columns.items()}

    events = [(t + scene.start, *rest) for t, *rest in _subsystem_events(res, fs, duration)]
    t_range = (scene.start + float(ref_t[0]), scene.start + float(ref_t[-1]))
    return Reference(headline=headline, signals=signals, events=events, t_range=t_range)
