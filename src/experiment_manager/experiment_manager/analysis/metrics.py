"""The metrics of each experiment type, from the rows of its finished iterations.

bin_static: figure 14 (fractions of parts passing candidacy, placeability and the container stage
per bin) and the best bin. bin_emptying: Table 2 (emptied bins, parts removed: mean, min, max,
standard deviation; searches before each pick). table_sweep: figure 15 (mean valid parts per n),
the 4th-order polynomial fit, its maximum n* and the optimal range n* +- margin. feeder_emptying:
Table 3 (emptied runs, vibrations to empty the feeder, and the time per vibration the refill
interval allows). gripper_sweep (ours, not the paper's): per gripper and grasp set, the stage
fractions and the valid parts per check with their 95 % interval, and the smallest gripper whose
interval's low end reaches the experiment's min_valid. Standard deviations are sample ones
(n - 1), 0 for a single value.
"""

from dataclasses import asdict, dataclass

import numpy as np
from pick_common.stats import interval, rate_interval, stats

from ..experiment_file import (
    BIN_EMPTYING,
    BIN_STATIC,
    BinEmptyingExperiment,
    BinStaticExperiment,
    DROP_TEST,
    Experiment,
    FEEDER_EMPTYING,
    FeederEmptyingExperiment,
    GRIPPER_SWEEP,
    GripperSweepExperiment,
    Ran,
    TABLE_SWEEP,
    TableSweepExperiment,
)
from . import decisions, drop_tests
from . import summary as model
from .records import Faults, Flagged, Fractions, Physics, Stats
from .summary import SCHEMA_VERSION

# The physics faults an iteration is flagged with (procedures.faults); the first three leave it
# out of the figures.
PHYSICS_FAULT, TUNNELLED, THROWN, UNSETTLED = ('physics_fault', 'tunnelled', 'thrown',
                                               'unsettled')
FAULTS = (PHYSICS_FAULT, TUNNELLED, THROWN, UNSETTLED)
EXCLUDED = (PHYSICS_FAULT, TUNNELLED, THROWN)

FIT_ORDER = 4
BOOTSTRAP = 4000        # resamples of a table_sweep's iterations for the interval of n*


def _stats(values) -> Stats:
    return Stats(**stats(values))


def _fractions(rows: list[dict]) -> Fractions:
    return Fractions(**{stage: _stats([r[stage] / r['checked'] for r in rows if r.get('checked')])
                        for stage in ('candidates', 'placeable', 'container_free', 'valid')})


def _decision(d: decisions.Decision) -> model.Decision:
    return model.Decision(**d.as_dict())


def _scene_mm(rows: list[dict]) -> list[float] | None:
    """The first iteration's container, mm; None for no iteration."""
    return ([round(rows[0][k] * 1000, 6) for k in ('container_x', 'container_y', 'container_z')]
            if rows else None)


def _regrasps(exp: Experiment, rows: list[dict]) -> dict:
    """`regrasps` with a station (picks placed only after a regrasp, per iteration)."""
    return {'regrasps': _stats([r.get('regrasps', 0) for r in rows])} if exp.station else {}


def bin_static(exp: BinStaticExperiment,
               rows: list[dict], base: dict | None = None) -> model.BinStatic:
    bins = []
    for b, spec in enumerate(exp.bins):
        mine = [r for r in rows if r['group'] == b]
        bins.append(model.Bin(
            index=b, size_mm=[round(s * 1000, 6) for s in spec.inner_size],
            xy_area_mm2=round(spec.inner_size[0] * spec.inner_size[1] * 1e6, 3),
            iterations=len(mine), fractions=_fractions(mine),
            spilled=_stats([r['spilled'] for r in mine])))
    scored = [(b.fractions.container_free.mean, -b.index) for b in bins
              if b.fractions.container_free.mean is not None]
    best = -max(scored)[1] if scored else None
    return model.BinStatic(**(base or _base(exp, rows)), bins=bins, best_bin=best,
                           best_bin_mm=bins[best].size_mm if best is not None else None)


def bin_emptying(file: Ran, exp: BinEmptyingExperiment, rows: list[dict],
                 picks: list[dict], base: dict | None = None) -> model.BinEmptying:
    """Table 2, with `emptied_ci95`: the 95 % interval of the share of bins emptied, and
    `decision`: that share against requirements.success_rate on its one-sided bounds
    (decisions.rate)."""
    emptied = sum(bool(r['emptied']) for r in rows)
    decision = decisions.rate(emptied, len(rows), file.requirements.success_rate,
                              'bins emptied')
    return model.BinEmptying(
        **(base or _base(exp, rows)), iterations=len(rows), parts=exp.parts,
        decision=_decision(decision),
        bin_mm=_scene_mm(rows), emptied=emptied,
        emptied_ci95=list(rate_interval(emptied, len(rows))),
        removed=_stats([r['picks'] for r in rows]),
        searches_per_pick=_stats([p['searches'] for p in picks]), first_check=_fractions(rows),
        **_regrasps(exp, rows))


def fit(counts: np.ndarray, means: np.ndarray, order: int, first: int, last: int
        ) -> tuple[np.ndarray, np.ndarray]:
    """The least-squares polynomial of `order` through the counts' mean valid parts, every
    count weighing the same, and its maximum over the integers in [first, last]; `means` (K,)
    or (K, B): B fits at once (coefficients (order + 1, B), maxima (B,)). With as many
    iterations at every count (the fixed counts) this is the fit to every iteration; an
    adaptive sweep that drops more at some counts than at others fits the same curve."""
    coefficients = np.polyfit(counts, means, order)
    grid = np.arange(first, last + 1)
    values = np.polyval(coefficients, grid if means.ndim == 1 else grid[:, None])
    return coefficients, grid[np.argmax(values, axis=0)]


@dataclass(frozen=True)
class Fit:
    """A table_sweep's polynomial fit (fit_optimum): its order, coefficients (highest power
    first), n* at its maximum and the optimal range about it; fit_max the fit's value at n*
    (None for order 0: a single count); no_valid: no valid part at any count."""
    order: int
    coefficients: list[float]
    n_star: int
    optimal_range: list[int]
    no_valid: bool
    fit_max: float | None = None


def fit_optimum(counts, valid, first: int, last: int, margin: int) -> Fit:
    """The polynomial fit (order 4, lower with fewer distinct counts) of valid parts against
    parts on the table (`counts`, `valid`: one per iteration; fit), n* at its maximum over the
    integers in [first, last], and the range [max(1, n* - margin), n* + margin]."""
    n, v = np.asarray(counts, dtype=float), np.asarray(valid, dtype=float)
    tested = np.unique(n)
    order = min(FIT_ORDER, len(tested) - 1)
    # No valid part at any count: the fit is flat and n* says nothing.
    no_valid = not np.any(v > 0)
    if order < 1:
        best = int(n[0])
        return Fit(0, [float(np.mean(v))], best, [max(1, best - margin), best + margin],
                   no_valid)
    means = np.array([v[n == c].mean() for c in tested])
    coefficients, best = fit(tested, means, order, first, last)
    best = int(best)
    return Fit(order, coefficients.tolist(), best, [max(1, best - margin), best + margin],
               no_valid, float(np.polyval(coefficients, best)))


def resampled_means(by_count: list, rng: np.random.Generator) -> np.ndarray:
    """(counts, BOOTSTRAP) bootstrap means of each count's iterations (`by_count[i]`, m >= 2
    of them), resampled about their mean with their deviations widened by sqrt(m / (m - 1)):
    resampling m values as they are gives their mean (m - 1) / m of its variance (Davison and
    Hinkley 1997, section 3.3), a fifth too little at an adaptive sweep's first look of 5."""
    out = []
    for v in by_count:
        v = np.asarray(v, dtype=float)
        widened = v.mean() + (v - v.mean()) * np.sqrt(len(v) / (len(v) - 1.0))
        out.append(widened[rng.integers(0, len(v), (len(v), BOOTSTRAP))].mean(axis=0))
    return np.stack(out)


def n_star_interval(counts, by_count: list, order: int, first: int, last: int,
                    confidence: float, rng: np.random.Generator) -> tuple[int, int] | None:
    """The bootstrap interval of n*: BOOTSTRAP fits of `order` (fit) to the counts' means of
    their iterations resampled (resampled_means; `by_count[i]`: the valid parts of
    `counts[i]`'s iterations), and the quantiles of their maxima over [first, last]; None
    while a count has fewer than two iterations (one says nothing of its spread)."""
    if order < 1 or any(len(v) < 2 for v in by_count):
        return None
    _, stars = fit(np.asarray(counts, dtype=float), resampled_means(by_count, rng), order,
                   first, last)
    tail = (1.0 - confidence) / 2.0
    return (int(np.quantile(stars, tail, method='lower')),
            int(np.quantile(stars, 1.0 - tail, method='higher')))


def table_sweep(file: Ran, exp: TableSweepExperiment, rows: list[dict],
                base: dict | None = None) -> model.TableSweep:
    """Valid parts per count, the fit and its n* with optimal range, and `n_star_ci95`: n*'s
    95 % bootstrap interval (n_star_interval, seeded by the file's seed and the rows), when
    every count has two iterations or more."""
    per_n, by_count = [], []
    for n in exp.counts:
        mine = [r['valid'] for r in rows if r['group'] == n]
        by_count.append(mine)
        if mine:
            per_n.append(model.Count(n=n, valid=_stats(mine)))
    fitted = {}
    if rows:
        found = fit_optimum([r['group'] for r in rows], [r['valid'] for r in rows],
                            exp.counts[0], exp.counts[-1], exp.margin)
        fitted = {k: v for k, v in asdict(found).items() if k != 'fit_max' or v is not None}
        ci = n_star_interval(exp.counts, by_count, found.order, exp.counts[0], exp.counts[-1],
                             0.95, np.random.default_rng([file.seed, len(rows)]))
        if ci:
            fitted['n_star_ci95'] = list(ci)
    return model.TableSweep(**(base or _base(exp, rows)), iterations=exp.iterations,
                            per_n=per_n, margin=exp.margin, **fitted)


def feeder_emptying(file: Ran, exp: FeederEmptyingExperiment, rows: list[dict],
                    optimal_range, base: dict | None = None) -> model.FeederEmptying:
    """`emptied`: runs that emptied the feeder and the table; `accepted`: of them, those that
    spilled at most requirements.max_spilled_parts over the tray's walls, and `accepted_ci95`
    the 95 % interval of that share of the runs (rate_interval); `parts_per_hour`: the cell's
    throughput per run that picked (cell_throughput) and its 95 % interval (interval);
    `decision`: the table's grounds (decisions.py), `time` (the cell's time to empty a refill
    against the refill interval) and `spills` (parts spilled per refill against
    requirements.max_spilled_parts)."""
    emptied = [r for r in rows if r['emptied']]
    hourly = throughputs(file.cell, rows)
    tolerated = file.requirements.max_spilled
    accepted = sum(r['spilled'] <= tolerated for r in emptied)
    vibrations = _stats([r['vibrations'] for r in emptied])
    refill = file.requirements.refill_interval
    grounds = table_grounds(file, rows)
    return model.FeederEmptying(
        **(base or _base(exp, rows)), iterations=len(rows), parts=exp.parts,
        optimal_range=list(optimal_range), max_vibrations=exp.max_vibrations,
        emptied=len(emptied), accepted=accepted,
        accepted_ci95=list(rate_interval(accepted, len(rows))), max_spilled=tolerated,
        runs_spilling=sum(r['spilled'] > 0 for r in rows), vibrations_to_empty=vibrations,
        feeds=_stats([r['feeds'] for r in rows]),
        stops={s: sum(r['stop'] == s for r in rows) for s in sorted({r['stop'] for r in rows})},
        minutes_per_vibration_allowed=(refill / vibrations.mean / 60.0 if vibrations.mean
                                       else None),
        parts_per_hour=_stats(hourly), parts_per_hour_ci95=list(interval(hourly)),
        cell=model.Cell(pick_s=file.cell.pick_time, image_s=file.cell.image_time,
                        regrasp_s=file.cell.regrasp_time),
        decision=model.TableGrounds(time=_decision(grounds['time']),
                                    spills=_decision(grounds['spills'])),
        first_check=_fractions(rows), **_regrasps(exp, rows))


def table_grounds(file: Ran, rows: list[dict],
                  confidence: float = decisions.CONFIDENCE) -> dict[str, decisions.Decision]:
    """The vibrating table's grounds from its feeder runs (`rows`, typed, left-out ones
    removed): the cell's time to empty a refill, and the spills."""
    runs = decisions.feeder_runs(rows, file.cell)
    r = file.requirements
    return {'time': decisions.table_time(runs, r.refill_interval, r.success_rate, confidence),
            'spills': decisions.spills(runs, r.max_spilled, r.success_rate, confidence)}


def throughputs(cell, rows: list[dict]) -> list[float]:
    """cell_throughput of each feeder run that picked."""
    return [cell_throughput(cell, r) for r in rows if r['picks']]


def cell_throughput(cell, row: dict) -> float:
    """The parts per hour a feeder run's cell would pick: its picks over the cell's time the
    run took (decisions.cell_time)."""
    return 3600.0 * row['picks'] / decisions.cell_time(row, cell)


def gripper_sweep(exp: GripperSweepExperiment, rows: list[dict], checks: list[dict],
                  base: dict | None = None) -> model.GripperSweep:
    """Per variant (gripper and grasp set, in the experiment's order; check k of each scene is
    variant k): the stage fractions, the valid parts per check with their 95 % interval
    (interval(counts=True)) and the scenes with at least one valid part; `meets`: the
    interval's low end is at least min_valid. `smallest`: the index of the smallest variant
    that meets (GripperVariant.size; the first in the file's order among equals), None when
    none does."""
    kept = {(r['group'], r['iteration']) for r in rows}
    variants = []
    for k, v in enumerate(exp.variants):
        mine = [c for c in checks if c['check'] == k and (c['group'], c['iteration']) in kept]
        valid = [c['valid'] for c in mine]
        low, high = interval(valid, counts=True)
        variants.append(model.Variant(
            index=k, grasp_set=v.grasp_set, grasps=[g.name for g in v.grasps],
            gripper_mm=v.gripper.file_values(), scenes=len(mine), fractions=_fractions(mine),
            valid=_stats(valid), valid_ci95=[low, high],
            scenes_with_valid=sum(x > 0 for x in valid),
            meets=low is not None and low >= exp.min_valid))
    by_size = sorted(range(len(variants)), key=lambda k: (exp.variants[k].size, k))
    smallest = next((k for k in by_size if variants[k].meets), None)
    return model.GripperSweep(**(base or _base(exp, rows)), iterations=len(rows),
                              parts=exp.parts, scene_mm=_scene_mm(rows),
                              min_valid=exp.min_valid, variants=variants, smallest=smallest)


def physics(rows: list[dict]) -> Physics:
    """The physics health of every iteration (left-out ones too): parts spilled, tunnelled and
    thrown (totals), the most parts left moving at a settle's end, the deepest penetration (m),
    the fastest part (m/s) and the worst tray tracking error (fraction of the command)."""
    return Physics(spilled=sum(r['spilled'] for r in rows),
                   tunnelled=sum(r['tunnelled'] for r in rows),
                   thrown=sum(r['thrown'] for r in rows),
                   max_speed=max((r['max_speed'] for r in rows), default=0.0),
                   unsettled=max((r['unsettled'] for r in rows), default=0),
                   max_penetration=max((r['max_penetration'] for r in rows), default=0.0),
                   tray_error=max((r['tray_error'] for r in rows), default=0.0))


def fault_counts(rows: list[dict]) -> Faults:
    """How many iterations each physics fault flagged (procedures.faults), and which."""
    return Faults(**{name: sum(name in r['fault'].split('+') for r in rows) for name in FAULTS},
                  flagged=[Flagged(group=r['group'], iteration=r['iteration'], fault=r['fault'])
                           for r in rows if r['fault']])


def left_out(rows: list[dict]) -> set[tuple[int, int]]:
    """(group, iteration) of the iterations left out of the figures: those with a fault of
    EXCLUDED."""
    return {(r['group'], r['iteration']) for r in rows
            if set(r['fault'].split('+')) & set(EXCLUDED)}


def _base(exp: Experiment, rows: list[dict]) -> dict:
    """The fields every experiment's summary has (summary._Experiment) from all its rows,
    left-out ones too: its type, faults and physics health, and its gripper and station when
    it names them."""
    return {'type': exp.type, 'faults': fault_counts(rows), 'physics': physics(rows),
            **({'gripper': exp.gripper} if exp.gripper else {}),
            **({'station': True} if exp.station else {})}


def summarise(file: Ran, exp: Experiment, rows: list[dict], picks: list[dict],
              earlier: dict | None = None, checks: list[dict] = ()) -> model.Experiment:
    """The metrics of one experiment from its rows of iterations.csv, picks.csv and checks.csv.
    `earlier`: the summaries of the experiments before it (for feeder_emptying's range taken
    from a table_sweep). Iterations that ended in a physics fault or with a tunnelled or
    thrown part have no figures and are left out; every flagged iteration is listed in
    `faults`, and `physics` tells the health of all."""
    base = _base(exp, rows)
    faulted = left_out(rows)
    rows = [r for r in rows if (r['group'], r['iteration']) not in faulted]
    picks = [p for p in picks if (p['group'], p['iteration']) not in faulted]
    return SUMMARIES[exp.type](file, exp, rows, picks, earlier or {}, checks, base)


def file_summary(file: Ran, summaries: dict) -> model.Summary:
    """The run's summary, as summary.json holds it: `experiments`, the file's own by id;
    `repeats`, a sensitivity experiment's repeats of them in its scenarios (id
    `<experiment>@<scenario>`), apart, so that the verdicts and the report's tables are the
    file's experiments'."""
    r = file.requirements
    repeats = {k: v for k, v in summaries.items() if '@' in k}
    return model.Summary(
        schema_version=SCHEMA_VERSION, id=file.id, seed=file.seed,
        requirements=model.Requirements(
            parts_per_hour=r.parts_per_hour, refill_interval_h=r.refill_interval / 3600.0,
            capacity=r.capacity, success_rate=r.success_rate,
            max_dimension_mm=round(r.max_dimension * 1000, 6)),
        experiments={k: v for k, v in summaries.items() if k not in repeats},
        **({'repeats': repeats} if repeats else {}))


# Per kind, its metrics: (file, exp, rows, picks, the summaries before it, checks, the base
# fields) -> its summary. A sensitivity's are sensitivity.summarise's, from its repeats'.
SUMMARIES = {
    BIN_STATIC: lambda file, exp, rows, picks, earlier, checks, base: bin_static(exp, rows,
                                                                                 base),
    BIN_EMPTYING: lambda file, exp, rows, picks, earlier, checks, base: bin_emptying(
        file, exp, rows, picks, base),
    TABLE_SWEEP: lambda file, exp, rows, picks, earlier, checks, base: table_sweep(
        file, exp, rows, base),
    FEEDER_EMPTYING: lambda file, exp, rows, picks, earlier, checks, base: feeder_emptying(
        file, exp, rows, exp.optimal_range or earlier[exp.range_from].optimal_range, base),
    GRIPPER_SWEEP: lambda file, exp, rows, picks, earlier, checks, base: gripper_sweep(
        exp, rows, checks, base),
    DROP_TEST: lambda file, exp, rows, picks, earlier, checks, base: drop_tests.summary(
        file, exp, rows, base),
}
