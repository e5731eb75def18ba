"""The four experiment types on the real cores (LocalBackend: PyBullet, FCL, the feeder
policy), the results files they leave, resumption, and the metrics."""

from dataclasses import replace
import json
import math
import os
import re
import threading
import time

from experiment_manager import experiment_file
from experiment_manager.analysis import metrics
from experiment_manager.analysis.headlines import headlines
from experiment_manager.analysis.records import Faults, Flagged
from experiment_manager.analysis.redecide import redecide
from experiment_manager.analysis.results import read_text_rows, ResultsWriter
from experiment_manager.analysis.rows import FILES, POSE
from experiment_manager.analysis.summary import validate
from experiment_manager.experiment_file import resolved
from experiment_manager.experiment_file.plan import iteration_seed, plan, Unit
from experiment_manager.running.backend import WorkerLost
from experiment_manager.running.local_backend import LocalBackend
from experiment_manager.running.procedures import faults, Iteration, run_unit, search_order
from experiment_manager.running.scheduler import Runner
from feeder_controller.policy import NAMES
import numpy as np
from pick_common.errors import InvalidArgument
from pick_common.states import PartStates
from pick_common.stats import interval, stats
from pick_sim_world.stepping import speed_limit
from pick_validity.results import STAGE_VALID
import pytest
from scipy import stats as scipy_stats

SMALL = os.path.join(os.path.dirname(__file__), 'small_experiment.yaml')


def read(directory: str, name: str) -> list[dict]:
    return read_text_rows(os.path.join(directory, f'{name}.csv'), drop=('wall_time',))


def test_every_type_records_its_rows_and_metrics(small):
    directory, summary = small
    rows = read(directory, 'iterations')
    by_type = {t: [r for r in rows if r['type'] == t] for t in experiment_file.TYPES}
    assert [len(by_type[t]) for t in experiment_file.TYPES] == [4, 1, 8, 1, 2, 0, 0]
    for r in rows:
        n = [int(r[k]) for k in ('checked', 'candidates', 'placeable', 'container_free')]
        assert n == sorted(n, reverse=True), r      # each stage passes a subset of the last
        assert r['settled'] == 'True' and int(r['spilled']) == int(r['tunnelled']) == 0
        # At the default step piles overlap up to about 1 mm (docs/physics.md, "Convergence":
        # 0.9-1.0 mm deepest in the benchmark's piles; 2.8 mm at the former solver settings).
        assert float(r['max_penetration']) < 0.002
    s = summary.experiments
    assert s['bins'].best_bin in (0, 1)
    best = s['bins'].bins[s['bins'].best_bin]
    assert best.fractions.container_free.mean == max(
        b.fractions.container_free.mean for b in s['bins'].bins)
    assert s['emptying'].bin_mm == best.size_mm
    # bin_emptying: one pick per check but the last, each the first valid in search order.
    picks = [p for p in read(directory, 'picks') if p['experiment'] == 'emptying']
    checks = [c for c in read(directory, 'checks') if c['experiment'] == 'emptying']
    assert len(picks) == int(by_type['bin_emptying'][0]['picks']) == len(checks) - 1 + (
        by_type['bin_emptying'][0]['stop'] == 'empty')
    parts = read(directory, 'parts')
    for p in picks:
        stages = {r['part_id']: int(r['stage']) for r in parts
                  if r['experiment'] == 'emptying' and r['check'] == p['check']}
        assert stages[p['part_id']] == 5 and int(p['searches']) >= 1
        assert np.isfinite([float(p[k]) for k in p if k.startswith('gripper_')]).all()
    # table_sweep: the fit's optimum lies in the tested range, the range is n* +- margin.
    sweep = s['sweep']
    assert [x.n for x in sweep.per_n] == [2, 6, 10, 14]
    assert 2 <= sweep.n_star <= 14 and sweep.order == 3
    assert sweep.optimal_range == [max(1, sweep.n_star - 2), sweep.n_star + 2]
    low, high = sweep.n_star_ci95        # two iterations a count: a bootstrap interval
    assert 2 <= low <= sweep.n_star <= high <= 14
    assert (f'  sweep (table_sweep): optimum {sweep.n_star} parts (95 % interval {low}-'
            f'{high}), range {sweep.optimal_range}') in headlines(summary)
    # feeder_emptying: the range came from the sweep; the run stopped by the policy.
    feeder = by_type['feeder_emptying'][0]
    assert s['feeder'].optimal_range == sweep.optimal_range
    assert feeder['stop'] in NAMES and int(feeder['vibrations']) <= 15
    assert int(feeder['picks']) + int(feeder['spilled']) <= 12
    assert 0 < float(feeder['tray_error']) < 0.05    # the tray moved as commanded
    # The table's time: each vibration lasts its move's duration and then settles, the first
    # feed streams its parts in; no other type has one.
    file = experiment_file.load(SMALL)
    shaking = int(feeder['vibrations']) * sum(m.duration for m in file.moves)
    assert shaking < float(feeder['table_time']) < shaking + 10.0 * (int(feeder['vibrations'])
                                                                      + int(feeder['feeds']))
    assert {float(r['table_time']) for r in rows if r['type'] != 'feeder_emptying'} == {0.0}
    hourly = 3600.0 * int(feeder['picks']) / (int(feeder['picks']) * file.cell.pick_time
                                              + float(feeder['table_time']))
    assert s['feeder'].parts_per_hour.mean == pytest.approx(hourly)
    with open(os.path.join(directory, 'summary.json')) as f:
        assert validate(json.load(f)) == summary


def test_a_gripper_sweep_checks_every_gripper_on_the_same_scenes(small):
    directory, summary = small
    exp = experiment_file.load(SMALL).experiment('grippers')
    checks = [c for c in read(directory, 'checks') if c['experiment'] == 'grippers']
    assert [(int(c['iteration']), int(c['check'])) for c in checks] == [
        (i, k) for i in range(2) for k in range(len(exp.variants))]
    valid: dict[tuple[int, int], set] = {}
    poses: dict[tuple[int, int], set] = {}
    for p in read(directory, 'parts'):
        if p['experiment'] == 'grippers':
            key = int(p['iteration']), int(p['check'])
            valid.setdefault(key, set())
            if int(p['stage']) == STAGE_VALID:
                valid[key].add(p['part_id'])
            poses.setdefault((key[0], p['part_id']), set()).add(tuple(p[k] for k in POSE))
    assert all(len(seen) == 1 for seen in poses.values())    # one scene for every gripper
    # Shapes nest: a gripper no wider (D) and no deeper (W) than another, with the same or
    # more grasps, reaches every part the other reaches.
    size = ('body_diameter', 'jaw_depth')
    pairs = 0
    for a, va in enumerate(exp.variants):
        for b, vb in enumerate(exp.variants):
            if a != b and set(va.grasps) >= set(vb.grasps) and all(
                    getattr(va.gripper, k) <= getattr(vb.gripper, k) for k in size):
                pairs += 1
                for i in range(2):
                    assert valid[i, a] >= valid[i, b], (i, va, vb)
    assert pairs == 19      # of the 8 x 7 ordered pairs
    # ... and the sweep tells them apart: the narrow gripper reaches more than the wide one.
    s = summary.experiments['grippers']
    means = [v.valid.mean for v in s.variants]
    assert means == [sum(len(valid[i, k]) for i in range(2)) / 2 for k in range(8)]
    assert means[0] > means[6]      # D 8 W 3 against D 20 W 6, every grasp
    assert [v.gripper_mm['body_diameter_mm'] for v in s.variants] == [8] * 4 + [20] * 4
    assert [v.grasp_set for v in s.variants] == ['all', 'upright'] * 4


def test_the_smallest_gripper_meeting_the_yield_is_chosen_by_size_then_order():
    file = experiment_file.parse(open(SMALL).read())
    exp = file.experiment('grippers')      # D 8 / 20 x W 3 / 6 x {all, upright}
    # Per scene (iteration), the valid parts of each variant; 8 scenes.
    per_variant = {0: [9] * 8, 1: [0, 1] * 4, 2: [4] * 8, 3: [16] * 8, 4: [25] * 8,
                   5: [0] * 8, 6: [1, 1, 1, 2] * 2, 7: [0] * 8}

    def summary(min_valid):
        e = replace(exp, min_valid=min_valid)
        healthy = dict.fromkeys(('spilled', 'tunnelled', 'thrown', 'max_speed', 'unsettled',
                                 'max_penetration', 'tray_error'), 0)
        iterations = [{'group': 0, 'iteration': i, 'container_x': 0.195, 'container_y': 0.15,
                       'container_z': 0.027, 'fault': '', **healthy} for i in range(8)]
        checks = [{'group': 0, 'iteration': i, 'check': k, 'checked': 30, 'candidates': 30,
                   'placeable': 30, 'container_free': 30, 'valid': v[i]}
                  for k, v in per_variant.items() for i in range(8)]
        return metrics.gripper_sweep(e, iterations, checks)

    s = summary(2.0)
    # Counts spread at least as a Poisson count's: 8 scenes of 4 valid parts give 4 +- t *
    # sqrt(4 / 8), not 4 +- 0.
    t = scipy_stats.t.ppf(0.975, 7)
    assert s.variants[2].valid_ci95 == pytest.approx([4 - t * 0.5 ** 0.5, 4 + t * 0.5 ** 0.5])
    assert [v.meets for v in s.variants] == [True, False, True, True, True, False, False,
                                             False]
    # D 8 W 3 'all' (0) and D 8 W 6 'all' (2) both meet; W 3 is smaller.
    assert s.smallest == 0 and s.scene_mm == [195, 150, 27]
    low, high = s.variants[6].valid_ci95
    assert low < 1.25 < high and s.variants[1].scenes_with_valid == 4
    assert summary(10.0).smallest == 3       # D 8 W 6 upright (16) before D 20 W 3 (25)
    assert summary(30.0).smallest is None
    # An interval reaching below 0 does not meet even min_valid 0.
    assert not summary(0.0).variants[1].meets
    assert interval([4.0]) == (None, None)
    assert interval([4.0, 4.0]) == (4.0, 4.0)


def test_runs_are_deterministic_and_independent_of_order(small, tmp_path):
    directory, _ = small
    file = experiment_file.load(SMALL)
    summary: dict = {}
    units = []
    with open(os.path.join(directory, 'summary.json')) as f:
        written = validate(json.load(f))
    for exp in file.experiments:   # planned as the run plans them, then run backwards
        units += plan(file, exp, summary)
        summary[exp.id] = written.experiments[exp.id]
    records = {}
    with LocalBackend() as backend:
        backend.start(file)
        for u in reversed(units):
            records[u.key] = run_unit(file, u, backend)
    rows = read(directory, 'iterations')
    for row in rows:
        again = records[(row['experiment'], int(row['group']), int(row['iteration']))]
        assert {k: str(v) for k, v in again.iteration.items() if k != 'wall_time'} == row


def test_an_interrupted_run_resumes_to_the_same_results(small, run_file, tmp_path):
    directory, summary = small
    file = experiment_file.load(SMALL)

    class Interrupt(Exception):
        pass

    class StopAfter(ResultsWriter):
        def write(self, record):
            if record.iteration['experiment'] == 'sweep' and record.iteration['group'] == 6:
                # some of the iteration's rows are written, then the run dies mid-row: the
                # torn row's key reads as a finished iteration's
                self._writers['parts'].writerows(record.parts[:3])
                self._files['parts'].write('sweep,0,0,0,')
                self._files['parts'].flush()
                raise Interrupt
            super().write(record)

    out = str(tmp_path / 'run')
    with LocalBackend() as backend, StopAfter(out, file.text) as writer:
        with pytest.raises(Interrupt):
            Runner(file, [backend], writer).run()
    assert len(read(out, 'iterations')) == 7        # every finished iteration is on disk
    with pytest.raises(InvalidArgument, match='already holds results'):
        ResultsWriter(out, file.text)
    with pytest.raises(InvalidArgument, match='differs from the file of the run'):
        ResultsWriter(out, file.text + '# edited\n', resume=True)
    assert run_file(out, resume=True) == summary
    for name in FILES:
        assert read(out, name) == read(directory, name), name


class Worker(LocalBackend):
    """A worker in this process whose resets are slowed by `delay` s, that dies at its
    reset number `dies_at` (after the delay), and whose physics turns NaN in the drop after
    its reset number `nan_at` (a NaN velocity given to PyBullet, which then steps to NaN)."""

    def __init__(self, delay: float = 0.0, dies_at: int = 0, missing: bool = False,
                 nan_at: int = 0, back_after: float | None = None) -> None:
        super().__init__()
        self.delay, self.dies_at, self.resets, self.missing = delay, dies_at, 0, missing
        self.nan_at, self.back_after = nan_at, back_after

    def rejoin(self, stop) -> bool:
        """Back after `back_after` s (its nodes restarted), unless the run is over first."""
        if self.back_after is None:
            return False
        deadline = time.monotonic() + self.back_after
        while time.monotonic() < deadline:
            if stop():
                return False
            time.sleep(0.01)
        return True

    def drop(self, count, zone):
        if self.resets != self.nan_at:
            return super().drop(count, zone)
        world = self._world
        ids, _ = world.drop(count, zone=zone)
        world.engine.set_velocity(world.body(ids[0]), [math.nan, 0, 0])
        return world.snapshot(), world.settle()

    def start(self, file) -> None:
        if self.missing:
            raise WorkerLost('the worker is not there')
        super().start(file)

    def reset(self, container, seed) -> None:
        self.resets += 1
        time.sleep(self.delay)
        if self.resets == self.dies_at:
            raise WorkerLost(f'the worker died at its reset {self.resets}')
        super().reset(container, seed)


class Writer(ResultsWriter):
    """Keeps the order in which iterations were written."""

    def write(self, record) -> None:
        self.written = getattr(self, 'written', [])
        self.written.append([str(record.iteration[k]) for k in ('experiment', 'group',
                                                                'iteration')])
        super().write(record)


def run_on(workers: list, directory: str, started: list | None = None
           ) -> tuple[Runner, dict, list]:
    """Run the small file on `workers`; `started` collects the experiment of each iteration
    in the order the workers took them."""
    file = experiment_file.load(SMALL)
    try:
        with Writer(directory, file.text) as writer:
            runner = Runner(file, workers, writer, lambda p: started is not None and ': ' in
                            p.phase and started.append(p.phase.split(':')[0]))
            return runner, runner.run(), writer.written
    finally:
        for w in workers:
            w.close()


def test_two_workers_give_the_results_of_one_whatever_order_they_finish_in(small, tmp_path):
    directory, summary = small
    # The first worker is slowed: iterations finish out of plan order, and the files are put
    # back in plan order as each experiment finishes.
    workers = [Worker(delay=0.3), Worker()]
    started: list[str] = []
    runner, got, written = run_on(workers, str(tmp_path / 'two'), started)
    assert got == summary and runner.lost_workers == []
    # both took work (how much each took depends on the machine's load: not asserted)
    assert workers[0].resets >= 1 and workers[1].resets >= 1
    planned = [[r['experiment'], r['group'], r['iteration']] for r in read(directory,
                                                                           'iterations')]
    assert written != planned and sorted(written) == sorted(planned)
    # The sweep needs no earlier metrics: a worker took it while the other finished the bins,
    # before the emptying (which needs the best bin) was planned. Asserted on the order the
    # iterations were taken (under the runner's lock), not the order they finished in, which
    # depends on thread scheduling (it failed on a loaded machine).
    assert started.index('sweep') < started.index('emptying')
    for name in FILES:
        assert read(str(tmp_path / 'two'), name) == read(directory, name), name


@pytest.mark.parametrize('lost', [
    Worker(dies_at=3),                 # while the other is busy
    Worker(delay=2.0, dies_at=1),      # late: the other has run out of work and must wait
    Worker(missing=True),              # missing at the start: left out
], ids=['busy', 'idle', 'missing'])
def test_a_lost_worker_s_iteration_runs_again_on_another(small, tmp_path, lost):
    directory, summary = small
    runner, got, _ = run_on([lost, Worker()], str(tmp_path / 'lost'))
    assert runner.lost_workers == [0] and lost.resets == lost.dies_at
    assert got == summary
    for name in FILES:
        assert read(str(tmp_path / 'lost'), name) == read(directory, name), name


@pytest.mark.parametrize('others', [0, 1], ids=['alone', 'beside another'])
def test_a_lost_worker_that_comes_back_gets_iterations_again(small, tmp_path, others):
    directory, summary = small
    back = Worker(delay=0.05, dies_at=2, back_after=0.3)
    runner, got, _ = run_on([back] + [Worker(delay=0.05) for _ in range(others)],
                            str(tmp_path / 'back'))
    assert runner.rejoined == [0] and runner.lost_workers == []
    assert back.resets > 2, 'it ran iterations after coming back'
    assert got == summary
    for name in FILES:
        assert read(str(tmp_path / 'back'), name) == read(directory, name), name


def test_the_run_fails_when_every_worker_is_lost_and_keeps_what_finished(tmp_path):
    workers = [Worker(dies_at=2), Worker(dies_at=3)]
    with pytest.raises(WorkerLost, match='died at its reset'):
        run_on(workers, str(tmp_path / 'none'))
    assert len(read(str(tmp_path / 'none'), 'iterations')) == 3
    assert threading.active_count() == 1, 'a worker thread outlived the run'
    with pytest.raises(WorkerLost, match='not there'):
        run_on([Worker(missing=True), Worker(missing=True)], str(tmp_path / 'absent'))


def test_a_physics_fault_is_marked_left_out_of_the_figures_and_the_run_goes_on(small,
                                                                                 tmp_path):
    directory, summary = small
    _, got, _ = run_on([Worker(nan_at=2)], str(tmp_path / 'nan'))
    rows = read(str(tmp_path / 'nan'), 'iterations')
    expected = read(directory, 'iterations')
    assert len(rows) == len(expected) == 16
    faulted = rows.pop(1)
    assert faulted['fault'] == 'physics_fault' and faulted['checks'] == '0'
    assert re.match(r'physics_fault: parts \[0\b.*\] got non-finite poses', faulted['stop'])
    # the faulted experiment's other iterations are untouched by the fault (an experiment
    # that takes its bin from it may take another: the faulted iteration is left out)
    assert [r for r in rows if r['experiment'] == 'bins'] == [
        r for r in expected[:1] + expected[2:] if r['experiment'] == 'bins']
    bins = got.experiments['bins']
    assert bins.faults.physics_fault == 1
    assert bins.faults.flagged == [Flagged(group=0, iteration=1, fault='physics_fault')]
    assert [b.iterations for b in bins.bins] == [1, 2]
    assert summary.experiments['bins'].faults == Faults(
        physics_fault=0, tunnelled=0, thrown=0, unsettled=0, flagged=[])


def test_parts_fallen_far_from_the_container_are_not_sent_to_the_check():
    """Found by the reduced test case: an escaped part had fallen to z = -80 m, beyond what
    check_parts accepts (10 m); the run failed."""
    file = experiment_file.load(SMALL)
    exp = file.experiment('emptying')
    container = file.experiment('bins').bins[0]
    u = Unit(exp, 0, 0, 5, container, 20)
    with LocalBackend() as backend:
        backend.start(file)
        backend.reset(container, u.seed)
        states, _ = backend.drop(20, 'container')
        world = backend._world
        world.engine.set_pose(world.body(int(states.ids[0])), [0, 0, -80.0])
        states = backend.parts()
        iteration = Iteration(file, u, backend)
        report, _ = iteration.check(states, True)
        record = iteration.record
    assert report.counts['checked'] == 19 and not states.inside[0]
    assert [p['part_id'] for p in record.parts] == states.ids.tolist()   # recorded, all 20


def test_tunnelled_thrown_and_unsettled_iterations_are_flagged_and_a_spill_is_not_a_fault():
    row = {'stop': 'empty', 'settled': True, 'spilled': 0, 'tunnelled': 0, 'thrown': 0}
    assert faults(row) == ''
    assert faults({**row, 'spilled': 3}) == ''
    assert faults({**row, 'settled': False}) == 'unsettled'
    assert faults({**row, 'settled': False, 'tunnelled': 2}) == 'tunnelled+unsettled'
    assert faults({**row, 'thrown': 1}) == 'thrown'
    counts = metrics.fault_counts([{'group': 0, 'iteration': i, 'fault': f} for i, f in
                                   enumerate(['', 'tunnelled+unsettled', 'tunnelled'])])
    assert (counts.unsettled, counts.tunnelled, len(counts.flagged)) == (1, 2, 2)


def test_the_health_of_an_iteration_counts_spilled_tunnelled_and_thrown_parts_apart():
    """Through the feeder procedure: a part pushed over the wall spills, one pushed under the
    floor tunnels, one launched at 4 m/s (what a solver blow-up does: 3.6 m/s was seen) is
    thrown, not spilled, although it flies out; the tunnelled iteration is left out of the
    figures, the spill is counted."""
    file = experiment_file.load(SMALL)
    exp = file.experiment('feeder')
    u = Unit(exp, 0, 0, 5, file.tray, exp.parts)
    with LocalBackend() as backend:
        backend.start(file)
        backend.reset(file.tray, u.seed)
        iteration = Iteration(file, u, backend)
        states, settle = backend.drop(8, 'feeder')
        world = backend._world
        x = file.tray.inner_size[0]
        for pid, where in zip(states.ids[:2].tolist(), ([x, 0.0, 0.05], [0.0, 0.0, -0.05]),
                              strict=True):
            world.engine.set_pose(world.body(pid), where)
        thrown = int(states.ids[2])
        world.engine.set_velocity(world.body(thrown), [0.0, 0.0, 4.0])
        report = world.settle(max_settle_time=0.3)
        iteration.reports += [settle, report]
        health = iteration.health()
    limit = speed_limit(file.tray, world.part)
    assert report.thrown_ids == [thrown] and thrown in report.escaped_ids
    assert report.max_speed > limit
    assert (health['spilled'], health['tunnelled'], health['thrown']) == (1, 1, 1)
    assert {'tunnelled', 'thrown'} <= set(faults({**health, 'stop': ''}).split('+'))
    rows = [{'group': 0, 'iteration': 0, **health, 'fault': faults({**health, 'stop': ''}),
             'emptied': True, 'vibrations': 5, 'feeds': 1, 'stop': 'stop: empty',
             'picks': 5, 'checks': 10, 'table_time': 9.0},
            {'group': 0, 'iteration': 1, **health, 'tunnelled': 0, 'thrown': 0, 'fault': '',
             'emptied': True, 'vibrations': 7, 'feeds': 1, 'stop': 'stop: empty',
             'picks': 7, 'checks': 14, 'table_time': 20.0}]
    s = metrics.summarise(file, replace(exp, optimal_range=(2, 4)), rows, [])
    assert s.faults.tunnelled == 1 and s.iterations == 1    # left out
    assert s.physics.spilled == 2 and s.accepted == 0       # counted, not accepted
    # the kept run's throughput: 7 picks of 4 s and 20 s of the table's, no image time
    assert s.parts_per_hour.mean == pytest.approx(3600 * 7 / (7 * 4 + 20))


def test_an_unwritable_output_directory_is_named(tmp_path):
    blocker = tmp_path / 'file'
    blocker.write_text('')
    with pytest.raises(InvalidArgument, match=r"output_dir: '.*file/run' cannot be written"):
        ResultsWriter(str(blocker / 'run'), 'x')
    with pytest.raises(InvalidArgument, match='holds no run to resume'):
        ResultsWriter(str(tmp_path / 'empty'), 'x', resume=True)


def test_a_results_file_cut_before_its_header_ends_gets_its_header_back_on_resume(tmp_path):
    with ResultsWriter(str(tmp_path), 'x'):
        pass
    (tmp_path / 'parts.csv').write_text('experiment,gr')    # killed while writing the header
    (tmp_path / 'picks.csv').write_text('')
    with ResultsWriter(str(tmp_path), 'x', resume=True):
        pass
    for name in ('parts', 'picks'):
        assert (tmp_path / f'{name}.csv').read_text().splitlines() == [','.join(FILES[name])]


def test_a_run_written_by_another_version_is_not_resumed_into_misaligned_rows(tmp_path):
    with ResultsWriter(str(tmp_path), 'x'):
        pass
    old = [c for c in FILES['iterations'] if c not in ('thrown', 'max_speed')]
    (tmp_path / 'iterations.csv').write_text(','.join(old) + '\n')   # before 'thrown'
    with pytest.raises(InvalidArgument, match=r'iterations.csv.* has the columns of another '
                       r'version \(missing: thrown, max_speed; unknown: none\)'):
        ResultsWriter(str(tmp_path), 'x', resume=True)


def test_iteration_seeds_differ_per_key_and_do_not_change():
    seeds = {iteration_seed(7, e, (g, i)) for e in ('a', 'b') for g in range(3)
             for i in range(3)}
    assert len(seeds) == 18 and all(0 <= s < 2**63 for s in seeds)
    assert iteration_seed(7, 'a', (0, 0)) == iteration_seed(7, 'a', (0, 0))
    assert iteration_seed(7, 'a', (0, 0)) != iteration_seed(8, 'a', (0, 0))


def test_search_orders():
    poses = np.zeros((4, 7))
    poses[:, 2] = [0.01, 0.03, 0.02, 0.03]
    states = PartStates(np.array([5, 6, 7, 8]), np.zeros(4, int), poses, np.ones(4, bool), 0.0)
    targets = np.array([5, 6, 7, 8])
    assert search_order('top_first', states, targets, 0).tolist() == [6, 8, 7, 5]
    assert search_order('id', states, targets[::-1], 0).tolist() == [5, 6, 7, 8]
    shuffled = search_order('random', states, targets, 3).tolist()
    assert sorted(shuffled) == [5, 6, 7, 8]
    assert shuffled == search_order('random', states, targets, 3).tolist()


def test_the_fit_finds_the_maximum_of_a_known_curve():
    n = np.repeat(np.arange(1, 61), 3)
    valid = 20.0 - 0.02 * (n - 37.0) ** 2 + 1e-6 * (n - 37.0) ** 4
    fit = metrics.fit_optimum(n, valid, 1, 60, 5)
    assert fit.order == 4 and fit.n_star == 37 and fit.optimal_range == [32, 42]
    assert metrics.fit_optimum([4, 4], [1, 3], 4, 4, 5).optimal_range == [1, 9]
    # Every count weighs the same, however many iterations it had (an adaptive sweep's).
    uneven = metrics.fit_optimum([1, 1, 1, 1, 2, 3], [0, 0, 0, 4, 3, 1], 1, 3, 1)
    assert np.allclose(uneven.coefficients, np.polyfit([1, 2, 3], [1, 3, 1], 2))
    assert stats([1, 2, 3]) == {'n': 3, 'mean': 2.0, 'min': 1.0, 'max': 3.0,
                                        'std': 1.0}
    assert stats([])['mean'] is None


def test_the_interval_of_n_star_is_the_row_fits_bootstrap_and_narrows_with_the_draws():
    counts = np.arange(5, 101, 5)
    rng = np.random.default_rng(3)

    def draws(noise, m):
        return [20.0 - 0.01 * (n - 60.0) ** 2 + rng.normal(0.0, noise, m) for n in counts]

    by_count = draws(2.0, 6)
    low, high = metrics.n_star_interval(counts, by_count, 4, 5, 100, 0.95,
                                        np.random.default_rng(7))
    # The same resamples fitted row by row give the same n*s: with as many iterations at
    # every count, the fit to the counts' means is the fit to every iteration.
    same = np.random.default_rng(7)
    widened = [v.mean() + (v - v.mean()) * np.sqrt(6 / 5) for v in by_count]
    rows = np.concatenate([v[same.integers(0, len(v), (len(v), metrics.BOOTSTRAP))]
                           for v in widened])
    _, stars = metrics.fit(np.repeat(counts, 6).astype(float), rows, 4, 5, 100)
    assert (low, high) == (np.quantile(stars, 0.025, method='lower'),
                           np.quantile(stars, 0.975, method='higher'))
    assert low <= 60 <= high
    many = draws(2.0, 60)
    tight = metrics.n_star_interval(counts, many, 4, 5, 100, 0.95, np.random.default_rng(7))
    assert tight[0] <= 60 <= tight[1] and tight[1] - tight[0] < high - low
    wide = metrics.n_star_interval(counts, many, 4, 5, 100, 0.999, np.random.default_rng(7))
    assert wide[0] <= tight[0] and tight[1] <= wide[1]
    # a count with one iteration says nothing of its spread
    assert metrics.n_star_interval(counts, [v[:1] for v in by_count], 4, 5, 100, 0.95,
                                   np.random.default_rng(7)) is None


def test_the_bootstrap_gives_a_mean_of_few_iterations_its_whole_variance():
    """Two iterations, 0 and 1: their mean's variance is s^2 / m = 0.5 / 2; resampling the two
    as they are gives half of it."""
    means = metrics.resampled_means([[0.0, 1.0], [2.0, 2.0]], np.random.default_rng(1))
    assert means.shape == (2, metrics.BOOTSTRAP)
    assert means[0].var() == pytest.approx(0.25, rel=0.05)
    assert means[0].mean() == pytest.approx(0.5, abs=0.02)
    assert (means[1] == 2.0).all()


EXTENDING = """id: ext
seed: 4
part: {model: radial_capacitor}
gripper: {body_diameter_mm: 8, jaw_depth_mm: 3}
tray_mm: [60, 50, 27]
experiments:
  - {id: sweep, type: table_sweep, iterations: 1, counts: {first: 1, last: 3, step: 1},
     margin: 1}
"""


@pytest.mark.parametrize('mode', ['fixed', 'adaptive'])
def test_a_sweep_still_rising_at_its_last_count_sweeps_on_until_its_peak_is_inside(tmp_path,
                                                                                  mode):
    text = EXTENDING + f'sampling: {{mode: {mode}, batch: 1}}\n'
    with LocalBackend() as backend, ResultsWriter(str(tmp_path), text) as writer:
        resolved.write(experiment_file.parse(text), str(tmp_path))
        summary = Runner(experiment_file.parse(text), [backend], writer).run()
    # decided again, it is swept as it ran: on its records' counts and the ones it went on to
    with open(tmp_path / 'summary.json', encoding='utf-8') as f:
        assert redecide(str(tmp_path)).json_text() == f.read()
    s = summary.experiments['sweep']
    counts = [p.n for p in s.per_n]
    assert counts[:3] == [1, 2, 3] and len(counts) > 3
    assert counts == list(range(1, counts[-1] + 1))        # on at the sweep's step
    assert s.n_star < counts[-1], 'the fitted peak lies inside the counts swept'
    rows = read(str(tmp_path), 'iterations')
    assert [int(r['group']) for r in rows] == counts        # written in the plan's order
    # told not to, it stops at its last count
    text = text.replace('margin: 1}', 'margin: 1, extend: false}')
    with LocalBackend() as backend, ResultsWriter(str(tmp_path / 'no'), text) as writer:
        summary = Runner(experiment_file.parse(text), [backend], writer).run()
    assert [p.n for p in summary.experiments['sweep'].per_n] == [1, 2, 3]
