"""Decisions on what the runs measure (analysis/decisions.py): the one-sided bounds against
their published values and their own promise (coverage), on made-up data."""

import math

from experiment_manager.analysis import decisions
from experiment_manager.experiment_file.model import Cell
import numpy as np
from pick_common.stats import binomial_bounds
import pytest
from scipy import stats


def test_the_gumbel_fit_finds_the_location_and_scale_it_was_drawn_with():
    location, scale = decisions.gumbel_fit(np.random.default_rng(5).gumbel(900.0, 30.0, 100_000))
    assert location == pytest.approx(900.0, abs=0.5) and scale == pytest.approx(30.0, rel=0.01)


def test_the_gumbel_bound_covers_the_quantile_as_often_as_it_promises():
    """Drawn from a known Gumbel (another generator than the factors'), the 95 % upper bound of
    the 90 % quantile lies above the true quantile in 95 % of samples, and the 95 % lower
    bound below it in 95 %, whatever the sample's size."""
    rng = np.random.default_rng(43)
    location, scale = 1200.0, 40.0
    quantile = location - scale * math.log(-math.log(0.9))
    for n in (3, 5, 12):
        upper, lower = [], []
        for _ in range(2000):
            runs = [{'time': t, 'spilled': 0} for t in rng.gumbel(location, scale, n)]
            fit = decisions.table_time(runs, 1e9, 0.9).detail['gumbel']
            upper.append(fit['upper'] >= quantile)
            lower.append(fit['lower'] <= quantile)
        # 2,000 samples: a coverage of 95 % is seen within 0.5 % (one standard deviation)
        assert 0.935 <= np.mean(upper) <= 0.965, (n, np.mean(upper))
        assert 0.935 <= np.mean(lower) <= 0.965, (n, np.mean(lower))


def test_the_fit_check_rejects_as_often_as_it_should_and_a_sample_the_gumbel_cannot_be():
    """Gumbel samples are rejected at 5 % about 5 % of the time; a sample skewed the other
    way (most runs long, a few short) nearly always."""
    rng = np.random.default_rng(7)
    rejected = [not decisions.table_time([{'time': t, 'spilled': 0} for t in
                                          rng.gumbel(1000.0, 20.0, 12)], 1e9, 0.9)
                .detail['gumbel']['fits'] for _ in range(2000)]
    assert 0.04 <= np.mean(rejected) <= 0.06
    left = [[{'time': 2000.0 - t, 'spilled': 0} for t in rng.gumbel(1000.0, 20.0, 12)]
            for _ in range(200)]
    assert np.mean([not decisions.table_time(r, 1e9, 0.9).detail['gumbel']['fits']
                    for r in left]) > 0.3


def test_the_time_ground_decides_on_the_bound_and_says_which():
    runs = [{'time': t, 'spilled': 0} for t in (1000.0, 1010.0, 1030.0)]
    far = decisions.table_time(runs, 14400.0, 0.9)
    assert far.verdict == decisions.FEASIBLE and far.runs == 3
    assert far.interval == 'one-sided 95 % tolerance bound, Gumbel'
    assert 1030.0 < far.bound < 14400.0
    assert decisions.table_time(runs, 900.0, 0.9).verdict == decisions.NOT_FEASIBLE
    near = decisions.table_time(runs, 1040.0, 0.9)     # past the runs, inside the bound
    assert near.verdict == decisions.UNDECIDED
    # runs that all took the same time: nothing spreads, the bound is that time
    same = decisions.table_time([{'time': 1000.0, 'spilled': 0}] * 3, 14400.0, 0.9)
    assert same.verdict == decisions.FEASIBLE and same.bound == pytest.approx(1000.0)
    # two runs: no fitted bound; the distribution-free one needs 29 runs all within
    two = decisions.table_time(runs[:2], 14400.0, 0.9)
    assert two.verdict == decisions.UNDECIDED and 'fewer than 3 runs' in two.reason
    assert binomial_bounds(0, 29)[1] < 0.1 <= binomial_bounds(0, 28)[1]
    # a run that did not empty: over the interval, the distribution-free bound alone
    stuck = runs + [{'time': math.inf, 'spilled': 0}]
    said = decisions.table_time(stuck, 14400.0, 0.9)
    assert said.interval == 'one-sided 95 % distribution-free (binomial)'
    assert said.verdict == decisions.UNDECIDED and said.detail['over'] == 1


def test_runs_the_vibration_limit_ended_early_in_the_interval_are_censored():
    # KiCad's axial resistor on the board cell: 5 feeder runs of 80 ended at the 500-vibration
    # limit after 7-10 picks, 9.6 min of cell time into the 240 min interval, about 56 an
    # hour (9 in 575 s here) where 20 empty the refill in it; read as "not emptied", the
    # limit made the table NOT FEASIBLE, not the interval
    cell = Cell()
    row = {'picks': 9, 'checks': 509, 'table_time': 538.7, 'regrasps': 0, 'spilled': 0,
           'parts': 80, 'vibrations': 500}
    cut = {**row, 'emptied': False, 'stop': 'stop: vibration limit'}
    runs = decisions.feeder_runs([cut, {**cut, 'table_time': 20000.0},
                                  {**row, 'emptied': True, 'stop': 'stop: empty'}], cell)
    assert [r['limited'] for r in runs] == [True, True, False]
    said = decisions.table_time(runs, 14400.0, 0.9)
    # the second ran past the interval: over it, whatever ended it
    assert said.detail['over'] == 1 and said.detail['censored'] == 1
    assert '1 of 3 runs over the interval or not emptied' in said.reason
    assert 'not counted: 1 run(s) stopped at the vibration limit (max_vibrations) with parts ' \
        'left, 9.6 min or less into the 240.0 min interval: they picked 56.4 parts an hour ' \
        'against the 20 that empty a refill of 80 in it' in said.reason
    # and the limit that would have let it reach the interval: 500 vibrations in its 575 s,
    # 12,521 in 240 min, rounded up to a hundred
    reach = 100 * math.ceil(500 * 14400.0 / runs[0]['busy'] / 100)
    assert reach == 12600
    assert f'a max_vibrations of {reach} would let each run reach the interval' in said.reason
    assert 'vibration limit' not in decisions.table_time(runs[1:], 14400.0, 0.9).reason
    # five such runs: NOT FEASIBLE as "not emptied", UNDECIDED as censored (counted over, the
    # share is at most 100 %; counted within, at least 0 %); no Gumbel fit either way
    five = decisions.feeder_runs([cut] * 5, cell)
    limited = decisions.table_time(five, 14400.0, 0.9)
    assert limited.verdict == decisions.UNDECIDED and limited.detail['over'] == 0
    assert 'a run the vibration limit ended' in limited.reason and 'gumbel' not in limited.detail
    # the pace: 45 picks in 48 min of cell time, at most 79 an hour (95 %, Poisson), at which
    # a refill of 80 empties within 4 h: it cannot be NOT FEASIBLE on it either
    assert limited.detail['pace']['picks'] == 45
    assert limited.detail['pace']['upper_per_h'] == pytest.approx(
        stats.chi2.ppf(0.95, 92) / 2 / (5 * runs[0]['busy']) * 3600)
    assert limited.detail['pace']['emptied_share_at_most'] > 0.99
    # the terminal block's jaws: no pick in 5 runs of 9.4 min; at most 3.8 picks an hour, and
    # at that pace no refill of 80 empties within 4 h: NOT FEASIBLE on the pace
    none = decisions.feeder_runs([{**cut, 'picks': 0, 'table_time': 520.0}] * 5, cell)
    stuck = decisions.table_time(none, 14400.0, 0.9)
    assert stuck.verdict == decisions.NOT_FEASIBLE and stuck.detail['over'] == 0
    assert stuck.detail['pace']['emptied_share_at_most'] < 1e-6
    assert 'the pace: 0 picks in ' in stuck.reason
    # one such run of 8.7 min says so too: at most 20.7 an hour, 83 in 4 h, which would empty
    # a refill of 80 at most 64 % of the time; a run of 2 min is too short to: at most 90
    one = decisions.table_time(none[:1], 14400.0, 0.9)
    assert one.verdict == decisions.NOT_FEASIBLE
    assert one.detail['pace']['emptied_share_at_most'] == pytest.approx(0.642, abs=1e-3)
    short = decisions.feeder_runs([{**cut, 'picks': 0, 'table_time': 120.0}], cell)
    assert decisions.table_time(short, 14400.0, 0.9).verdict == decisions.UNDECIDED
    # beside 29 runs that emptied within it, one censored run keeps FEASIBLE out of reach
    # (1 of 30 counted over: at most 14.8 %), and would not with it counted within
    quick = decisions.feeder_runs([{**row, 'emptied': True}] * 29, cell)
    assert decisions.table_time(quick + five[:1], 14400.0, 0.9).verdict == decisions.UNDECIDED
    assert decisions.table_time(quick, 14400.0, 0.9).verdict == decisions.FEASIBLE


def test_spills_are_a_share_of_refills_decided_on_its_bounds():
    clean = [{'time': 1.0, 'spilled': 0}] * 30
    spilled = {'time': 1.0, 'spilled': 2}
    # none of 3: refills may still spill up to 63.2 % of the time (its 95 % bound)
    three = decisions.spills(clean[:3], 0, 0.9)
    assert three.verdict == decisions.UNDECIDED and three.detail['low'] == pytest.approx(
        0.05 ** (1 / 3))
    # 1 of 5: the share within lies between 34 % and 99 %: neither side
    five = decisions.spills(clean[:4] + [spilled], 0, 0.9)
    assert five.verdict == decisions.UNDECIDED and five.detail['successes'] == 4
    assert five.detail['spilled'] == 2
    assert '4 of 5 refills spilling at most 0 part(s)' in five.reason
    # none of 30: at least 90.5 % of refills spill nothing
    thirty = decisions.spills(clean, 0, 0.9)
    assert thirty.verdict == decisions.FEASIBLE and thirty.detail['low'] > 0.9
    assert decisions.spills(clean[:28], 0, 0.9).verdict == decisions.UNDECIDED
    # every one of 3 spilling: at most 63.2 % spill nothing
    assert decisions.spills([spilled] * 3, 0, 0.9).verdict == decisions.NOT_FEASIBLE
    # a refill may spill 2 parts: those runs are within the limit
    assert decisions.spills(clean[:28] + [spilled] * 2, 2, 0.9).verdict == decisions.FEASIBLE
    assert decisions.spills([], 0, 0.9).verdict == decisions.UNDECIDED


def test_a_rate_decides_on_its_one_sided_bounds():
    assert decisions.rate(29, 29, 0.9, 'bins emptied').verdict == decisions.FEASIBLE
    assert decisions.rate(28, 28, 0.9, 'bins emptied').verdict == decisions.UNDECIDED
    assert decisions.rate(0, 2, 0.9, 'bins emptied').verdict == decisions.NOT_FEASIBLE
    assert decisions.rate(0, 1, 0.9, 'bins emptied').verdict == decisions.UNDECIDED
