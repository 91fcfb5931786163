"""Statistics of a tolerance study that say how far they can be trusted.

* Mean and standard deviation with a percentile-bootstrap confidence interval (resampling
  the completed samples; seeded, so the same samples give the same interval).
* Percentiles with the exact distribution-free interval between two order statistics (the
  number of samples below a quantile is binomial).  The bootstrap's percentile intervals
  cannot reach past the smallest or largest sample and miss the 1 % and 99 % points far
  more often than 5 % at a few dozen samples; these intervals hold their level, and stay
  open on a side the samples cannot bound yet (the 1 % point needs 368 samples for a
  two-sided 95 % interval).
  With Sobol points every interval treats the samples as independent, which overstates the
  spread of the estimates: the intervals are then conservative.
* Violation probability of an acceptance limit: k of n with the exact Clopper-Pearson
  interval, and the one-sided upper bound ("0 of 500" reads "< 0.6 % at 95 %").
* Convergence: the standard error of the mean against N for these samples (s/sqrt(N)), and
  Monte Carlo against Sobol by repeated draws of a quadratic least-squares fit of the
  results (cheap, so many repetitions; it carries the fit's error, reported as its R^2).
* Sensitivity: Spearman rank correlation of each input with the result, and the share of
  variance of a linear regression on the standardised inputs (squared standardised
  regression coefficients; they add up to the regression's R^2 for independent inputs).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import stats

from orchestrator.studies.sampling import unit_points

PERCENTILES = (1, 5, 50, 95, 99)
CONFIDENCE = 0.95
RESAMPLES = 2000


@dataclass(frozen=True)
class Estimate:
    value: float
    low: float  # confidence interval
    high: float


@dataclass(frozen=True)
class Summary:
    n: int
    mean: Estimate
    sd: Estimate
    percentiles: dict[int, Estimate]


@dataclass(frozen=True)
class Violation:
    k: int  # samples outside the limit (or without a value)
    n: int
    rate: float
    low: float  # two-sided Clopper-Pearson interval
    high: float
    upper: float  # one-sided upper bound at the same confidence


def _bootstrap(values: np.ndarray, statistic, seed: int) -> Estimate:  # noqa: ANN001
    value = float(statistic(values, axis=-1))
    if len(values) < 3 or np.ptp(values) == 0.0:
        return Estimate(value, math.nan, math.nan)
    res = stats.bootstrap(
        (values,),
        statistic,
        n_resamples=RESAMPLES,
        confidence_level=CONFIDENCE,
        method="percentile",
        vectorized=True,
        random_state=np.random.default_rng(seed),
    )
    return Estimate(value, float(res.confidence_interval.low), float(res.confidence_interval.high))


def summarize(values: np.ndarray, seed: int = 0) -> Summary:
    """Mean, standard deviation and PERCENTILES of finite ``values``, with CIs."""
    x = np.asarray(values, dtype=float)
    x = x[np.isfinite(x)]
    if len(x) == 0:
        nan = Estimate(math.nan, math.nan, math.nan)
        return Summary(0, nan, nan, {p: nan for p in PERCENTILES})

    def sd(v: np.ndarray, axis: int = -1) -> np.ndarray:
        return np.std(v, axis=axis, ddof=1) if v.shape[axis] > 1 else np.zeros(v.shape[:-1])

    percentiles = {p: percentile_interval(x, p) for p in PERCENTILES}
    return Summary(len(x), _bootstrap(x, np.mean, seed), _bootstrap(x, sd, seed + 1), percentiles)


def percentile_interval(values: np.ndarray, p: float) -> Estimate:
    """The p-th percentile and its exact distribution-free interval [x(l), x(u)]: with B
    the number of samples below the true quantile, B ~ Binomial(n, p/100), so
    P(x(l) <= q) = P(B >= l) and P(x(u) >= q) = P(B < u), each held >= 1 - alpha/2.  A side
    no order statistic reaches at this n is infinite."""
    x = np.sort(np.asarray(values, dtype=float))
    n, q = len(x), p / 100.0
    value = float(np.percentile(x, p))
    tail = (1.0 - CONFIDENCE) / 2.0
    ranks = np.arange(1, n + 1)
    below = stats.binom.sf(ranks - 1, n, q) >= 1.0 - tail  # P(B >= l)
    above = stats.binom.cdf(ranks - 1, n, q) >= 1.0 - tail  # P(B < u)
    low = float(x[ranks[below][-1] - 1]) if below.any() else -math.inf
    high = float(x[ranks[above][0] - 1]) if above.any() else math.inf
    return Estimate(value, low, high)


def violation(k: int, n: int) -> Violation:
    """Probability of violating a limit from k violations in n samples (Clopper-Pearson)."""
    if n == 0:
        return Violation(k, n, math.nan, math.nan, math.nan, math.nan)
    two_sided = stats.binomtest(k, n).proportion_ci(CONFIDENCE, method="exact")
    one_sided = stats.binomtest(k, n, alternative="less").proportion_ci(CONFIDENCE, method="exact")
    return Violation(k, n, k / n, two_sided.low, two_sided.high, one_sided.high)


def sensitivity(inputs: np.ndarray, y: np.ndarray) -> tuple[list[float], list[float], float]:
    """(Spearman rho per input, linear-regression share of variance per input, R^2)."""
    x = np.asarray(inputs, dtype=float)
    y = np.asarray(y, dtype=float)
    d = x.shape[1]
    if len(y) < d + 2 or np.ptp(y) == 0.0:
        return [math.nan] * d, [math.nan] * d, math.nan
    rho = []
    for j in range(d):
        if np.ptp(x[:, j]) == 0.0:
            rho.append(math.nan)
        else:
            rho.append(float(stats.spearmanr(x[:, j], y).statistic))
    sx = x.std(axis=0, ddof=1)
    varied = sx > 0
    z = (x[:, varied] - x[:, varied].mean(axis=0)) / sx[varied]
    zy = (y - y.mean()) / y.std(ddof=1)
    design = np.column_stack([np.ones(len(y)), z])
    coef, *_ = np.linalg.lstsq(design, zy, rcond=None)
    fitted = design @ coef
    r2 = 1.0 - float(np.sum((zy - fitted) ** 2) / np.sum(zy**2))
    shares = np.full(d, math.nan)
    shares[varied] = coef[1:] ** 2
    return rho, [float(s) for s in shares], r2


def standard_errors(y: np.ndarray) -> tuple[list[int], list[float]]:
    """s/sqrt(n) of the running mean of the first n results, n = 4, 8, 16, ..., N."""
    y = np.asarray(y, dtype=float)
    ns = [n for n in (2**k for k in range(2, 31)) if n < len(y)] + [len(y)]
    ns = [n for n in ns if n >= 2]
    return ns, [float(np.std(y[:n], ddof=1) / math.sqrt(n)) for n in ns]


def _features(u: np.ndarray) -> np.ndarray:
    d = u.shape[1]
    cols = [np.ones(len(u)), *(u[:, j] for j in range(d)), *(u[:, j] ** 2 for j in range(d))]
    cols += [u[:, i] * u[:, j] for i in range(d) for j in range(i + 1, d)]
    return np.column_stack(cols)


def surrogate_convergence(
    u: np.ndarray, y: np.ndarray, ns: list[int], replicates: int = 64, seed: int = 0
) -> tuple[dict[str, list[float]], float]:
    """Standard error of the mean against N for Monte Carlo and scrambled Sobol, from
    ``replicates`` independent draws each of a quadratic fit of y over the unit points
    ``u`` (the study's own points before the inverse CDFs); linear when there are fewer
    than two samples per coefficient of the quadratic.  Returns ({method: SEs}, R^2 of the
    fit); empty when there are too few samples even for the linear fit."""
    u = np.asarray(u, dtype=float)
    y = np.asarray(y, dtype=float)
    features = _features(u)
    # At least two samples per coefficient, else the fit follows the samples, not the model.
    if len(y) < 2 * features.shape[1]:
        features = features[:, : 1 + u.shape[1]]  # linear only
        if len(y) < 2 * features.shape[1]:
            return {}, math.nan
    quadratic = features.shape[1] > 1 + u.shape[1]
    coef, *_ = np.linalg.lstsq(features, y, rcond=None)
    fitted = features @ coef
    r2 = 1.0 - float(np.sum((y - fitted) ** 2) / max(np.sum((y - y.mean()) ** 2), 1e-300))

    def model(points: np.ndarray) -> np.ndarray:
        f = _features(points)
        return (f if quadratic else f[:, : 1 + u.shape[1]]) @ coef

    out: dict[str, list[float]] = {}
    for method in ("monte-carlo", "sobol"):
        ses = []
        for n in ns:
            means = [
                float(model(unit_points(n, u.shape[1], method, seed + 1000 + r)).mean())
                for r in range(replicates)
            ]
            ses.append(float(np.std(means, ddof=1)))
        out[method] = ses
    return out, r2
