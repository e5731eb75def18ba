"""Decisions on what each run measures, with one-sided bounds where the requirement is
one-sided.

The vibrating table. The requirement is a time: the cell must pick a refill's parts within the
refill interval. Each feeder run measures its cell's time to empty the feeder (`feeder_runs`:
picks x cell.pick_s, images x cell.image_s, and the table's simulated feeds and vibrations); a
run that did not empty within the interval counts as over it. One that the vibration limit (the
experiment's max_vibrations, a setting) ended with time of the interval left is censored: it
says neither that the refill empties within the interval nor that it does not (a feeder that
picks 9 resistors in 500 vibrations, 9.6 min, picks 80 well within 240 min at that pace). It
counts as over the interval for FEASIBLE and as within it for NOT FEASIBLE (the binomial's
bounds at either end), so the limit alone never decides; the ground says how many runs it
ended, how far into the interval, and the pace they picked at against the refill's. The
paper's stop rule (a run at the limit is not emptied) read such a run as over the interval,
and the limit, not the requirement, decided the verdict. The table is decided on the upper
tolerance bound that covers requirements.success_rate (say 90 %) of refills at 95 %
confidence (`table_time`):
- Gumbel (the largest extreme value distribution): a feeder is empty when its last part is
  picked, so the time to empty is a maximum, and the vibrations a feeder takes until its last
  part, like the draws a coupon collector needs for the last coupon, tend centred and scaled
  to this distribution (Erdos and Renyi 1961; Fisher-Tippett). Fitted by L-moments (Hosking,
  JRSS B 52(1), 1990: scale lambda2 / ln 2, location lambda1 - Euler's gamma x scale), the
  bound location + k scale with k exact for the family (location and scale are equivariant,
  so (quantile - location) / scale is pivotal: Lawless, *Statistical Models and Methods for
  Lifetime Data*, 2003, sec. 5.1; k is that pivot's quantile over GUMBEL_DRAWS samples of a
  seeded generator, the same every run). The fit is checked by the probability plot
  correlation (Vogel, Water Resources Research 22(4), 1986: Gringorten's plotting positions),
  its p from the same simulation; used when every run emptied within the interval and the
  check does not reject at 5 % (with 3 runs the check is weak, and said so); FEASIBLE when the
  upper bound is within the interval; NOT FEASIBLE when the lower 95 % bound of the same
  quantile is beyond it. Not a lognormal: on 50 runs of each test-case part a lognormal's
  bound (of the time less the robot's known part) on 3 to 12 of them said FEASIBLE at the
  50's own estimate of PTH1's 90 % quantile up to 7.4 % of the time (the runs are skewed to
  the right beyond a lognormal's), the Gumbel's at most 4.6 % on any part (docs/paper-test-case.md,
  "Deciding on few runs");
- distribution-free, beside it: the runs over the interval (or not emptied) as a binomial
  count: FEASIBLE when the one-sided 95 % upper bound of their share (censored runs counted
  over) is below 1 - success_rate (with none over, 29 runs at 90 %), NOT FEASIBLE when its
  lower bound (censored runs counted within) is above it. Used alone when the fitted bound
  cannot be (a run over the interval or censored, or the fit rejected).
- the pace, beside it when no run emptied within the interval and the limit ended one
  (`pace`): the runs' picks over their cell time as a Poisson count, its one-sided upper
  bound at `confidence` (Garwood 1936: chi-square with 2 picks + 2 degrees of freedom, over
  2 x the time), and at that rate the chance that a refill's parts are all picked within the
  interval (a Poisson count reaching them). NOT FEASIBLE when even that chance is below
  success_rate; it never makes the table FEASIBLE. It rests on picks coming no faster later
  in a run than in the part the runs saw: the table holds its load from the feeder while
  the feeder has parts, and fewer parts on it later pick no faster (the coupon collector's
  tail). A table that picks nothing in its runs to the limit is NOT FEASIBLE on it when that
  time is long enough against the interval, as the paper's stop rule read it; one that picks
  at a pace that could empty the refill stays UNDECIDED.
  Where this rests on an assumption: the fitted bound takes a run that would not empty as the
  Gumbel's own far tail. A feeder that jams now and then for a reason of its own (a part
  that wedges) is a second mode the fit cannot see in 3 runs that emptied; only the
  distribution-free count shows it, and needs 29 runs to show it below 10 %.
Spills are a share, decided as the rates below: the refills that spilled at most
requirements.max_spilled_parts parts, against requirements.success_rate (a refill that spills
is not emptied by picking: the paper's stop rule), FEASIBLE or NOT FEASIBLE only where the
bounds settle it.

Rates of success (bins emptied, `rate`): the exact (Clopper-Pearson) one-sided 95 % bounds:
FEASIBLE when the lower bound reaches the required rate, NOT FEASIBLE when the upper bound lies
below it.

Pure: no rclpy, no files.
"""

from dataclasses import dataclass, field, replace
import functools
import math

from feeder_controller.policy import NAMES, STOP_VIBRATION_LIMIT
import numpy as np
from pick_common.stats import binomial_bounds
from scipy import stats as scipy_stats

FEASIBLE, NOT_FEASIBLE, UNDECIDED = 'FEASIBLE', 'NOT FEASIBLE', 'UNDECIDED'
CONFIDENCE = 0.95
FIT_ALPHA = 0.05        # a probability plot correlation p below this rejects the Gumbel fit
GUMBEL_DRAWS = 200_000  # simulated samples behind each Gumbel k factor and fit check
EULER_GAMMA = 0.5772156649015329


@dataclass(frozen=True)
class Decision:
    """One ground of a verdict: what it measures, its bound, the interval type, the runs it
    took, and whether it is settled (FEASIBLE or NOT FEASIBLE) or not."""

    verdict: str
    quantity: str
    bound: float | None
    interval: str
    runs: int
    reason: str
    detail: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        return {'verdict': self.verdict, 'quantity': self.quantity, 'bound': self.bound,
                'interval': self.interval, 'runs': self.runs, 'reason': self.reason,
                **self.detail}


def feeder_runs(rows: list[dict], cell) -> list[dict]:
    """Per feeder run (rows of iterations.csv, typed, of feeder_emptying): `time`, the cell's
    time to empty the feeder, s (inf for a run that did not empty), `spilled`, `busy`, the
    cell's time the run took, s, emptied or not, `picks`, `parts` (its refill; None in rows
    without it), `vibrations` (None in rows without it), and `limited`: it ended at the
    vibration limit (the experiment's max_vibrations) with parts left."""
    out = []
    for r in rows:
        busy = cell_time(r, cell)
        out.append({'time': busy if r['emptied'] else math.inf, 'spilled': r['spilled'],
                    'emptied': bool(r['emptied']), 'busy': busy, 'picks': r['picks'],
                    'parts': r.get('parts'), 'vibrations': r.get('vibrations'),
                    'limited': not r['emptied']
                    and r.get('stop') == NAMES[STOP_VIBRATION_LIMIT]})
    return out


def cell_time(row: dict, cell) -> float:
    """The cell's time a feeder run took, s: its picks (`cell.pick_time` each), its checks (an
    image of `cell.image_time` each), its regrasps (`cell.regrasp_time` each) and the table's
    feeds and vibrations until the parts rested (simulated, `table_time`)."""
    return (row['picks'] * cell.pick_time + row['checks'] * cell.image_time + row['table_time']
            + row.get('regrasps', 0) * cell.regrasp_time)


def iterations_to_decide(successes: int, n: int, required: float, most: int = 10_000
                         ) -> int | None:
    """The fewest iterations, more than n, whose one-sided bounds (`rate`) would decide if the
    rate seen so far held (successes / n of them succeeding, rounded); None when no count up
    to `most` would (a rate seen at the requirement itself) or n = 0."""
    if n == 0:
        return None
    m = np.arange(n + 1, most + 1)
    fails = m - np.round(successes / n * m)
    low_fail, high_fail = binomial_bounds(fails, m)
    decided = np.flatnonzero((1.0 - high_fail >= required) | (1.0 - low_fail < required))
    return int(m[decided[0]]) if decided.size else None


def rate(successes: int, n: int, required: float, what: str,
         confidence: float = CONFIDENCE) -> Decision:
    """A success rate against `required` on its one-sided exact bounds at `confidence`."""
    kind = _one_sided(confidence) + ' exact bounds (Clopper-Pearson)'
    if n == 0:
        return Decision(UNDECIDED, f'share of {what}', None, kind, 0, f'no {what} yet')
    # the share of failures, bounded: success rate >= 1 - its upper bound
    low_fail, high_fail = binomial_bounds(n - successes, n, confidence)
    low, high = 1.0 - high_fail, 1.0 - low_fail
    said = (f'{successes} of {n} {what}: at least {_pc(low)} and at most {_pc(high)} '
            f'({kind}); required {_pc(required)} (requirements.success_rate)')
    verdict = FEASIBLE if low >= required else NOT_FEASIBLE if high < required else UNDECIDED
    return Decision(verdict, f'share of {what}', low if verdict != NOT_FEASIBLE else high,
                    kind, n, said, {'low': low, 'high': high, 'successes': successes})


def spills(runs: list[dict], limit: int, required: float,
           confidence: float = CONFIDENCE) -> Decision:
    """The share of refills that spilled at most `limit` parts over the tray's walls
    (requirements.max_spilled_parts) against `required` (requirements.success_rate), on its
    one-sided exact bounds (`rate`), as every share is decided: the paper's stop rule is the
    feeder emptied, and a refill that spills a part is not emptied by picking, so it counts
    against the refills that must succeed. None spilling in 3 runs settles nothing (at 90 %,
    29 runs without a spill do); 1 of 5 neither."""
    n = len(runs)
    within = sum(r['spilled'] <= limit for r in runs)
    total = int(sum(r['spilled'] for r in runs))
    what = f'refills spilling at most {limit} part(s)'
    decided = rate(within, n, required, what, confidence)
    said = (f"{total} part(s) spilled over the tray's walls in {n} runs (a refill spilling "
            f'more than requirements.max_spilled_parts, {limit}, is one the picking did not '
            'empty); ' + decided.reason)
    return replace(decided, quantity=f'share of {what}', reason=said,
                   detail={**decided.detail, 'spilled': total})


def combined(said: list[str]) -> str:
    """An option's verdict from its grounds' (`said`): NOT FEASIBLE when a ground is;
    FEASIBLE when every ground is; else UNDECIDED."""
    return (NOT_FEASIBLE if NOT_FEASIBLE in said else
            FEASIBLE if said and all(v == FEASIBLE for v in said) else UNDECIDED)


def _one_sided(confidence: float) -> str:
    return f'one-sided {round(confidence * 100, 6):g} %'


def table_time(runs: list[dict], refill: float, coverage: float,
               confidence: float = CONFIDENCE) -> Decision:
    """The table's time ground: the cell's time to empty a refill (`runs`, feeder_runs)
    against `refill`, s, for `coverage` of refills (requirements.success_rate) at
    `confidence` (module docstring)."""
    n = len(runs)
    times = np.array([r['time'] for r in runs], dtype=float)
    quantity = f'time to empty the feeder, {_pc(coverage)} of refills'
    if n == 0:
        return Decision(UNDECIDED, quantity, None, _one_sided(confidence), 0,
                        'no feeder run yet')
    cut = censored(runs, refill)
    over = int((times > refill).sum()) - len(cut)
    b_low = binomial_bounds(over, n, confidence)[0]
    b_high = binomial_bounds(over + len(cut), n, confidence)[1]
    free = (f'{over} of {n} runs over the interval or not emptied: their share at most '
            f'{_pc(b_high)} ({_one_sided(confidence)}, distribution-free), allowed '
            f'{_pc(1 - coverage)}')
    free_verdict = (FEASIBLE if b_high < 1 - coverage else
                    NOT_FEASIBLE if b_low > 1 - coverage else UNDECIDED)
    detail = {'over': over, 'censored': len(cut), 'refill_s': refill, 'coverage': coverage,
              'times_s': [t if math.isfinite(t) else None for t in times.tolist()],
              'distribution_free': {'verdict': free_verdict, 'share_bounds': [b_low, b_high]}}
    paced = bool(cut) and not (times <= refill).any() and sum(r['busy'] for r in runs) > 0
    free += _limited(cut, refill, said_pace=not paced)
    if paced:
        detail['pace'] = pace(runs, refill, confidence)
        if free_verdict == UNDECIDED and detail['pace']['emptied_share_at_most'] < coverage:
            free_verdict = detail['distribution_free']['verdict'] = NOT_FEASIBLE
        free += _paced(detail['pace'], coverage, confidence)
    fit = _gumbel(times, coverage, confidence) if over == 0 and not cut and n >= 3 else None
    if fit is not None:
        detail['gumbel'] = fit
    if fit is not None and fit['fits']:
        upper, lower = fit['upper'], fit['lower']
        verdict = FEASIBLE if upper <= refill else NOT_FEASIBLE if lower > refill else UNDECIDED
        weak = '; a weak check at 3 runs' if n == 3 else ''
        words = (f'{n} runs emptied in {_min(times.min())} to {_min(times.max())}: '
                 f'{_pc(coverage)} of refills empty within {_min(upper)} '
                 f'({_one_sided(confidence)} tolerance bound, Gumbel, probability plot '
                 f'correlation p = {fit["p"]:.2f}{weak}), against the {_min(refill)} refill '
                 f'interval; distribution-free: {free_verdict}')
        return Decision(verdict, quantity, upper,
                        _one_sided(confidence) + ' tolerance bound, Gumbel', n, words, detail)
    why = ('a run over the interval or not emptied' if over else
           'a run the vibration limit ended' if cut else
           'fewer than 3 runs for a fitted bound' if n < 3 else
           f'the Gumbel fit rejected, probability plot correlation p = {fit["p"]:.3f}')
    return Decision(free_verdict, quantity, None,
                    _one_sided(confidence) + ' distribution-free (binomial)', n,
                    f'{free} ({why})', detail)


def pace(runs: list[dict], refill: float, confidence: float = CONFIDENCE) -> dict:
    """The runs' picks over their cell time (feeder_runs' `picks`, `busy`, s; some time in
    all): the upper bound of that rate at `confidence` (Garwood's exact Poisson bound) and,
    at it, the chance that the refill's parts (the runs' `parts`) are all picked within
    `refill`, s."""
    picks = int(sum(r['picks'] for r in runs))
    busy = float(sum(r['busy'] for r in runs))
    upper = pace_bound(picks, busy, confidence)
    parts = max((r['parts'] or 0) for r in runs)
    return {'picks': picks, 'cell_h': busy / 3600.0, 'upper_per_h': float(upper * 3600.0),
            'parts': parts, 'emptied_share_at_most': emptied_share(upper, parts, refill)}


def pace_bound(picks: int, busy: float, confidence: float, upper: bool = True) -> float:
    """Garwood's exact one-sided bound at `confidence` of the rate of `picks` in `busy` s of
    cell time, per s: the upper (chi-square with 2 picks + 2 degrees of freedom), or the lower
    (2 picks; 0 with no pick), over 2 x the time."""
    if upper:
        return float(scipy_stats.chi2.ppf(confidence, 2 * picks + 2) / 2.0 / busy)
    return float(scipy_stats.chi2.ppf(1.0 - confidence, 2 * picks) / 2.0 / busy) if picks else 0.0


def emptied_share(rate: float, parts: int, refill: float) -> float:
    """The chance that a refill's `parts` are all picked within `refill` s at `rate` picks a
    second (a Poisson count reaching them); 1 with no parts."""
    return float(scipy_stats.poisson.sf(parts - 1, rate * refill)) if parts else 1.0


def _paced(p: dict, coverage: float, confidence: float) -> str:
    return (f'; the pace: {p["picks"]} picks in {p["cell_h"] * 60:.1f} min of cell time, at '
            f'most {p["upper_per_h"]:.3g} an hour ({_one_sided(confidence)}, Poisson), at '
            f'which at most {_pc(p["emptied_share_at_most"])} of refills of {p["parts"]} '
            f'would empty within the interval, required {_pc(coverage)}')


def censored(runs: list[dict], refill: float) -> list[dict]:
    """The runs (feeder_runs) that the vibration limit ended with parts left before the refill
    interval, `refill`, s, was spent: neither within the interval nor over it."""
    return [r for r in runs if r.get('limited') and r['busy'] <= refill]


def _limited(cut: list[dict], refill: float, said_pace: bool = True) -> str:
    """Said of the censored runs (`censored`): how far into the interval the limit ended them,
    and (`said_pace`, where `pace` does not bound it) the pace they picked at against the pace
    that empties a refill within it."""
    if not cut:
        return ''
    busy = sum(r['busy'] for r in cut)
    pace = (f': they picked {3600.0 * sum(r["picks"] for r in cut) / busy:.3g} parts an hour'
            if busy > 0 and said_pace else '')
    parts = cut[0]['parts']
    if pace and parts:
        pace += f' against the {3600.0 * parts / refill:.3g} that empty a refill of {parts} in it'
    return (f'; not counted: {len(cut)} run(s) stopped at the vibration limit '
            f'(max_vibrations) with parts left, {_min(max(r["busy"] for r in cut))} or less '
            f'into the {_min(refill)} interval{pace}; the limit ended them, not the interval, '
            'so they count as over it for FEASIBLE and as within it for NOT FEASIBLE'
            + _reaching(cut, refill))


def _reaching(cut: list[dict], refill: float) -> str:
    """The max_vibrations at which the censored runs (`censored`) would have reached the
    interval, `refill`, s, at the vibrations per second of cell time each ran at (the most
    of them, rounded up to a hundred), in words; '' where the rows do not say their
    vibrations. From cell time only, so the same runs say the same figure on any machine."""
    rates = [r['vibrations'] / r['busy'] for r in cut if r.get('vibrations') and r['busy'] > 0]
    if not rates:
        return ''
    most = 100 * math.ceil(max(rates) * refill / 100.0)
    return (f'; a max_vibrations of {most} would let each run reach the interval (each '
            f'simulating up to its {_min(refill)} of cell time)')


def gumbel_fit(values) -> tuple[float, float]:
    """The Gumbel's location and scale from `values` (the last axis: samples) by L-moments:
    scale lambda2 / ln 2, location lambda1 - Euler's gamma x scale (Hosking 1990)."""
    x = np.sort(np.asarray(values, dtype=float), axis=-1)
    n = x.shape[-1]
    b0 = x.mean(axis=-1)
    b1 = (x * (np.arange(n) / (n - 1))).mean(axis=-1)
    scale = (2.0 * b1 - b0) / math.log(2.0)
    return b0 - EULER_GAMMA * scale, scale


def standard_quantile(share):
    """The standard Gumbel's (location 0, scale 1) quantile of `share` (a float or an array)."""
    return -np.log(-np.log(share))


def gringorten(n: int) -> np.ndarray:
    """The standard Gumbel's quantiles at Gringorten's plotting positions (i - 0.44) /
    (n + 0.12), the probability plot's x for n ordered values."""
    return standard_quantile((np.arange(1, n + 1) - 0.44) / (n + 0.12))


def plot_correlation(values: np.ndarray) -> np.ndarray:
    """The probability plot correlation of `values` (the last axis: a sample, at least one
    value apart from the rest): their order statistics' correlation with gringorten's."""
    ordered = np.sort(values, axis=-1)
    centred = ordered - ordered.mean(axis=-1, keepdims=True)
    z = gringorten(ordered.shape[-1])
    z = z - z.mean()
    return centred @ z / np.sqrt((centred ** 2).sum(axis=-1) * (z @ z))


@functools.lru_cache(maxsize=8)     # 4.8 MB a size; an adaptive run looks at a few sizes
def _gumbel_pivots(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Of GUMBEL_DRAWS standard Gumbel samples of n (a seeded generator: the same every
    run): their L-moment location and scale, and their probability plot correlations,
    sorted."""
    rng = np.random.default_rng(20261127)
    location, scale, correlation = [], [], []
    for rows in np.array_split(np.arange(GUMBEL_DRAWS), max(1, GUMBEL_DRAWS * n // 2_000_000)):
        sample = rng.gumbel(size=(rows.size, n))
        a, b = gumbel_fit(sample)
        location.append(a)
        scale.append(b)
        correlation.append(plot_correlation(sample))
    return np.concatenate(location), np.concatenate(scale), np.sort(np.concatenate(correlation))


@functools.cache
def gumbel_k(n: int, coverage: float, confidence: float = CONFIDENCE) -> float:
    """The one-sided Gumbel tolerance factor: location + k scale (gumbel_fit) bounds
    `coverage` of the population from above with `confidence` (n >= 3): the `confidence`
    quantile of the pivot (quantile - location) / scale over standard samples."""
    location, scale, _ = _gumbel_pivots(n)
    return float(np.quantile((standard_quantile(coverage) - location) / scale, confidence))


def _gumbel(times: np.ndarray, coverage: float, confidence: float) -> dict:
    """The Gumbel fit of `times` (s, all finite, n >= 3) and the bounds of the times'
    `coverage` quantile: `upper` at `confidence` (the tolerance bound), `lower` at
    1 - `confidence`, `estimate` the quantile itself; `p` the probability plot correlation's
    (the share of standard samples that correlate less)."""
    n = len(times)
    location, scale = (float(v) for v in gumbel_fit(times))
    if scale > 0:
        r = float(plot_correlation(times))
        p = float(np.searchsorted(_gumbel_pivots(n)[2], r) / GUMBEL_DRAWS)
    else:
        p = 1.0     # every run took the same time: nothing to check
    k_upper, k_lower = gumbel_k(n, coverage, confidence), gumbel_k(n, coverage, 1 - confidence)
    return {'n': n, 'location_s': location, 'scale_s': scale, 'p': p, 'fits': p >= FIT_ALPHA,
            'k_upper': k_upper, 'k_lower': k_lower,
            'upper': location + k_upper * scale, 'lower': location + k_lower * scale,
            'estimate': location + float(standard_quantile(coverage)) * scale}


def _pc(share: float) -> str:
    """A share as the reports write it: 90 %, 63.2 %."""
    return f'{round(100 * share, 1):g} %'


def _min(seconds: float) -> str:
    return f'{seconds / 60:.1f} min'
