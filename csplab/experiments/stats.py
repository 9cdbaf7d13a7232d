"""Statistics for experiment reports: Wilson intervals, bootstrap intervals, divergences.

Examples
--------
>>> lo, hi = wilson(8, 10)
>>> round(lo, 3), round(hi, 3)
(0.49, 0.943)
>>> wilson(0, 0)
(0.0, 1.0)
>>> round(total_variation([0.5, 0.5], [0.9, 0.1]), 3)
0.4
>>> round(jensen_shannon([1, 0], [0, 1]), 3)        # bits: the maximum is 1
1.0
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "bootstrap_ci",
    "jensen_shannon",
    "median_iqr",
    "normalise",
    "total_variation",
    "wilson",
]

Z95 = 1.959963984540054


def wilson(successes: int, n: int, z: float = Z95) -> tuple[float, float]:
    """The Wilson score interval for a binomial proportion (95% by default).

    Unlike the normal approximation it stays inside [0, 1] and is sensible at 0 or ``n``
    successes. ``n = 0`` gives ``(0, 1)``.
    """
    if n <= 0:
        return 0.0, 1.0
    if not 0 <= successes <= n:
        raise ValueError(f"successes={successes} must be between 0 and n={n}")
    p = successes / n
    z2 = z * z
    denom = 1 + z2 / n
    centre = (p + z2 / (2 * n)) / denom
    half = z * math.sqrt(p * (1 - p) / n + z2 / (4 * n * n)) / denom
    lo = 0.0 if successes == 0 else max(0.0, centre - half)
    hi = 1.0 if successes == n else min(1.0, centre + half)
    return lo, hi


def median_iqr(values: Sequence[float]) -> tuple[float, float, float]:
    """``(median, 25th percentile, 75th percentile)``; NaNs for an empty sequence."""
    if len(values) == 0:
        return math.nan, math.nan, math.nan
    q = np.percentile(np.asarray(values, dtype=float), [50, 25, 75])
    return float(q[0]), float(q[1]), float(q[2])


def normalise(counts: ArrayLike) -> NDArray[np.float64]:
    """Counts -> a probability vector (all zeros stay zeros)."""
    c = np.asarray(counts, dtype=np.float64)
    s = c.sum()
    return c / s if s > 0 else c


def total_variation(p: ArrayLike, q: ArrayLike) -> float:
    """Total variation distance ``0.5 * sum |p - q|`` between two distributions."""
    a, b = normalise(p), normalise(q)
    return float(0.5 * np.abs(a - b).sum())


def jensen_shannon(p: ArrayLike, q: ArrayLike) -> float:
    """Jensen-Shannon divergence in bits (0 for equal distributions, at most 1)."""
    a, b = normalise(p), normalise(q)
    s = a + b  # 2 m; m itself can underflow to 0 next to a subnormal x

    def kl(x: NDArray[np.float64]) -> float:
        nz = x > 0
        return float(np.sum(x[nz] * np.log2(2 * x[nz] / s[nz])))

    return 0.5 * kl(a) + 0.5 * kl(b)


def bootstrap_ci(
    data: Sequence[Any] | NDArray[Any],
    statistic: Callable[[NDArray[Any]], float],
    *,
    rng: int | np.random.Generator = 0,
    n_boot: int = 1000,
    level: float = 0.95,
) -> tuple[float, float, float]:
    """Percentile bootstrap: ``(statistic(data), lower, upper)``, resampling along axis 0.

    Examples
    --------
    >>> est, lo, hi = bootstrap_ci(np.arange(100.0), np.mean, rng=1, n_boot=200)
    >>> est, lo < est < hi
    (49.5, True)
    """
    arr = np.asarray(data)
    gen = rng if isinstance(rng, np.random.Generator) else np.random.default_rng(rng)
    est = float(statistic(arr))
    n = arr.shape[0]
    if n == 0:
        return est, math.nan, math.nan
    reps = np.empty(n_boot)
    for i in range(n_boot):
        reps[i] = statistic(arr[gen.integers(0, n, n)])
    a = (1 - level) / 2
    lo, hi = np.quantile(reps, [a, 1 - a])
    return est, float(lo), float(hi)
