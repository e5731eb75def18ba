"""The statistics every package uses, in one place: a list's figures, the interval of a mean,
the bound of a difference of means, and the intervals of a share. Pure: numpy and scipy.

Which share interval where, and why:
- a verdict's share (bins emptied, runs that spill, runs over a refill time) and a share
  figure beside one: the exact (Clopper-Pearson) interval, `rate_interval` two-sided and
  `binomial_bounds` one-sided. A verdict rests on few iterations (the reduced test case runs
  one), where the exact interval keeps its stated coverage and Wilson's does not: 0 of 1 is
  below 0.79 by Wilson, below 0.975 exactly (Brown, Cai and DasGupta, "Interval estimation
  for a binomial proportion", Statistical Science 16(2), 2001).
- an aspect's share of hundreds of drops (a drop test, its studies): Wilson's interval,
  `wilson_interval`, whose coverage is near its nominal 95 % at such counts where the exact
  one is wider than it needs to be (the same paper's recommendation for n of 40 and more).
"""

import math

import numpy as np
from scipy import stats as scipy_stats

Z95 = 1.959963984540054        # the standard normal's 97.5 % quantile


def stats(values) -> dict:
    """n, mean, min, max and the sample standard deviation (n - 1; 0 for one value) of a list
    of numbers; None for each but n of an empty list."""
    a = np.asarray(values, dtype=float)
    if a.size == 0:
        return {'n': 0, 'mean': None, 'min': None, 'max': None, 'std': None}
    return {'n': int(a.size), 'mean': float(a.mean()), 'min': float(a.min()),
            'max': float(a.max()), 'std': float(a.std(ddof=1)) if a.size > 1 else 0.0}


def interval(values, confidence: float = 0.95, counts: bool = False
             ) -> tuple[float | None, float | None]:
    """The two-sided Student-t confidence interval of the mean of `values`; (None, None) for
    fewer than two values (one value says nothing of its spread). counts: the values are counts
    of parts, whose spread is taken as at least a Poisson count's (variance >= mean): a few
    scenes that happen to agree (two scenes of 4 valid parts each) do not make a mean certain."""
    a = np.asarray(values, dtype=float)
    if a.size < 2:
        return None, None
    variance = a.var(ddof=1)
    if counts:
        variance = max(variance, a.mean())
    half = scipy_stats.t.ppf(0.5 + confidence / 2, a.size - 1) * np.sqrt(variance / a.size)
    return float(a.mean() - half), float(a.mean() + half)


def difference_bound(a, b, confidence: float) -> float:
    """The one-sided upper confidence bound of mean(a) - mean(b) at `confidence`, Welch's (a t
    with the Welch-Satterthwaite degrees of freedom: the two spreads need not be equal); a and
    b each of at least two values. Two separate intervals that do not overlap are a far
    stricter test than this one (Schenker and Gentleman, "On judging the significance of
    differences by examining the overlap between confidence intervals", The American
    Statistician 55(3), 2001)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    va, vb = a.var(ddof=1) / a.size, b.var(ddof=1) / b.size
    difference = float(a.mean() - b.mean())
    if va + vb == 0.0:
        return difference
    df = (va + vb) ** 2 / (va ** 2 / (a.size - 1) + vb ** 2 / (b.size - 1))
    return difference + float(scipy_stats.t.ppf(confidence, df) * np.sqrt(va + vb))


def rate_interval(successes, n, confidence: float = 0.95):
    """The exact (Clopper-Pearson) two-sided confidence interval of a share from `successes`
    of `n` trials (ints or int arrays of one shape), as (low, high); (None, None) for n = 0.
    Exact rather than Wilson's: the module docstring says why."""
    k, n = np.asarray(successes), np.asarray(n)
    if not n.shape and n == 0:
        return None, None
    tail = (1.0 - confidence) / 2.0
    with np.errstate(invalid='ignore', divide='ignore'):
        low = np.where(k > 0, scipy_stats.beta.ppf(tail, k, n - k + 1), 0.0)
        high = np.where(k < n, scipy_stats.beta.ppf(1.0 - tail, k + 1, n - k), 1.0)
    return (float(low), float(high)) if not low.shape else (low, high)


def binomial_bounds(over, n, confidence: float = 0.95):
    """One-sided exact (Clopper-Pearson) bounds of a share from `over` of `n` (ints, or int
    arrays of one shape): (lower, upper), each at `confidence`."""
    k, n = np.asarray(over), np.asarray(n)
    with np.errstate(invalid='ignore', divide='ignore'):
        low = np.where(k > 0, scipy_stats.beta.ppf(1 - confidence, k, n - k + 1), 0.0)
        high = np.where(k < n, scipy_stats.beta.ppf(confidence, k + 1, n - k), 1.0)
    return (float(low), float(high)) if not low.shape else (low, high)


def wilson_interval(count: int, total: int) -> tuple[float, float]:
    """The 95 % Wilson interval of a share count / total ((0, 1) for no total): for shares of
    many drops (the module docstring says why)."""
    if total <= 0:
        return 0.0, 1.0
    z = Z95
    p = count / total
    centre = (p + z * z / (2 * total)) / (1 + z * z / total)
    half = z * math.sqrt(p * (1 - p) / total + z * z / (4 * total * total)) / (1 + z * z / total)
    return max(0.0, centre - half), min(1.0, centre + half)
