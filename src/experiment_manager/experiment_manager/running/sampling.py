"""Adaptive sampling: how many iterations an experiment needs before its decision is settled.

With `sampling.mode: adaptive` an experiment's iterations run in batches of `sampling.batch`
per group (bin, count of parts on the tray; one group otherwise), up to the file's
`iterations`, which stay the most it may take. After each batch is written, the scheduler
asks `unsettled` which groups still need one; when none does (or none has iterations left),
the experiment stops. The
iterations keep the keys and seeds of the fixed counts (plan.py), so an adaptive run is the
first iterations of the fixed-count run of the same file, and its figures are computed from
them exactly as the fixed counts' (metrics.py).

What settles each decision, looked at after every batch:
- bin_emptying: the share of bins emptied against requirements.success_rate, on its
  one-sided exact bounds, as the verdict reads it (decisions.rate): settled when the lower
  bound reaches the requirement or the upper bound lies below it.
- feeder_emptying: the table's grounds as the verdict reads them (metrics.table_grounds): the
  cell's time to empty a refill against the refill interval (its tolerance bound) and the
  share of refills spilling at most requirements.max_spilled_parts (its exact bounds: with no
  spill, 66 runs at the interim 99.9 %, 29 at the last look's 95 %); settled when one ground
  is NOT FEASIBLE or every ground FEASIBLE, or when FEASIBLE is out of reach for a run the
  vibration limit ended with the interval unspent (censored: decisions.table_time): counted
  over the interval for FEASIBLE, it keeps the last look's 95 % upper bound of the share over
  at or above 1 - success_rate even if every iteration left emptied within it, so more runs
  cannot make the table FEASIBLE (a stop for futility: Snapinn et al., "Assessment of
  futility in clinical trials", Pharmaceutical Statistics 5(4), 2006), and NOT FEASIBLE is
  out of reach too or has had its chance: the runs' pace at its INTERIM_CONFIDENCE lower
  bound (Garwood's, as decisions.pace's upper) already empties success_rate of refills
  within the interval, so the pace will not say NOT FEASIBLE; or LIMITED_RUNS (5) runs have
  been made. Its verdict is what the runs so far say: UNDECIDED, with the limit named and
  the pace the censored runs picked at, or NOT FEASIBLE. Without the stop a feeder whose
  runs all reach the limit would run every iteration (30 in the board cell) to it, where the
  paper's reading, not emptied, settled it in one batch of 5. A look after fewer runs (a
  smaller batch) stops as soon as the pace is clear: the sonde board's DIPs picked 5 in
  their first run's 9.5 min of cell time, at least 4.67 an hour at 99.9 %, at which 99.8 %
  of refills of 8 empty within 4 h. An iteration left
  out of the figures (a physics fault) settles bins and feeder too: the verdict is NOT
  FEASIBLE then.
- bin_static, a race: a bin leaves it when it is known to lie below the leading bin (the
  highest mean container-free fraction): the one-sided RACE_CONFIDENCE (99.95 %) upper bound of
  its mean less the leader's, Welch's (metrics.difference_bound), is below 0. The race ends
  with one bin left (the best bin), or with a tie: every bin left is known to lie within
  BIN_TIE (5 %) of the leader (the same bound of the leader's mean less the bin's at most 5 %
  of the leader's lower bound), so whichever of them is taken gives at least 95 % of the best
  bin's container-free parts (the leader is named best; the summary lists the tie); or at the
  most iterations. 5 % is our choice, the same as FLAT_TOP's: PTH1's three widest bins lie
  within 1 % of each other on 40 drops each and no race could part them. Not two intervals
  that must not overlap (a bin left when its own 99.9 % interval lay below the leader's): they
  ask for a difference of about the sum of their half-widths, where the difference's
  own bound asks for about the root of the sum of their squares, and on 5 drops a t with 4
  degrees of freedom where Welch's has up to 8. The chance that the best bin leaves at a look
  is at most (bins - 1) x 0.05 % (a comparison with each bin that could lead), where the two
  intervals' was bins x 0.05 %.
- table_sweep: the optimum n* of the fit, bootstrapped (metrics.n_star_interval: iterations
  resampled within each count, a seed of the file's): settled when the interval of n* lies
  inside the optimal range n* +- margin, so the feeder runs' range holds the optimum; or when
  the top is flat: the fit across the whole interval of n* stays within FLAT_TOP (5 %) of its
  peak, so wherever in it the optimum lies, the range at n* gives the feeder runs at least
  95 % of the best valid parts per check (a feeder's checks to empty grow about as their
  inverse: at most about 5 % more). 5 % is our choice, not a source's; on PTH0's flat top
  (n* 72, its interval 70-100 on all 4,000 drops) the margin alone never settles. Or when
  no feeder run that reads its range could run otherwise (`range_unread`): n* and its
  interval's low end, less the margin, reach the parts each holds (plan.held), so each puts
  all its parts on the table whatever the range; nor is it extended then (plan.extended). A
  board's refill of 8 DIPs had its sweep run 160 drops, extended past 100 parts, for an
  optimum of 133 that no feeder run of 8 reads. Every
  count gets the first batch (the fit needs its whole curve); each later look places as many
  parts' worth of drops as a batch at every count would, where they narrow n* most
  (_sweep_batches), so a sweep takes about as many looks as with a batch at every count.
- gripper_sweep: the smallest gripper meeting min_valid (metrics.gripper_sweep): settled when,
  in size order, every gripper before the first that meets is known not to meet (its interval
  of valid parts per check lies below min_valid) and that one is known to meet (its interval's
  low end at least min_valid), or every gripper is known not to meet.

Looking again and again at the same growing sample and stopping at the first clear interval
would make a 95 % interval wrong more often than 1 in 20. So a look before the last uses
INTERIM_CONFIDENCE (99.9 %) intervals and bounds, and only the last look, at the most
iterations, the 95 % ones every figure reports: the Haybittle-Peto rule of clinical trials
(Haybittle 1971, Peto et al. 1976). With L looks the chance of a wrong early stop is at most
L x 0.1 %.
"""

import numpy as np
from pick_common.stats import binomial_bounds, difference_bound, interval

from ..analysis import decisions, metrics
from ..experiment_file import (
    BIN_EMPTYING,
    BIN_STATIC,
    BinEmptyingExperiment,
    BinStaticExperiment,
    DROP_TEST,
    DropTestExperiment,
    Experiment,
    ExperimentFile,
    FEEDER_EMPTYING,
    FeederEmptyingExperiment,
    GRIPPER_SWEEP,
    GripperSweepExperiment,
    TABLE_SWEEP,
    TableSweepExperiment,
)
from ..experiment_file.kinds import kind_of
from ..experiment_file.plan import groups, held

INTERIM_CONFIDENCE = 0.999
# The feeder runs a table whose runs the vibration limit ends is given before its pace alone
# decides it: the one batch of the default sampling.batch (5) it was given before the pace.
LIMITED_RUNS = 5
# a bin's difference from the leader, one-sided: the tail of each INTERIM_CONFIDENCE interval
RACE_CONFIDENCE = 1.0 - (1.0 - INTERIM_CONFIDENCE) / 2.0
FLAT_TOP = 0.05     # a sweep's top is flat when its fit over n*'s interval is within this
BIN_TIE = 0.05      # bins tie when each is known to lie within this share of the leader


def unsettled(file: ExperimentFile, exp: Experiment, rows: list[dict],
              checks: list[dict] = ()) -> list[int]:
    """The groups of `exp` that need more iterations for its decision, from `rows` (its
    iterations written so far, any order) and `checks` (its rows of checks.csv, for a
    gripper_sweep), at INTERIM_CONFIDENCE; [] when the decision is settled."""
    return ended(file, exp, rows, checks)[0]


def ended(file: ExperimentFile, exp: Experiment, rows: list[dict],
          checks: list[dict] = ()) -> tuple[list[int], list[int]]:
    """(unsettled's groups, the bins of a tie that settled a bin_static race: race)."""
    kept, out = _kept(rows)
    if out and kind_of(exp).left_out_settles:
        return [], []       # a left-out iteration makes the option NOT FEASIBLE: settled
    if kind_of(exp).uses_checks:
        kept_keys = {(r['group'], r['iteration']) for r in kept}
        checks = [c for c in checks if (c['group'], c['iteration']) in kept_keys]
    return DECISIONS[exp.type](file, exp, kept, checks)


def _kept(rows: list[dict]) -> tuple[list[dict], set]:
    """The rows a look reads, in (group, iteration) order, without those left out of the
    figures (metrics.left_out), and the keys of those left out."""
    rows = sorted(rows, key=lambda r: (r['group'], r['iteration']))
    out = metrics.left_out(rows)
    return [r for r in rows if (r['group'], r['iteration']) not in out], out


def _drops_unsettled(file: ExperimentFile, exp: DropTestExperiment, kept: list[dict],
                     checks: list[dict]) -> tuple[list[int], list[int]]:
    return groups(exp), []      # no decision: every drop asked for is made


def _gripper_unsettled(file: ExperimentFile, exp: GripperSweepExperiment, kept: list[dict],
                       checks: list[dict]) -> tuple[list[int], list[int]]:
    return ([] if _smallest_settled(exp, checks) else groups(exp)), []


def _emptying_unsettled(file: ExperimentFile, exp: BinEmptyingExperiment, kept: list[dict],
                        checks: list[dict]) -> tuple[list[int], list[int]]:
    successes = sum(bool(r['emptied']) for r in kept)
    return ([] if rate_settled(successes, len(kept), file.requirements.success_rate)
            else groups(exp)), []


def _feeder_unsettled(file: ExperimentFile, exp: FeederEmptyingExperiment, kept: list[dict],
                      checks: list[dict]) -> tuple[list[int], list[int]]:
    grounds = metrics.table_grounds(file.ran, kept, INTERIM_CONFIDENCE)
    required = file.requirements.success_rate
    time = grounds['time']
    settled = (decisions.combined([g.verdict for g in grounds.values()]) != decisions.UNDECIDED
               or _out_of_reach(time, exp.iterations, required)
               and (time.runs >= LIMITED_RUNS or _pace_clear(time, required)))
    return ([] if settled else groups(exp)), []


def _pace_clear(time: decisions.Decision, required: float) -> bool:
    """The time ground's pace (decisions.pace: no run emptied within the interval), at its
    INTERIM_CONFIDENCE lower bound (Garwood), empties at least `required` of refills within
    the interval: more runs will not make it say NOT FEASIBLE."""
    p = time.detail.get('pace')
    if not p:
        return False
    low = decisions.pace_bound(p['picks'], 3600.0 * p['cell_h'], INTERIM_CONFIDENCE,
                               upper=False)
    return low > 0 and decisions.emptied_share(low, p['parts'], time.detail['refill_s']) \
        >= required


def _out_of_reach(time: decisions.Decision, iterations: int, required: float) -> bool:
    """The table's time ground (decisions.table_time) holds a censored run and cannot be
    FEASIBLE at `iterations` runs even if every one left emptied within the interval: its
    last look's upper bound of the share over, censored runs counted over, reaches
    1 - `required`."""
    cut = time.detail.get('censored', 0)
    if not cut:
        return False
    over = time.detail['over'] + cut
    return binomial_bounds(over, max(iterations, time.runs))[1] >= 1.0 - required


def rate_settled(successes: int, n: int, required: float,
                 confidence: float = INTERIM_CONFIDENCE) -> bool:
    """The rate's one-sided exact bounds at `confidence` put it at or above `required`, or
    below it (decisions.rate)."""
    return decisions.rate(successes, n, required, '', confidence).verdict != decisions.UNDECIDED


def race(exp: BinStaticExperiment, rows: list[dict]) -> tuple[list[int], list[int]]:
    """(the bins still in the race, the bins of a tie that ended it). Racing: the leader (the
    highest mean container-free fraction) and every bin not known to lie below it: the
    one-sided RACE_CONFIDENCE bound of its mean less the leader's (metrics.difference_bound)
    reaches 0; all of them while any has fewer than two iterations; none when one is left (it
    is the best) or when those left tie within BIN_TIE of the leader: the same bound of the
    leader's mean less each one's at most BIN_TIE of the leader's INTERIM_CONFIDENCE lower
    bound (they are then the tie, the leader first)."""
    if len(groups(exp)) == 1:
        return [], []
    fractions = {g: [r['container_free'] / r['checked'] for r in rows
                     if r['group'] == g and r['checked']] for g in groups(exp)}
    if any(len(v) < 2 for v in fractions.values()):
        return groups(exp), []
    leader = max(groups(exp), key=lambda g: (np.mean(fractions[g]), -g))
    ahead = fractions[leader]
    racing = [g for g in groups(exp) if g == leader
              or difference_bound(fractions[g], ahead, RACE_CONFIDENCE) >= 0.0]
    if len(racing) == 1:
        return [], []
    floor = interval(ahead, INTERIM_CONFIDENCE)[0]
    if all(difference_bound(ahead, fractions[g], RACE_CONFIDENCE) <= BIN_TIE * floor
           for g in racing if g != leader):
        return [], [leader] + [g for g in racing if g != leader]
    return racing, []


def _sweep_unsettled(file: ExperimentFile, exp: TableSweepExperiment,
                     rows: list[dict]) -> list[int]:
    """[] when the sweep's n* is settled (no feeder run reading it could run otherwise:
    range_unread; its bootstrap interval at INTERIM_CONFIDENCE lies inside n* +- margin; or
    the fit is flat across it: FLAT_TOP), else where the next look's drops go
    (_sweep_batches). The counts' rows and the fit are made once for all."""
    by_count, fitted, low, high = _sweep_look(file, exp, rows)
    if fitted is None:              # also every row left out: nothing to fit
        return _sweep_batches(file, exp, by_count, None)
    if low is None:
        return []           # one count: n* is that count
    if _above(file, exp, fitted, low) is not None:
        return []
    best = fitted.n_star
    if best - exp.margin <= low and high <= best + exp.margin:
        return []
    peak = fitted.fit_max
    if peak > 0 and np.polyval(fitted.coefficients, np.arange(low, high + 1)).min() \
            >= (1.0 - FLAT_TOP) * peak:
        return []           # a flat top: any n* of its interval yields within FLAT_TOP
    return _sweep_batches(file, exp, by_count, fitted)


def _sweep_look(file: ExperimentFile, exp: TableSweepExperiment, rows: list[dict]
                ) -> tuple[list[np.ndarray], metrics.Fit | None, int | None, int | None]:
    """What a look at a sweep's rows (in _kept's order) sees: each count's valid parts, the
    fit (None while a count has fewer than two iterations) and n*'s bootstrap interval at
    INTERIM_CONFIDENCE, seeded by the file's seed and the rows (None, None for a fit of one
    count)."""
    by_count = [np.array([r['valid'] for r in rows if r['group'] == n], dtype=float)
                for n in exp.counts]
    if any(len(v) < 2 for v in by_count):
        return by_count, None, None, None
    first, last = exp.counts[0], exp.counts[-1]
    fitted = metrics.fit_optimum([r['group'] for r in rows], [r['valid'] for r in rows],
                                 first, last, exp.margin)
    if fitted.order < 1:
        return by_count, fitted, None, None
    low, high = metrics.n_star_interval(exp.counts, by_count, fitted.order, first, last,
                                        INTERIM_CONFIDENCE,
                                        np.random.default_rng([file.seed, len(rows)]))
    return by_count, fitted, low, high


def range_unread(file: ExperimentFile, exp: TableSweepExperiment, rows: list[dict]
                 ) -> int | None:
    """The parts of the feeder runs that read `exp`'s range (plan.held) when the sweep's
    range is known, at INTERIM_CONFIDENCE, to start at or above them (as a look at `rows`
    sees it: _sweep_look): its fit's n* and the low end of n*'s bootstrap interval, less the
    margin, both reach them. Every feeder run then puts all its parts on the table whatever
    more drops would make of n*, so they read nothing more of the sweep (a refill of 8 DIPs
    on a sweep whose optimum is 133). None otherwise."""
    if held(file, exp) is None:
        return None
    _, fitted, low, _ = _sweep_look(file, exp, _kept(rows)[0])
    return None if low is None else _above(file, exp, fitted, low)


def _above(file: ExperimentFile, exp: TableSweepExperiment, fitted: metrics.Fit, low: int
           ) -> int | None:
    """plan.held's parts when the fit's n* and `low` (n*'s interval's low end), less the
    margin, both reach them; else None."""
    parts = held(file, exp)
    if parts is None or min(fitted.n_star, low) - exp.margin < parts:
        return None
    return parts


def _sweep_batches(file: ExperimentFile, exp: TableSweepExperiment, by_count: list[np.ndarray],
                   fitted: metrics.Fit | None) -> list[int]:
    """Where a sweep's next look puts its iterations: as many parts' worth of drops as a batch
    at every count, given a batch at a time to the count where a batch shrinks the variance of
    the fit's slope at n* most per part dropped (a greedy sequential c-optimal design: n* is
    where that slope crosses zero, so its spread is the slope's over the curvature). The fit
    weighs every count's mean the same (metrics.fit), so the slope's variance is the sum over
    counts of influence^2 x variance / iterations, and more drops at a count narrow n* without
    moving the curve the fixed counts fit. Each count's variance of valid parts is smoothed by
    a quadratic in n (a count seen five times can show no spread by chance). A count listed k
    times gets k batches. Every count has had the first batch, so the whole curve is known.
    Falls back to a batch at every count when the fit cannot say (no fit, no spread at all,
    or too few counts). `by_count`: each count's valid parts; `fitted`: metrics.fit_optimum's
    fit of them, None while a count has fewer than two iterations."""
    batch = file.sampling.batch
    counts = np.array(exp.counts, dtype=float)
    taken = np.array([len(v) for v in by_count], dtype=float)
    left = exp.iterations - taken
    # not settled: never [], even with no iterations left (the scheduler then stops)
    everywhere = [n for n, k in zip(exp.counts, left, strict=True) if k > 0] or list(exp.counts)
    if fitted is None or fitted.order < 1 or len(counts) < 3:
        return everywhere
    first, last, order = exp.counts[0], exp.counts[-1], fitted.order
    spread = np.array([v.var(ddof=1) for v in by_count])
    if not spread.any():
        return everywhere
    smooth = np.polyval(np.polyfit(counts, spread, 2, w=np.sqrt(taken - 1.0)), counts)
    variance = np.maximum(smooth, 1e-3 * spread.max())
    u = 2.0 * (counts - first) / (last - first) - 1.0      # the fit's basis, scaled
    basis = np.vander(u, order + 1)
    at = 2.0 * (fitted.n_star - first) / (last - first) - 1.0
    slope = np.array([k * at ** (k - 1) if k else 0.0 for k in range(order, -1, -1)])
    influence = basis @ np.linalg.solve(basis.T @ basis, slope)   # d slope / d mean, per count
    weight = influence ** 2 * variance

    def gains(m: np.ndarray, step: np.ndarray) -> np.ndarray:
        """The slope's variance removed per part dropped by `step` more iterations."""
        with np.errstate(divide='ignore', invalid='ignore'):
            return np.where(step > 0, weight * (1.0 / m - 1.0 / (m + step)) / (step * counts),
                            -np.inf)

    # A look drops at most as many parts as a batch at every count, so a sweep takes about as
    # many looks as with a batch at every count (the interim confidence's bound grows with the
    # looks; PTH0's unsettled sweep: 9 against 8).
    budget = batch * counts.sum()
    given = np.zeros(len(counts))
    out = []
    while True:
        step = np.minimum(batch, left - given)
        g = np.where(step * counts <= budget, gains(taken + given, step), -np.inf)
        best = int(np.argmax(g))
        if g[best] == -np.inf:
            break
        budget -= step[best] * counts[best]
        given[best] += step[best]
        out.append(exp.counts[best])
    return out or everywhere


def _smallest_settled(exp: GripperSweepExperiment, checks: list[dict]) -> bool:
    """In size order: every gripper known not to meet min_valid up to one known to meet it,
    or all known not to."""
    for k in sorted(range(len(exp.variants)), key=lambda k: (exp.variants[k].size, k)):
        low, high = interval([c['valid'] for c in checks if c['check'] == k],
                                     INTERIM_CONFIDENCE, counts=True)
        if low is None:
            return False
        if low >= exp.min_valid:
            return True
        if high >= exp.min_valid:
            return False
    return True


# Per kind, whether its decision is settled: (file, exp, its kept rows, its kept checks) ->
# (unsettled groups, the bins of a tie that settled a race). A sensitivity has none: its
# repeats are sampled as the experiments they repeat.
DECISIONS = {
    BIN_STATIC: lambda file, exp, kept, checks: race(exp, kept),
    BIN_EMPTYING: _emptying_unsettled,
    TABLE_SWEEP: lambda file, exp, kept, checks: (_sweep_unsettled(file, exp, kept), []),
    FEEDER_EMPTYING: _feeder_unsettled,
    GRIPPER_SWEEP: _gripper_unsettled,
    DROP_TEST: _drops_unsettled,
}
