"""Adaptive sampling: the rule that settles each experiment type's decision (on rows made up to
the case), and a run that stops once it is settled, on the real cores."""

from dataclasses import replace
import json
import os
from types import SimpleNamespace

from experiment_manager import experiment_file
from experiment_manager.analysis import metrics, report
from experiment_manager.analysis.headlines import headlines
from experiment_manager.analysis.report import Run
from experiment_manager.analysis.results import read_text_rows, ResultsWriter
from experiment_manager.analysis.summary import Sampling, Summary
from experiment_manager.analysis.verdicts import NOT_FEASIBLE, UNDECIDED, verdicts
from experiment_manager.analysis.wording import sampling_end
from experiment_manager.experiment_file import plan
from experiment_manager.running import sampling
from experiment_manager.running.local_backend import LocalBackend
from experiment_manager.running.scheduler import Runner
import numpy as np
from pick_common.errors import InvalidArgument
from pick_common.stats import difference_bound, interval, rate_interval
import pytest
from scipy import stats

SMALL = os.path.join(os.path.dirname(__file__), 'small_experiment.yaml')


def small(**sampling_section) -> experiment_file.ExperimentFile:
    text = open(SMALL).read()
    if sampling_section:
        text += f'sampling: {json.dumps(sampling_section)}\n'
    return experiment_file.parse(text, SMALL)


HEALTHY = dict.fromkeys(('spilled', 'tunnelled', 'thrown', 'max_speed', 'unsettled',
                         'max_penetration', 'tray_error'), 0)


def row(group: int, i: int, **values) -> dict:
    """An iteration's row as iterations.csv reads, healthy: no part spilled or moving."""
    return {'group': group, 'iteration': i, 'fault': '', **HEALTHY, **values}


def test_the_sampling_section_is_read_and_checked():
    assert small().sampling == experiment_file.Sampling('fixed', 5)
    assert small(mode='adaptive', batch=3).sampling.adaptive
    with pytest.raises(InvalidArgument, match=r"sampling.mode.*'every'"):
        small(mode='every')
    with pytest.raises(InvalidArgument, match=r'sampling.batch'):
        small(mode='adaptive', batch=0)
    copy = experiment_file.parse(experiment_file.reduced(small(), None, adaptive=True), SMALL)
    assert copy.sampling.adaptive and copy.experiments == small().experiments


def test_a_rate_is_settled_once_its_99_9_percent_bound_clears_or_misses_the_requirement():
    # One-sided 99.9 % bounds. 0 of 2: the upper bound is 0.968, above 0.9; 0 of 4: 0.822.
    assert not sampling.rate_settled(0, 2, 0.9)
    assert sampling.rate_settled(0, 4, 0.9)
    # Every iteration a success: the lower bound 0.001^(1/n) reaches 0.9 at 66 runs (99.9 %),
    # 0.05^(1/n) at 29 (95 %; the two-sided 95 % interval needed 36).
    assert not sampling.rate_settled(65, 65, 0.9) and sampling.rate_settled(66, 66, 0.9)
    assert not sampling.rate_settled(28, 28, 0.9, confidence=0.95)
    assert sampling.rate_settled(29, 29, 0.9, confidence=0.95)
    assert not sampling.rate_settled(0, 0, 0.9)


def feeder_run(i: int, table_time: float = 60.0, **values) -> dict:
    """A feeder run of 12 picks and 30 checks (about 480 parts per hour at 4 s a pick)."""
    return row(0, i, **{'emptied': True, 'spilled': 0, 'picks': 12, 'checks': 30,
                        'table_time': table_time, **values})


def test_feeder_runs_settle_on_their_time_to_empty_and_their_spills():
    file = small()          # a refill every 4 h, no spill allowed
    exp = file.experiment('feeder')
    # Three runs emptying in about 110 s (12 picks of 4 s and about 60 s of the table): the
    # 99.9 % tolerance bound lies far inside the 4 h interval; but none spilling in 3 runs
    # leaves the spills open (at 99.9 %, 66 runs without a spill settle them). Two runs give
    # no fitted bound.
    quick = [feeder_run(i, 60.0 + i % 3) for i in range(66)]
    assert sampling.unsettled(file, exp, quick[:3]) == [0]
    assert sampling.unsettled(file, exp, quick[:65]) == [0]
    assert sampling.unsettled(file, exp, quick) == []
    # Runs that spilled: every one of 4 puts the share that spill nothing below 90 % at
    # 99.9 % (at most 82.2 %): NOT FEASIBLE, settled; one run spilling is not.
    assert sampling.unsettled(file, exp, [dict(r, spilled=1) for r in quick[:4]]) == []
    assert sampling.unsettled(file, exp, [dict(quick[0], spilled=1)]) == [0]
    # Runs that did not empty count as over the interval: 4 of 4 put the share over it above
    # 10 % at 99.9 % (at least 17.8 %), 2 of 2 do not (at least 3.2 %).
    stuck = [feeder_run(i, emptied=False) for i in range(4)]
    assert sampling.unsettled(file, exp, stuck) == []
    assert sampling.unsettled(file, exp, stuck[:2]) == [0]
    # Times spread up to the interval: the bound reaches past it, the lower one does not.
    spread = [feeder_run(i, t) for i, t in enumerate([3000.0, 9000.0, 14000.0, 6000.0])]
    assert sampling.unsettled(file, exp, spread) == [0]
    # A tunnelled part leaves the run out and makes the option NOT FEASIBLE: settled.
    tunnelled = [feeder_run(0, fault='tunnelled')]
    assert sampling.unsettled(file, exp, tunnelled) == []


def test_runs_the_limit_ends_stop_once_neither_verdict_is_in_reach_or_after_five():
    """Feeder runs that the vibration limit ends 9 min into the 4 h interval (censored): one
    keeps FEASIBLE out of reach of 30 runs. Where they picked 6 each, 12 in 2 runs is at least
    18 an hour at 99.9 %, which empties a refill of 12 within 4 h: the pace will not say NOT
    FEASIBLE either, and 2 runs settle it (so does 1). Where they picked nothing, NOT FEASIBLE
    stays in reach and the runs go on, to LIMITED_RUNS (5), as one batch of the default 5
    did."""
    file = small()
    exp = replace(file.experiment('feeder'), iterations=30)
    limited = dict(emptied=False, stop='stop: vibration limit', parts=12)
    picking = [feeder_run(i, 500.0, picks=6, **limited) for i in range(2)]
    assert sampling.unsettled(file, exp, picking) == []
    # one run of 6 is clear too (at least 10 an hour); one of 1 pick is not
    assert sampling.unsettled(file, exp, picking[:1]) == []
    assert sampling.unsettled(file, exp, [dict(picking[0], picks=1)]) == [0]
    idle = [feeder_run(i, 500.0, picks=0, **limited) for i in range(5)]
    for k in range(1, sampling.LIMITED_RUNS):
        assert sampling.unsettled(file, exp, idle[:k]) == [0]
    assert sampling.LIMITED_RUNS == 5 and sampling.unsettled(file, exp, idle) == []


def four_bins() -> tuple:
    """The small file and its bins experiment with 4 bins."""
    file = small()
    return file, replace(file.experiment('bins'), bins=file.experiment('bins').bins * 2)


def bin_rows(rng, means: list[int], n: int) -> list[dict]:
    """n drops per bin of 100 parts checked, container-free around each bin's mean (+-2)."""
    return [row(g, i, checked=100, container_free=int(m + rng.integers(-2, 3)))
            for g, m in enumerate(means) for i in range(n)]


def test_bins_leave_the_race_when_they_are_clearly_behind_the_leader():
    file, exp = four_bins()
    rng = np.random.default_rng(0)
    assert sampling.unsettled(file, exp, bin_rows(rng, [90, 89, 60, 30], 6)) == [0, 1]
    assert sampling.unsettled(file, exp, bin_rows(rng, [90, 50, 60, 30], 6)) == []  # one: best
    assert sampling.unsettled(file, exp, bin_rows(rng, [90, 50, 60, 30], 1)) == [0, 1, 2, 3]
    one = replace(exp, bins=exp.bins[:1])        # nothing to race: the one bin is the best
    assert sampling.unsettled(file, one, bin_rows(rng, [90], 1)) == []


def test_a_bin_leaves_the_race_on_its_difference_from_the_leader():
    """Bins 5 points of 100 apart on 6 drops of +-2: their own 99.9 % intervals still overlap
    (an earlier rule raced them on), but the one-sided bound of the difference, at
    each interval's tail, lies below 0: the second leaves and the leader is the best."""
    file, exp = four_bins()
    rows = bin_rows(np.random.default_rng(0), [90, 85, 60, 30], 6)
    share = [[r['container_free'] / 100 for r in rows if r['group'] == g] for g in (0, 1)]
    ahead, second = (interval(v, sampling.INTERIM_CONFIDENCE) for v in share)
    assert second[1] >= ahead[0]                                # the intervals overlap
    assert difference_bound(share[1], share[0], sampling.RACE_CONFIDENCE) < 0
    assert sampling.race(exp, rows) == ([], [])


def test_the_difference_bound_is_welchs_one_sided_test():
    """Below 0 exactly when Welch's one-sided t test (scipy's) rejects at 1 - confidence, and
    equal to the difference when neither sample varies."""
    rng = np.random.default_rng(3)
    for _ in range(50):
        a, b = rng.normal(0.0, rng.uniform(0.5, 2.0), 6), rng.normal(1.0, 1.0, 9)
        p = stats.ttest_ind(a, b, equal_var=False, alternative='less').pvalue
        bound = difference_bound(a, b, 0.99)
        assert (bound < 0) == (p < 0.01)
        t = stats.ttest_ind(a, b, equal_var=False)
        assert bound == pytest.approx(a.mean() - b.mean() + stats.t.ppf(0.99, t.df)
                                      * (a.mean() - b.mean()) / t.statistic)
    assert difference_bound([1.0, 1.0], [3.0, 3.0], 0.99) == -2.0


def test_a_race_between_bins_that_tie_within_bin_tie_ends_in_the_tie(monkeypatch):
    file, exp = four_bins()
    rng = np.random.default_rng(2)
    close = [60, 89, 90, 30]        # bins 1 and 2 a point apart, of 100 parts
    assert sampling.race(exp, bin_rows(rng, close, 6)) == ([1, 2], [])   # not yet known to tie
    tied = bin_rows(rng, close, 30)
    assert sampling.race(exp, tied) == ([], [2, 1])             # the leader first
    assert sampling.ended(file, exp, tied) == ([], [2, 1])
    monkeypatch.setattr(sampling, 'BIN_TIE', 0.0)               # no tie: they race on
    assert sampling.unsettled(file, exp, tied) == [1, 2]


def unread(file: experiment_file.ExperimentFile) -> experiment_file.ExperimentFile:
    """The file without its feeder runs: no one reads its sweep's range (plan.held)."""
    return replace(file, experiments=tuple(e for e in file.experiments
                                           if e.type != 'feeder_emptying'))


def test_a_sweep_is_settled_when_the_optimum_s_interval_lies_inside_its_range():
    file = unread(small())
    exp = replace(file.experiment('sweep'), counts=tuple(range(10, 101, 10)), margin=5)
    rng = np.random.default_rng(1)

    def rows(noise, n):
        return [row(c, i, valid=max(0.0, 20 - (c - 50) ** 2 / 100 + rng.normal(0, noise)))
                for c in exp.counts for i in range(n)]

    assert sampling.unsettled(file, exp, rows(0.3, 10)) == []
    assert sampling.unsettled(file, exp, rows(8.0, 3)) == list(exp.counts)
    assert sampling.unsettled(file, exp, rows(0.3, 1)) == list(exp.counts)    # one each
    # every iteration left out (a physics fault): nothing to fit, a batch at every count
    faulted = [{**r, 'fault': metrics.PHYSICS_FAULT} for r in rows(0.3, 1)]
    assert sampling.unsettled(file, exp, faulted) == list(exp.counts)


def test_a_sweep_with_a_flat_top_is_settled_when_any_n_star_of_its_interval_yields_the_same():
    # Valid parts rise to 20 at n = 40 and stay there: n* may be anywhere in 40-100, so its
    # interval never lies within +-5, but every range in it yields within 5 % of the best.
    file = unread(small())
    exp = replace(file.experiment('sweep'), counts=tuple(range(10, 101, 10)), margin=5)
    rng = np.random.default_rng(2)
    flat = [row(c, i, valid=min(20.0, c / 2) + rng.normal(0, 3.0))
            for c in exp.counts for i in range(5)]
    fitted = metrics.fit_optimum([r['group'] for r in flat], [r['valid'] for r in flat],
                                 10, 100, 5)
    low, high = metrics.n_star_interval(exp.counts, [[r['valid'] for r in flat
                                                      if r['group'] == c] for c in exp.counts],
                                        fitted.order, 10, 100, sampling.INTERIM_CONFIDENCE,
                                        np.random.default_rng([file.seed, len(flat)]))
    assert high - low > 2 * exp.margin          # the margin alone would not settle it
    assert sampling.unsettled(file, exp, flat) == []
    # a broad hump is no flat top: 25 % lower 30 parts from its peak, with noise to match
    hump = [row(c, i, valid=20 - (c - 70) ** 2 / 180 + rng.normal(0, 4.0))
            for c in exp.counts for i in range(3)]
    assert sampling.unsettled(file, exp, hump) == list(exp.counts)


def test_a_sweep_stops_once_no_feeder_run_reading_its_range_could_run_otherwise():
    """A broad hump about 70 parts, too noisy for its n* to settle within +-5 on 3 drops a
    count: the small file's feeder runs (12 parts, their range the sweep's) put every part on
    the table for any range from n*'s interval, so the sweep is settled; with 60 parts they
    would not be, nor with no feeder reading it. It says so in its sampling."""
    file = small()
    exp = replace(file.experiment('sweep'), counts=tuple(range(10, 101, 10)), margin=5,
                  extend=True)
    file = replace(file, experiments=tuple(exp if e.id == 'sweep' else e
                                           for e in file.experiments))
    rng = np.random.default_rng(3)
    hump = [row(c, i, valid=20 - (c - 70) ** 2 / 180 + rng.normal(0, 4.0))
            for c in exp.counts for i in range(3)]
    assert file.experiment('feeder').parts == 12
    assert sampling.unsettled(file, exp, hump) == []
    assert sampling.range_unread(file, exp, hump) == 12
    more = replace(file, experiments=tuple(replace(e, parts=60) if e.id == 'feeder' else e
                                           for e in file.experiments))
    assert sampling.range_unread(more, exp, hump) is None
    assert sampling.unsettled(more, exp, hump) == list(exp.counts)
    assert sampling.unsettled(unread(file), exp, hump) == list(exp.counts)
    # before every count has two drops, nothing is known of n*'s interval
    assert sampling.range_unread(file, exp, [r for r in hump if r['iteration'] == 0]) is None
    # a sweep still rising at its last count is not extended for feeder runs of 12: its range
    # starts at 95 whatever more counts would show; for runs of 120 it would be
    rising = metrics.table_sweep(file.ran, exp, [row(c, i, valid=c / 10 + i)
                                                 for c in exp.counts for i in range(2)])
    assert rising.n_star == 100 and rising.optimal_range[0] == 95
    assert plan.extended(file, exp, rising) is None
    more = replace(file, experiments=tuple(replace(e, parts=120) if e.id == 'feeder' else e
                                           for e in file.experiments))
    assert plan.extended(more, exp, rising).counts[-1] > 100
    said = SimpleNamespace(sampling=Sampling(mode='adaptive', batch=5, batches=1,
                                             iterations_run=30, most=100, settled=True,
                                             held=12))
    assert sampling_end(said) == ('settled: its range starts at or above the 12 parts its '
                                  'feeder runs hold, which they put on the table whatever the '
                                  'range')


def test_a_sweep_places_its_next_drops_where_they_narrow_n_star_most():
    """Looks as the scheduler makes them, on rows drawn from a known curve (n* = 50; 20 %
    lower 20 parts away, so that it is no flat top, and noisy): the placed batches settle n* with
    fewer parts dropped than a batch at every count, never drop more at a look, and never ask
    for a count that has no iterations left."""
    file = unread(small(mode='adaptive', batch=5))
    exp = replace(file.experiment('sweep'), counts=tuple(range(10, 101, 10)), margin=5,
                  iterations=40)
    drawn = {c: 8 - (c - 50) ** 2 / 250 + np.random.default_rng(c).normal(0, 3, 40)
             for c in exp.counts}

    def sweep(everywhere: bool) -> tuple[int, int]:
        taken = dict.fromkeys(exp.counts, 5)
        while True:
            rows = [row(c, i, valid=drawn[c][i]) for c in exp.counts for i in range(taken[c])]
            wanted = sampling.unsettled(file, exp, rows)
            if not wanted:
                return metrics.table_sweep(file, exp, rows).n_star, sum(
                    c * k for c, k in taken.items())
            if everywhere:
                wanted = [c for c in exp.counts if taken[c] < 40]
            assert all(taken[c] < 40 for c in wanted)
            assert sum(wanted) * 5 <= 5 * sum(exp.counts)
            for c in wanted:
                taken[c] = min(40, taken[c] + 5)

    placed, uniform = sweep(everywhere=False), sweep(everywhere=True)
    assert abs(placed[0] - 50) <= 2 and abs(uniform[0] - 50) <= 2
    assert placed[1] < uniform[1]


def test_a_gripper_sweep_is_settled_by_the_smallest_gripper_s_decision():
    file = small()
    exp = replace(file.experiment('grippers'), min_valid=2.0)   # 8 variants, 0 the smallest

    def checks(per_variant, n=8):
        return [{'group': 0, 'iteration': i, 'check': k, 'valid': v}
                for k, v in enumerate(per_variant) for i in range(n)]

    rows = [row(0, i) for i in range(8)]
    # The smallest meets clearly: the rest do not matter.
    assert sampling.unsettled(file, exp, rows, checks([30] + [0] * 7)) == []
    # The smallest is near min_valid: not settled, whatever the others give.
    assert sampling.unsettled(file, exp, rows, checks([2] + [30] * 7)) == [0]
    # None meets, each clearly.
    assert sampling.unsettled(file, exp, rows, checks([0] * 8)) == []


def read(directory: str) -> list[dict]:
    return read_text_rows(os.path.join(directory, 'iterations.csv'), drop=('wall_time',))


# Feeder runs allowed one vibration cannot empty the feeder; with a refill interval of 3.6 ms
# (`run`'s default) each is over it when the limit ends it, so each counts against the table.
HOPELESS = ('id: stop_early\nseed: 3\npart: {model: radial_capacitor}\n'
            'gripper: {body_diameter_mm: 8, jaw_depth_mm: 3}\n'
            'experiments:\n'
            '  - {id: feeder, type: feeder_emptying, iterations: 6, parts: 12, '
            'optimal_range: [4, 8], max_vibrations: 1}\n')


def run(mode: str, directory: str, writer=ResultsWriter, resume: bool = False,
        progress=None, required: float = 0.9, interval_h: float = 1e-6) -> Summary:
    file = experiment_file.parse(HOPELESS + f'sampling: {{mode: {mode}, batch: 2}}\n'
                        f'requirements: {{success_rate: {required}, '
                        f'refill_interval_h: {interval_h:f}}}\n', SMALL)
    with LocalBackend() as backend, writer(directory, file.text, resume) as sink:
        return Runner(file, [backend], sink, progress).run()


def test_an_adaptive_run_stops_a_feeder_study_that_settled_and_keeps_the_fixed_counts_seeds(
        tmp_path):
    """0 of 4 settles the verdict (NOT FEASIBLE), so 4 of the 6 iterations run, in two
    batches; they are the fixed run's first four, row for row."""
    shown = []
    runs = {mode: (run(mode, str(tmp_path / mode), progress=shown.append),
                   read(str(tmp_path / mode))) for mode in ('fixed', 'adaptive')}
    summary, rows = runs['adaptive']
    # the progress line ends full: the iterations not needed leave its total
    assert (shown[-1].done, shown[-1].total, shown[-1].eta) == (4, 4, 0)
    s = summary.experiments['feeder']
    assert s.sampling == Sampling(mode='adaptive', batch=2, batches=2, iterations_run=4, most=6,
                                  settled=True)
    assert s.iterations == 4 and s.accepted == 0
    assert rows == runs['fixed'][1][:4]
    assert runs['fixed'][0].experiments['feeder'].sampling is None
    assert verdicts(summary)[1].verdict == NOT_FEASIBLE
    assert rate_interval(0, 4)[1] < 0.9
    # The terminal and the report say how many iterations ran and why they stopped.
    assert '[adaptive: 4 of 6 iterations, settled]' in headlines(summary)[0]
    assert '| `feeder` | 4 | 6 | 2 | settled |' in report.markdown(Run(summary))
    assert '## Sampling' not in report.markdown(Run(runs['fixed'][0]))


def test_runs_the_vibration_limit_ended_early_stop_once_feasible_is_out_of_reach(tmp_path):
    """The same hopeless runs against a 4 h refill interval: the limit ends each well inside
    it (under a minute), so none says whether a refill empties within it (censored). Two of
    them keep the table from FEASIBLE at any of the 6 iterations (2 of 6 counted over: at most
    73 % at 95 %, against 10 % allowed), and their pace (15 picks in 1.1 min of cell time) from
    NOT FEASIBLE: the run stops after its first batch, its time ground UNDECIDED, and says
    why."""
    summary = run('adaptive', str(tmp_path / 'limited'), interval_h=4.0)
    s = summary.experiments['feeder']
    assert (s.iterations, s.sampling.settled) == (2, True)
    time = s.decision.time
    assert (time.verdict, time.over, time.censored) == (UNDECIDED, 0, 2)
    assert 'not counted: 2 run(s) stopped at the vibration limit' in time.reason
    # the option's verdict rests on its grounds (here also the 12 parts loaded, fewer than a
    # refill): the time ground says what would settle it
    reasons = ' '.join(verdicts(summary)[1].reasons)
    assert 'runs at this vibration limit cannot settle it' in reasons


def test_an_interrupted_adaptive_run_resumes_to_the_same_batches_and_results(tmp_path):
    class Interrupt(Exception):
        pass

    class StopAtTheThird(ResultsWriter):
        def write(self, record):
            if record.iteration['iteration'] == 2:      # the second batch's first
                raise Interrupt
            super().write(record)

    whole = run('adaptive', str(tmp_path / 'whole'))
    out = str(tmp_path / 'cut')
    with pytest.raises(Interrupt):
        run('adaptive', out, StopAtTheThird)
    assert len(read(out)) == 2
    assert run('adaptive', out, resume=True) == whole
    assert read(out) == read(str(tmp_path / 'whole'))


def test_a_resumed_adaptive_run_looks_only_at_the_batches_it_released(tmp_path):
    """At a 95 % requirement, 0 of 2 runs does not settle the verdict and 0 of 3 does. A run
    cut after the second batch's first iteration has written 3 rows; resumed, its first look
    must see the first batch's 2, as the uncut run's did, and not stop at 3."""
    class Interrupt(Exception):
        pass

    class StopAtTheFourth(ResultsWriter):
        def write(self, record):
            if record.iteration['iteration'] == 3:
                raise Interrupt
            super().write(record)

    assert not sampling.rate_settled(0, 2, 0.95) and sampling.rate_settled(0, 3, 0.95)
    whole = run('adaptive', str(tmp_path / 'whole'), required=0.95)
    assert whole.experiments['feeder'].iterations == 4
    out = str(tmp_path / 'cut')
    with pytest.raises(Interrupt):
        run('adaptive', out, StopAtTheFourth, required=0.95)
    assert len(read(out)) == 3
    assert run('adaptive', out, resume=True, required=0.95) == whole
    assert read(out) == read(str(tmp_path / 'whole'))


def test_an_adaptive_race_that_runs_out_names_the_bins_it_could_not_tell_apart(tmp_path):
    """Two drops per bin cannot part two bins at the race's 99.95 %: the race ends at the most
    iterations with both still in it, and the summary, the terminal and the report say which."""
    text = open(SMALL).read()
    bins = next(line for line in text.splitlines() if '{id: bins' in line)
    file = experiment_file.parse(text.split('experiments:\n')[0] + f'experiments:\n{bins}\n'
                        'sampling: {mode: adaptive, batch: 2}\n', SMALL)
    assert [e.id for e in file.experiments] == ['bins']
    with LocalBackend() as backend, ResultsWriter(str(tmp_path), file.text) as sink:
        summary = Runner(file, [backend], sink).run()
    s = summary.experiments['bins']
    assert s.sampling.settled is False and s.sampling.tied_bins == [0, 1]
    said = 'not settled: bins 100 x 100 x 20 and 120 x 80 x 20 mm could not be told apart'
    assert said in headlines(summary)[0]
    assert f'at the most iterations, {said}' in report.markdown(Run(summary))


def test_a_tie_is_said_with_its_bins():
    bins = [SimpleNamespace(index=i, size_mm=size) for i, size in enumerate(
        ([100, 100, 20], [120, 80, 20], [75, 75, 40]))]
    said = Sampling(mode='adaptive', batch=2, batches=3, iterations_run=6, most=40,
                    settled=True, tie=[1, 0], tie_within=0.05,
                    race_confidence=sampling.RACE_CONFIDENCE)
    experiment = SimpleNamespace(bins=bins, sampling=said)
    assert sampling_end(experiment) == ('settled: bins 120 x 80 x 20 and 100 x 100 x 20 mm tie '
                                        'within 5.0 % of the first, which has the highest mean '
                                        '(one-sided 99.95 % bounds of the differences)')
    # a version-0 summary has no race_confidence: its race compared intervals
    experiment.sampling = said.model_copy(update={'race_confidence': None})
    assert sampling_end(experiment).endswith('(99.9 % intervals)')
    experiment.sampling = said.model_copy(update={'tie': None})
    assert sampling_end(experiment) == 'settled'
