"""What a tolerance study says, as ``study.md`` and ``study.png``."""

from __future__ import annotations

import math
from collections import Counter
from pathlib import Path

import numpy as np

from orchestrator.studies import study_statistics as st
from orchestrator.studies.study_result import OK, StudyResult


def _g(x: float, digits: int = 5) -> str:
    return "–" if x is None or not math.isfinite(x) else f"{x:.{digits}g}"


def _pct(x: float) -> str:
    return "–" if not math.isfinite(x) else f"{100.0 * x:.3g} %"


def _ci(e: st.Estimate) -> str:
    if math.isnan(e.low) or math.isnan(e.high):
        return "–"
    low = _g(e.low) if math.isfinite(e.low) else "−∞ (too few samples)"
    high = _g(e.high) if math.isfinite(e.high) else "∞ (too few samples)"
    return f"{low} … {high}"


def limit_rows(result: StudyResult) -> list[tuple[str, str, st.Violation, int]]:
    """(quantity, limit in words, violation estimate, samples without a value) per bound.
    A sample without a value (failed, not armed, ...) counts as a violation."""
    rows = []
    for limit in result.spec.limits:
        without = sum(
            1 for s in result.samples if not math.isfinite(s.values.get(limit.quantity, math.nan))
        )
        unit = result.units.get(limit.quantity, "")
        unit = "" if unit in ("", "1") else f" {unit}"
        for bound, text, below in (
            (limit.low, limit.low_text, True),
            (limit.high, limit.high_text, False),
        ):
            if bound is None:
                continue
            bad = sum(
                1
                for s in result.samples
                if math.isfinite(v := s.values.get(limit.quantity, math.nan))
                and (v < bound if below else v > bound)
            )
            sign = "≥" if below else "≤"
            words = f"{sign} {bound:g}{unit} ({text} if not)"
            rows.append(
                (limit.quantity, words, st.violation(bad + without, len(result.samples)), without)
            )
    return rows


def write_markdown(result: StudyResult, path: Path) -> None:
    spec, scene = result.spec, result.scene
    m = scene.master
    key, step = m.own_step
    master = f"{m.algorithm}, {key.replace('_', ' ')} {step:g} s" + "".join(
        f", {k} {v:g}" for k, v in m.options.items() if k in ("tolerance",)
    )
    counts = Counter(s.status for s in result.samples)
    lines = [
        f"# Tolerance study: {scene.name}",
        "",
        f"{len(result.samples)} of {result.requested} samples recorded"
        + (" (interrupted: `--resume` runs the rest)" if result.interrupted else "")
        + f"; {spec.sampling} sampling, seed {spec.seed}; master {master}. "
        + "Run time: "
        + "; ".join(
            f"{r['samples_run']} samples in {r['wall_time']:.1f} s ({r['where']}"
            + (f", commit {r['commit']}" if r.get("commit") else "")
            + ")"
            for r in result.invocations
            if r["samples_run"]
        )
        + ".",
        "",
        "## Inputs",
        "",
        "| input | sets | distribution |",
        "|---|---|---|",
    ]
    for inp in spec.inputs:
        keys = ", ".join(f"`{k}`" for k in inp.keys)
        lines.append(f"| {inp.label} (`{inp.name}`) | {keys} | {inp.describe()} |")
    lines += ["", "## Outcomes", ""]
    lines.append(", ".join(f"{status}: {c}" for status, c in sorted(counts.items())) or "none")
    others = [s for s in result.samples if s.status != OK]
    if others:
        lines += ["", "Samples without every quantity (kept, and counted against every limit):", ""]
        for s in others:
            lines.append(f"- sample {s.index} ({s.status}): {s.reason}")
    for q in spec.quantities:
        unit = result.units.get(q, "")
        values = result.values(q)
        summary = st.summarize(values, seed=spec.seed)
        lines += [
            "",
            f"## {q}" + (f" [{unit}]" if unit and unit != "1" else ""),
            "",
            f"From the {summary.n} samples with a value; 95 % intervals: bootstrap "
            f"({st.RESAMPLES} resamples) for mean and deviation, exact order-statistic "
            "intervals for the percentiles.",
            "",
            "| statistic | value | 95 % interval |",
            "|---|---|---|",
            f"| mean | {_g(summary.mean.value, 6)} | {_ci(summary.mean)} |",
            f"| standard deviation | {_g(summary.sd.value, 4)} | {_ci(summary.sd)} |",
        ]
        for p, e in summary.percentiles.items():
            lines.append(f"| {p} % | {_g(e.value, 6)} | {_ci(e)} |")
        rho, shares, r2 = st.sensitivity(result.inputs(), values)
        lines += [
            "",
            f"Sensitivity (linear regression on the standardised inputs, R² = {_g(r2, 3)}):",
            "",
            "| input | Spearman ρ | share of variance |",
            "|---|---|---|",
        ]
        for inp, r, share in zip(spec.inputs, rho, shares, strict=True):
            lines.append(f"| {inp.label} | {_g(r, 3)} | {_pct(share)} |")
        ns, se, comparison, fit_r2 = convergence(result, q)
        if ns:
            lines += [
                "",
                "Standard error of the mean against N: these samples (s/√N), and Monte Carlo "
                "against scrambled Sobol from 64 draws each of a least-squares fit of the "
                f"results (quadratic, or linear below two samples per coefficient; "
                f"fit R² = {_g(fit_r2, 3)}, – when too few samples for either). The variance "
                "the fit leaves out, (1 − R²) s², converges at the Monte Carlo rate whatever "
                "the points: the last column adds it to the Sobol line.",
                "",
                "| N | this study | Monte Carlo (fit) | Sobol (fit) | Sobol (fit + rest) |",
                "|---|---|---|---|---|",
            ]
            for i, n in enumerate(ns):
                mc = comparison.get("monte-carlo", [math.nan] * len(ns))[i]
                so = comparison.get("sobol", [math.nan] * len(ns))[i]
                rest = math.sqrt(so**2 + max(0.0, 1.0 - fit_r2) * se[i] ** 2)
                cells = [str(n), *(_g(v, 3) for v in (se[i], mc, so, rest))]
                lines.append("| " + " | ".join(cells) + " |")
    rows = limit_rows(result)
    if rows:
        lines += [
            "",
            "## Acceptance limits",
            "",
            "Violation probability, exact (Clopper–Pearson) 95 % interval and one-sided 95 % "
            "upper bound; samples without a value count as violations.",
            "",
            "| quantity | limit | violations | probability | 95 % interval | at 95 % |",
            "|---|---|---|---|---|---|",
        ]
        for q, words, v, without in rows:
            extra = f" ({without} without a value)" if without else ""
            lines.append(
                f"| {q} | {words} | {v.k} of {v.n}{extra} | {_pct(v.rate)} | "
                f"{_pct(v.low)} … {_pct(v.high)} | < {_pct(v.upper)} |"
            )
    path.write_text("\n".join(lines) + "\n")


def convergence(
    result: StudyResult, quantity: str
) -> tuple[list[int], list[float], dict[str, list[float]], float]:
    """(N, s/sqrt(N) of these samples, {method: SE from the fit}, fit R^2)."""
    y = result.values(quantity)
    ok = np.isfinite(y)
    if ok.sum() < 4:
        return [], [], {}, math.nan
    ns, se = st.standard_errors(y[ok])
    u = result.unit_points()[ok]
    comparison, r2 = st.surrogate_convergence(u, y[ok], ns, seed=result.spec.seed)
    return ns, se, comparison, r2


def write_plot(result: StudyResult, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    quantities = result.spec.quantities
    fig, axes = plt.subplots(
        len(quantities), 3, figsize=(12, 3.4 * len(quantities) + 0.5), squeeze=False
    )
    limits = {lim.quantity: lim for lim in result.spec.limits}
    for row, q in zip(axes, quantities, strict=True):
        unit = result.units.get(q, "")
        label = q + (f" [{unit}]" if unit and unit != "1" else "")
        y = np.sort(result.values(q))
        hist, cdf, conv = row
        if len(y):
            hist.hist(
                y, bins=max(5, min(40, int(2 * len(y) ** (1 / 3)) + 1)), color="C0", alpha=0.8
            )
            n = len(y)
            cdf.step(y, np.arange(1, n + 1) / n, where="post", color="C0", label=f"{n} samples")
            summary = st.summarize(y, seed=result.spec.seed)
            for p, e in summary.percentiles.items():
                if not math.isnan(e.low):
                    lo = e.low if math.isfinite(e.low) else y[0]
                    hi = e.high if math.isfinite(e.high) else y[-1]
                    cdf.plot([lo, hi], [p / 100, p / 100], color="C3", lw=3, alpha=0.6)
                cdf.plot(e.value, p / 100, "|", color="C3", ms=10)
            cdf.plot([], [], color="C3", lw=3, alpha=0.6, label="percentiles, 95 % CI")
        lim = limits.get(q)
        for bound in (lim.low, lim.high) if lim else ():
            if bound is not None:
                for ax in (hist, cdf):
                    ax.axvline(bound, color="k", ls="--", lw=1)
        hist.set_xlabel(label)
        hist.set_ylabel("samples")
        cdf.set_xlabel(label)
        cdf.set_ylabel("cumulative fraction")
        if len(y):  # no sample with a value: nothing to label
            cdf.legend(fontsize="x-small", loc="upper left")
        ns, se, comparison, r2 = convergence(result, q)
        if ns:
            conv.loglog(ns, se, "o-", label="these samples, s/√N")
            for method, ses in comparison.items():
                conv.loglog(ns, ses, ".--", label=f"{method} (on the fit, R² {r2:.2f})")
            conv.set_xticks(ns, [str(n) for n in ns])
            conv.minorticks_off()
            conv.legend(fontsize="x-small")
        conv.set_xlabel("samples N")
        conv.set_ylabel(
            f"standard error of mean{' [' + unit + ']' if unit not in ('', '1') else ''}"
        )
        for ax in row:
            ax.grid(True, alpha=0.3)
    fig.suptitle(
        f"{result.scene.name}: {len(result.samples)} samples ({result.spec.sampling}, "
        f"seed {result.spec.seed})"
    )
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
