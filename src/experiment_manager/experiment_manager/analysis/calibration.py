"""A drop test calibrated: the inputs of a sensitivity experiment's scenarios (a grid over the
contact materials, say) fitted to the user's own measured counts by likelihood.

Each scenario's repeat of the drop test gives the simulated counts of each aspect; the
measured counts' log likelihood under the scenario's shares ranks the scenarios. The shares are
themselves estimated from a few hundred simulated drops, so the likelihood is the
Dirichlet-multinomial's, the multinomial's averaged over the shares the simulated counts allow
(a Dirichlet of the counts plus SMOOTH, Jeffreys' prior: an aspect the simulation never showed
is unlikely, not impossible). With plain shares, two points 1 mm of drop height apart differed
by 5.9 in log likelihood from the simulation's noise alone (docs/drop-tests.md), three times
the interval's 1.92. The fit is the likeliest; an input's 95 % interval spans the scenarios within
CHI2_HALF of it in log likelihood (the profile likelihood's chi-square(1) rule, at the grid's
resolution: the interval is no finer than the grid). How far the simulation's noise alone moves
that ranking is measured too (noise): on binom4 (404 drops measured, ~400 simulated a point),
two points of the likeliest's shares differ by 2.3 (SD), so the noise alone puts such a point
outside the interval four times in ten. Pure: no rclpy.
"""

import json
import math

import numpy as np
from pick_common.parts.aspects import agreement

from ..experiment_file.scenarios import DROP_HEIGHT
from .summary import Calibration, DropTest, Point

SMOOTH = 0.5            # added to every simulated count
CHI2_HALF = 1.920729    # half the 95 % quantile of chi-square with one degree of freedom
RESAMPLES = 400         # pairs of resampled simulated counts behind `noise`


def log_likelihood(measured: dict[str, int], simulated: dict[str, int]) -> float:
    """The measured counts' Dirichlet-multinomial log likelihood (up to a constant that does
    not depend on the simulation) given the simulated counts, each plus SMOOTH."""
    names = set(measured) | set(simulated)
    alpha = {n: simulated.get(n, 0) + SMOOTH for n in names}
    total = sum(alpha.values())
    return (math.lgamma(total) - math.lgamma(total + sum(measured.values()))
            + sum(math.lgamma(alpha[n] + m) - math.lgamma(alpha[n])
                  for n, m in measured.items() if m))


def counts_of(drop_summary: DropTest) -> dict[str, int]:
    """A drop test's summary's counts by aspect."""
    return {a.name: a.count for a in drop_summary.aspects}


def calibrate(experiment: str, measured: dict[str, int],
              points: list[tuple[dict[str, float], dict[str, int]]]) -> Calibration:
    """The fit of `points` ((input values, simulated counts) per scenario) to `measured`: the
    likeliest values, each input's 95 % interval, the G-test p there, every point's log
    likelihood, and the file keys to paste (file_keys)."""
    scored = [(log_likelihood(measured, counts), values, counts) for values, counts in points]
    best_ll, best, best_counts = max(scored, key=lambda s: s[0])
    near = [values for ll, values, _ in scored if ll >= best_ll - CHI2_HALF]
    intervals = {name: [min(v[name] for v in near), max(v[name] for v in near)]
                 for name in best}
    keys: dict[str, tuple[float, float, float] | str] = {
        name: (best[name], *intervals[name]) for name in best if name != DROP_HEIGHT}
    for name in best:                   # a material's pair says the values are calibrated
        if name.startswith('materials.'):
            pair, key = name.rsplit('.', 1)
            keys[f'{pair}.basis.{key}'] = 'calibrated'
            keys[f'{pair}.source'] = (f'calibrated to the drop test {experiment} '
                                      f'({sum(measured.values())} drops measured)')
    sd = noise(measured, best_counts)
    return Calibration(
        experiment=experiment, best=best, intervals=intervals,
        p=agreement(best_counts, measured), noise_sd=sd,
        noise_outside=math.erfc(CHI2_HALF / (sd * math.sqrt(2))) if sd > 0 else 0.0,
        points=[Point(values=v, log_likelihood=ll) for ll, v, _ in scored],
        keys=file_keys(keys) + height_note(best, intervals))


def noise(measured: dict[str, int], simulated: dict[str, int], seed: int = 0) -> float:
    """The simulation's own noise in a difference of log likelihoods: its SD between two
    points whose true shares are both `simulated`'s, each from as many simulated drops
    (RESAMPLES pairs of multinomial resamplings of those counts, seeded: the same counts give
    the same figure). Beside CHI2_HALF it says how far an interval is the noise's."""
    names = sorted(simulated)
    n = sum(simulated.values())
    if n == 0:
        return 0.0
    shares = np.array([simulated[k] for k in names], dtype=float) / n
    draws = np.random.default_rng(seed).multinomial(n, shares, size=2 * RESAMPLES)
    ll = np.array([log_likelihood(measured, dict(zip(names, map(int, d), strict=True)))
                   for d in draws])
    return float(np.std(ll[:RESAMPLES] - ll[RESAMPLES:], ddof=1))


def noise_said(sd: float | None, outside: float | None) -> str:
    """The noise in words (calibrate's noise_sd and noise_outside), '' for a summary that has
    none (one of version 1: summary.migrate)."""
    if sd is None or outside is None:
        return ''
    return (f"the simulation's own noise: two points of the likeliest's shares, each from as "
            f'many simulated drops, differ by {sd:.2g} in log likelihood (SD), so the noise '
            f'alone puts such a point outside an interval {round(100 * outside)} % of the time'
            + (": the intervals are the noise's as much as the counts'; more drops a point "
               "(the drop test's iterations) narrow it" if outside > 0.05 else ''))


def height_note(best: dict[str, float], intervals: dict[str, list[float]]) -> list[str]:
    """A comment on the fitted drop height, which is no key of the cell's: the height the
    simulated drops fit the user's best from (none when it was not varied)."""
    if DROP_HEIGHT not in best:
        return []
    low, high = intervals[DROP_HEIGHT]
    return [f'# {DROP_HEIGHT}: {best[DROP_HEIGHT]:.4g}    # 95 %: {low:.4g} to {high:.4g} (the '
            "height the simulated drops fit yours best from; no key of the cell's)"]


def file_keys(values: dict[str, tuple[float, float, float] | str]) -> list[str]:
    """YAML lines that set each dotted key (an input's name: its file key) to its value,
    nested as the file nests them: {name: (value, low, high)} with the interval in a comment,
    or {name: text}."""
    lines: list[str] = []
    open_path: list[str] = []
    for name, given in sorted(values.items()):
        *path, key = name.split('.')
        common = 0
        while common < min(len(path), len(open_path)) and path[common] == open_path[common]:
            common += 1
        for depth in range(common, len(path)):
            lines.append('  ' * depth + f'{path[depth]}:')
        open_path = path
        if isinstance(given, str):
            lines.append('  ' * len(path) + f'{key}: {json.dumps(given)}')
            continue
        value, low, high = given
        lines.append('  ' * len(path) + f'{key}: {value:.4g}    # 95 %: {low:.4g} to {high:.4g}')
    return lines
