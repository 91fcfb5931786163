"""Sample points of a tolerance study: uniform points in the unit cube, then each input's
inverse distribution function.

The first n points of a draw of N > n are the same n points (Monte Carlo fills row by row
from one seeded generator; scrambled Sobol is a sequence), so a study can be extended or
resumed and sample k is always the same wherever and whenever it is drawn.
"""

from __future__ import annotations

import warnings

import numpy as np
from scipy import stats
from scipy.stats import qmc

from orchestrator.studies.study_table import BAND_SIGMAS, StudyInput, StudySpec


def unit_points(n: int, dims: int, method: str, seed: int) -> np.ndarray:
    """(n, dims) points in the open unit cube."""
    if method == "sobol":
        sobol = qmc.Sobol(dims, scramble=True, seed=seed)
        with warnings.catch_warnings():  # n need not be a power of two for a study
            warnings.simplefilter("ignore", UserWarning)
            u = sobol.random(n)
    elif method == "monte-carlo":
        u = np.random.default_rng(seed).random((n, dims))
    else:
        raise ValueError(f"unknown sampling method {method!r}")
    # Keep away from 0 and 1 exactly, where an unbounded inverse CDF is infinite.
    tiny = np.finfo(float).eps
    return np.clip(u, tiny, 1.0 - tiny)


def inverse_cdf(spec: StudyInput, u: np.ndarray) -> np.ndarray:
    """Values of one input at unit-interval points ``u`` (SI)."""
    p = spec.params
    if spec.distribution == "band":
        nominal, half, uniform = p
        if uniform:
            return nominal - half + 2.0 * half * u
        sd = half / BAND_SIGMAS
        return stats.truncnorm.ppf(u, -BAND_SIGMAS, BAND_SIGMAS, loc=nominal, scale=sd)
    if spec.distribution == "normal":
        return stats.norm.ppf(u, loc=p[0], scale=p[1])
    if spec.distribution == "uniform":
        return p[0] + (p[1] - p[0]) * u
    if spec.distribution == "lognormal":
        return p[0] * np.exp(p[1] * stats.norm.ppf(u))
    values = np.asarray(p, dtype=float)
    index = np.minimum((u * len(values)).astype(int), len(values) - 1)
    return values[index]


def draw(spec: StudySpec, n: int | None = None, method: str | None = None) -> np.ndarray:
    """(n, inputs) sample values of the study (SI), n defaulting to the study's own."""
    n = spec.samples if n is None else n
    u = unit_points(n, len(spec.inputs), method or spec.sampling, spec.seed)
    return np.column_stack([inverse_cdf(inp, u[:, j]) for j, inp in enumerate(spec.inputs)])
