"""Decisions on what each run measures, with one-sided bounds where the requirement is
one-sided (issue 43).

The vibrating table. The requirement is a time: the cell must pick a refill's parts within the
refill interval. Each feeder run measures its cell's time to empty the feeder (`feeder_runs`:
picks x cell.pick_s, images x cell.image_s, and the table's simulated feeds and vibrations); a
run that did not empty counts as over the interval. The table is decided on the upper
tolerance bound that covers requirements.success_rate (say 90 %) of refills at 95 %
confidence (`table_time`):
- lognormal: the times' logarithms taken as normal (a time is positive and its spread grows
  with it), the bound exp(mean + k s) with the exact one-sided k factor (the noncentral t,
  Krishnamoorthy and Mathew, *Statistical Tolerance Regions*, 2009, sec. 2.2; NIST/SEMATECH
  e-Handbook 7.2.6.3). Used when every run emptied within the interval and Shapiro-Wilk does
  not reject the fit at 5 % (checked on the data; with 3 runs the check is weak, and said so);
  FEASIBLE when the upper bound is within the interval; NOT FEASIBLE when the lower 95 % bound
  of the same quantile is beyond it;
- distribution-free, beside it: the runs over the interval (or not emptied) as a binomial
  count: FEASIBLE when the one-sided 95 % upper bound of their share is below 1 - success_rate
  (with none over, 29 runs at 90 %), NOT FEASIBLE when its lower bound is above it. Used alone
  when the lognormal bound cannot be (a run over the interval, or the fit rejected).
  Where this rests on an assumption: the fitted bound takes a run that would not empty as the
  lognormal's own far tail. A feeder that jams now and then for a reason of its own (a part
  that wedges) is a second mode the fit cannot see in 3 runs that emptied; only the
  distribution-free count shows it, and needs 29 runs to show it below 10 %.
Spills are a rate: parts spilled per refill, bounded one-sidedly (Poisson, over all the runs)
against requirements.max_spilled_parts; at a limit of 0 a spill is a count that must be zero.

Rates of success (bins emptied, `rate`): the exact (Clopper-Pearson) one-sided 95 % bounds:
FEASIBLE when the lower bound reaches the required rate, NOT FEASIBLE when the upper bound lies
below it.

Pure: no rclpy, no files.
"""

from dataclasses import dataclass, field
import math

import numpy as np
from scipy import stats

FEASIBLE, NOT_FEASIBLE, UNDECIDED = 'FEASIBLE', 'NOT FEASIBLE', 'UNDECIDED'
CONFIDENCE = 0.95
FIT_ALPHA = 0.05        # a Shapiro-Wilk p below this rejects the lognormal fit


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
    time to empty the feeder, s (inf for a run that did not empty), and `spilled`."""
    out = []
    for r in rows:
        picking = r['picks'] * cell.pick_time
        busy = picking + r['checks'] * cell.image_time + r['table_time']
        out.append({'time': busy if r['emptied'] else math.inf, 'spilled': r['spilled'],
                    'emptied': bool(r['emptied']), 'picking': picking})
    return out


def k_factor(n: int, coverage: float, confidence: float = CONFIDENCE) -> float:
    """The one-sided normal tolerance factor: mean + k s bounds `coverage` of the population
    from above with `confidence` (noncentral t; n >= 2)."""
    z = stats.norm.ppf(coverage)
    return float(stats.nct.ppf(confidence, n - 1, z * math.sqrt(n)) / math.sqrt(n))


def binomial_bounds(over, n, confidence: float = CONFIDENCE):
    """One-sided exact (Clopper-Pearson) bounds of a share from `over` of `n` (ints, or int
    arrays of one shape): (lower, upper), each at `confidence`."""
    k, n = np.asarray(over), np.asarray(n)
    with np.errstate(invalid='ignore', divide='ignore'):
        low = np.where(k > 0, stats.beta.ppf(1 - confidence, k, n - k + 1), 0.0)
        high = np.where(k < n, stats.beta.ppf(confidence, k + 1, n - k), 1.0)
    return (float(low), float(high)) if not low.shape else (low, high)


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


def spills(runs: list[dict], limit: int, confidence: float = CONFIDENCE) -> Decision:
    """Parts spilled over the tray's walls per refill against `limit`
    (requirements.max_spilled_parts): a Poisson rate over all the runs, one-sided bounds
    (Garwood's exact ones); at a limit of 0 a count that must be zero."""
    n, total = len(runs), int(sum(r['spilled'] for r in runs))
    quantity = 'parts spilled per refill'
    if limit == 0:
        kind = 'a count that must be zero'
        verdict = NOT_FEASIBLE if total else FEASIBLE if n else UNDECIDED
        return Decision(verdict, quantity, float(total), kind, n,
                        f"{total} parts spilled over the tray's walls in {n} runs; the limit "
                        'is 0 (requirements.max_spilled_parts: a spilled part is lost)',
                        {'spilled': total})
    kind = _one_sided(confidence) + ' Poisson bounds (Garwood)'
    if n == 0:
        return Decision(UNDECIDED, quantity, None, kind, 0, 'no feeder run yet')
    upper = stats.chi2.ppf(confidence, 2 * (total + 1)) / (2 * n)
    lower = stats.chi2.ppf(1 - confidence, 2 * total) / (2 * n) if total else 0.0
    verdict = FEASIBLE if upper <= limit else NOT_FEASIBLE if lower > limit else UNDECIDED
    return Decision(verdict, quantity, float(upper if verdict != NOT_FEASIBLE else lower), kind,
                    n, f'{total} parts spilled in {n} runs: {lower:.2f} to {upper:.2f} per '
                    f'refill ({kind}); the limit is {limit} (requirements.max_spilled_parts)',
                    {'spilled': total, 'low': lower, 'high': upper})


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
    over = int((times > refill).sum())
    b_low, b_high = binomial_bounds(over, n, confidence)
    free = (f'{over} of {n} runs over the interval or not emptied: their share at most '
            f'{_pc(b_high)} ({_one_sided(confidence)}, distribution-free), allowed '
            f'{_pc(1 - coverage)}')
    free_verdict = (FEASIBLE if b_high < 1 - coverage else
                    NOT_FEASIBLE if b_low > 1 - coverage else UNDECIDED)
    detail = {'over': over, 'refill_s': refill, 'coverage': coverage,
              'times_s': [t if math.isfinite(t) else None for t in times.tolist()],
              'distribution_free': {'verdict': free_verdict, 'share_bounds': [b_low, b_high]}}
    # the robot's time is known once every part is picked (picks x cell.pick_s, the same in
    # every emptied run): the spread is the table's and the camera's, and it is what is fitted
    picking = max((r.get('picking', 0.0) for r in runs), default=0.0)
    fit = (_lognormal(times, coverage, confidence, picking) if over == 0 and n >= 3
           and (times > picking).all() else None)
    if fit is not None:
        detail['lognormal'] = fit
    if fit is not None and fit['fits']:
        upper, lower = fit['upper'], fit['lower']
        verdict = FEASIBLE if upper <= refill else NOT_FEASIBLE if lower > refill else UNDECIDED
        weak = '; a weak check at 3 runs' if n == 3 else ''
        words = (f'{n} runs emptied in {_min(times.min())} to {_min(times.max())}: '
                 f'{_pc(coverage)} of refills empty within {_min(upper)} '
                 f'({_one_sided(confidence)} tolerance bound, lognormal, Shapiro-Wilk p = '
                 f'{fit["p"]:.2f}{weak}), against the {_min(refill)} refill interval; '
                 f'distribution-free: {free_verdict}')
        return Decision(verdict, quantity, upper,
                        _one_sided(confidence) + ' tolerance bound, lognormal', n, words, detail)
    why = ('a run over the interval or not emptied' if over else
           'fewer than 3 runs for a fitted bound' if n < 3 else
           f'the lognormal fit rejected, Shapiro-Wilk p = {fit["p"]:.3f}')
    return Decision(free_verdict, quantity, None,
                    _one_sided(confidence) + ' distribution-free (binomial)', n,
                    f'{free} ({why})', detail)


def _lognormal(times: np.ndarray, coverage: float, confidence: float,
               shift: float = 0.0) -> dict:
    """The lognormal fit of `times` - `shift` (s, all finite and > `shift`, n >= 3; `shift`:
    the part of every time that does not vary) and the bounds of the times' `coverage`
    quantile: `upper` at `confidence` (the tolerance bound), `lower` at 1 - `confidence`,
    `estimate` the quantile itself; `p` Shapiro-Wilk's on the logarithms."""
    logs = np.log(times - shift)
    n = len(logs)
    mean, sd = float(logs.mean()), float(logs.std(ddof=1))
    p = float(stats.shapiro(logs).pvalue) if sd > 0 else 1.0
    k_upper = k_factor(n, coverage, confidence)
    k_lower = k_factor(n, coverage, 1 - confidence)
    return {'n': n, 'log_mean': mean, 'log_sd': sd, 'p': p, 'fits': p >= FIT_ALPHA,
            'shift_s': shift, 'k_upper': k_upper, 'k_lower': k_lower,
            'upper': shift + math.exp(mean + k_upper * sd),
            'lower': shift + math.exp(mean + k_lower * sd),
            'estimate': shift + math.exp(mean + stats.norm.ppf(coverage) * sd)}


def _pc(share: float) -> str:
    """A share as the reports write it: 90 %, 63.2 %."""
    return f'{round(100 * share, 1):g} %'


def _min(seconds: float) -> str:
    return f'{seconds / 60:.1f} min'
