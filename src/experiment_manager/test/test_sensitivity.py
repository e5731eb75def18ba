"""The sensitivity experiment: its scenarios as the loader builds them, the errors it names,
and (sensitivity_experiment.yaml run on the cores) what its repeats ran with and what its
summary, verdicts and report say. tests/test_experiment_graph.py runs the same file through
the graph."""

from dataclasses import replace
import os
from types import SimpleNamespace

from experiment_manager import experiment_file
from experiment_manager.analysis import metrics, report
from experiment_manager.analysis.headlines import headlines
from experiment_manager.analysis.report import Run
from experiment_manager.analysis.report.sensitivity import section as sensitivity_section
from experiment_manager.analysis.results import read_csv, read_text_rows, ResultsWriter
from experiment_manager.analysis.sensitivity import _held_said, _map, _robustness, SpillRuns
from experiment_manager.analysis.sensitivity import summarise as sensitivity_summary
from experiment_manager.analysis.summary import Flip, Held, Said, Scenario, Sensitivity, Summary
from experiment_manager.analysis.verdicts import verdicts
from experiment_manager.commands.run import main as run_main
from experiment_manager.experiment_file.plan import plan
from experiment_manager.experiment_file.scenarios import latin_hypercube, point_key
from experiment_manager.running.local_backend import LocalBackend
from experiment_manager.running.procedures import run_unit
from experiment_manager.running.scheduler import Runner
import numpy as np
from pick_common.errors import InvalidArgument
import pytest

SENSITIVITY = os.path.join(os.path.dirname(__file__), 'sensitivity_experiment.yaml')
HEAD = """id: s
seed: 3
gripper: {body_diameter_mm: 8, jaw_depth_mm: 3}
moves: [flip, {move: forward, duration_s: 0.2}]
experiments:
  - {id: bins, type: bin_static, iterations: 3, parts: 20, bins_mm: [[100, 100, 20]]}
  - {id: emptying, type: bin_emptying, iterations: 4, parts: 20, bin: bins}
  - {id: sweep, type: table_sweep, iterations: 1, counts: {first: 2, last: 6, step: 2}}
"""


def _typed(said: dict) -> Sensitivity:
    """A sensitivity experiment's summary as summary.json holds it, from the keys a test sets
    (the rest: no held experiment, no tornado, no fault, no physics)."""
    return Sensitivity.model_validate({
        'type': 'sensitivity', 'held': {}, 'tornado': {},
        'faults': {**dict.fromkeys(metrics.FAULTS, 0), 'flagged': []},
        'physics': metrics.physics([]).model_dump(), **said})


@pytest.fixture(scope='module')
def sens(tmp_path_factory) -> tuple[str, Summary]:
    """sensitivity_experiment.yaml run on the cores: (run directory, summary)."""
    directory = str(tmp_path_factory.mktemp('sens'))
    file = experiment_file.load(SENSITIVITY)
    with LocalBackend() as backend, ResultsWriter(directory, file.text) as writer:
        return directory, Runner(file, [backend], writer).run()


def sensitivity(text: str) -> str:
    return HEAD + '  - {id: robust, type: sensitivity, ' + text + '}\n'


def test_each_input_gets_a_low_and_a_high_scenario_and_the_repeats_keep_their_sources():
    f = experiment_file.parse(sensitivity(
        'iterations: 2, of: [emptying], joint: 3, inputs: {'
        'materials.part_on_surface.lateral_friction: '
        '{low: 0.2, high: 0.9, source: tilting-plane tests}, '
        'gripper.jaw_depth_mm: {low: 2, high: 5, source: catalogue}, '
        'moves.duration_scale: {low: 0.5, high: 2, source: feeder manual}}'))
    robust = f.experiment('robust')
    names = [s.name for s in robust.scenarios]
    assert names == ['materials_part_on_surface_lateral_friction_low',
                     'materials_part_on_surface_lateral_friction_high',
                     'gripper_jaw_depth_mm_low', 'gripper_jaw_depth_mm_high',
                     'moves_duration_scale_low', 'moves_duration_scale_high',
                     'joint_1', 'joint_2', 'joint_3']
    assert [x.base for x in robust.inputs] == [0.35, 3.0, 1.0]
    assert robust.inputs[0].source == 'tilting-plane tests'
    # the repeats come before the sensitivity experiment, capped at its iterations, and take
    # their bin from the file's `bins` (not repeated)
    assert [e.id for e in f.experiments][3:] == [f'emptying@{n}' for n in names] + ['robust']
    low = f.experiment('emptying@materials_part_on_surface_lateral_friction_low')
    assert low.iterations == 2 and low.bin_from == 'bins'
    assert robust.sources[-1] == 'emptying@joint_3'
    # one input changed, the rest as in the file
    run = f.for_experiment(low)
    assert run.part.part_on_surface.lateral_friction == 0.2 and run.gripper == f.gripper
    assert run.moves == f.moves and f.for_experiment(f.experiment('emptying')) is f
    deep = f.for_experiment(f.experiment('emptying@gripper_jaw_depth_mm_high'))
    assert deep.gripper.jaw_depth == pytest.approx(0.005) and deep.part == f.part
    slow = f.for_experiment(f.experiment('emptying@moves_duration_scale_high'))
    assert [m.duration for m in slow.moves] == pytest.approx([2 * m.duration for m in f.moves])
    assert [m.amplitude for m in slow.moves] == [m.amplitude for m in f.moves]
    # common random numbers: a repeat's iterations have the seeds of the experiment's own
    summary = {'bins': SimpleNamespace(best_bin=0)}      # plan reads the best bin's field
    assert [u.seed for u in plan(f, low, summary)] == [
        u.seed for u in plan(f, f.experiment('emptying'), summary)][:2]


def test_a_repeated_source_is_taken_from_the_same_scenario():
    f = experiment_file.parse(sensitivity(
        'iterations: 1, of: [bins, emptying], inputs: {'
        'materials.part_on_surface.restitution: {low: 0, high: 0.6, source: guess}}'))
    high = 'materials_part_on_surface_restitution_high'
    assert f.experiment(f'emptying@{high}').bin_from == f'bins@{high}'


def test_the_joint_scenarios_are_a_latin_hypercube():
    f = experiment_file.parse(sensitivity(
        'iterations: 1, of: [sweep], joint: 10, inputs: {'
        'materials.part_on_surface.lateral_friction: {low: 0.2, high: 0.7, source: a}, '
        'part.mass_g: {low: 0.5, high: 1.5, source: b}}'))
    robust = f.experiment('robust')
    joint = [dict(s.values) for s in robust.scenarios if s.name.startswith('joint')]
    for x in robust.inputs:      # one value in each tenth of each range
        strata = sorted(int((p[x.name] - x.low) / (x.high - x.low) * 10) for p in joint)
        assert strata == list(range(10)), x.name
    assert joint == latin_hypercube(robust.inputs, 10, 3, 'robust')   # seeded: the same again
    mass = f.for_experiment(f.experiment('sweep@joint_1')).part.mass
    assert mass == pytest.approx(joint[0]['part.mass_g'] / 1000)


RESTITUTION = r'experiments\[3\]\.inputs\.materials\.part_on_surface\.restitution'


@pytest.mark.parametrize('text, field, rule', [
    ('iterations: 1, of: [sweep], inputs: {part.colour: {low: 0, high: 1, source: x}}',
     r'experiments\[3\]\.inputs\.part\.colour', 'is not an input a sensitivity experiment '
     r'varies \(materials\.part_on_surface\.lateral_friction'),
    ('iterations: 1, of: [sweep], inputs: {materials.part_on_surface.restitution: '
     '{low: 0.5, high: 0.2, source: x}}',
     RESTITUTION + r'\.high', r'must be above low \(0\.5\)'),
    ('iterations: 1, of: [sweep], inputs: {materials.part_on_surface.restitution: '
     '{low: 0.1, high: 0.2}}', RESTITUTION + r'\.source', 'is required|missing'),
    ('iterations: 1, of: [sweep], inputs: {materials.part_on_surface.restitution: '
     '{low: 0.1, high: 1.5, source: x}}', RESTITUTION + r'\.high', r'1\.5'),
    ('iterations: 1, of: [sweep], inputs: {part.restitution: {low: 0.1, high: 0.5, source: x}}',
     r'experiments\[3\]\.inputs\.part\.restitution', 'has moved: vary materials'),
    ('iterations: 1, of: [feeder], inputs: {materials.part_on_surface.restitution: '
     '{low: 0, high: 1, source: x}}',
     r'experiments\[3\]\.of\[0\]', 'names no earlier experiment'),
    # the gripper's key's own limit (its kind's table), named at the input
    ('iterations: 1, of: [sweep], inputs: {gripper.jaw_depth_mm: {low: 1, high: 1200, '
     'source: x}}', r'experiments\[3\]\.inputs\.gripper\.jaw_depth_mm\.high',
     'must be <= 1000'),
    ('iterations: 1, of: [sweep], inputs: {moves.amplitude_scale: {low: 1, high: 40, '
     'source: x}}', r'experiments\[3\]\.inputs \(moves_amplitude_scale_high\) \(moves\[0\]',
     ''),
])
def test_a_bad_sensitivity_experiment_is_named(text, field, rule):
    with pytest.raises(InvalidArgument, match=field + '.*' + rule):
        experiment_file.parse(sensitivity(text))


def test_the_repeats_ran_with_their_scenario_and_the_summary_compares_them(sens):
    directory, summary = sens
    rows = read_csv(os.path.join(directory, 'iterations.csv'))
    by_id = {r['experiment']: r for r in rows if r['experiment'].startswith('feeder')}
    # the same seed in every scenario; what differs is the input
    assert len({r['seed'] for r in by_id.values()}) == 1
    base = by_id['feeder']
    moved = [k for k, r in by_id.items() if k != 'feeder' and _run(r) != _run(base)]
    assert 'feeder@materials_part_on_surface_lateral_friction_low' in moved, moved
    # the gripper reached the checks: on the same scenes, a wider body finds fewer valid
    checks = read_csv(os.path.join(directory, 'checks.csv'))
    valid = {k: [int(c['valid']) for c in checks if c['experiment'] == k]
             for k in ('feeder', 'feeder@gripper_body_diameter_mm_high')}
    assert sum(valid['feeder@gripper_body_diameter_mm_high']) < sum(valid['feeder']), valid
    s = summary.experiments['robust']
    assert set(summary.repeats) == {f'feeder@{x.name}' for x in s.scenarios}
    assert [x.name for x in s.inputs] == ['materials.part_on_surface.lateral_friction',
                                          'gripper.body_diameter_mm', 'moves.amplitude_scale']
    assert s.inputs[1].base == 8.0 and s.inputs[0].source == 'a guess, for the tests'
    # the answers are the repeats' own; the tornado's bars are the low and high scenarios'
    for x in s.scenarios:
        repeat = summary.repeats[f'feeder@{x.name}']
        assert x.answers['vibrations'] == repeat.vibrations_to_empty.mean
    scenario = {x.name: x.answers for x in s.scenarios}
    assert s.tornado['vibrations']['materials.part_on_surface.lateral_friction'] == {
        'low': scenario['materials_part_on_surface_lateral_friction_low']['vibrations'],
        'high': scenario['materials_part_on_surface_lateral_friction_high']['vibrations']}
    seen = [x.answers['vibrations'] for x in [s.base, *s.scenarios]]
    assert s.ranges['vibrations'] == [min(v for v in seen if v is not None),
                                      max(v for v in seen if v is not None)]
    # the table's verdict in each scenario, and said with the file's verdict
    table = next(r for r in s.robustness if r.option == 'vibrating table')
    said = {x.verdicts['vibrating table'] for x in s.scenarios}
    assert table.holds == (said == {table.verdict})
    reasons = next(v for v in verdicts(summary) if v.option == 'vibrating table').reasons
    assert reasons[-1] == f'over the ranges of `robust`: {table.said}'
    assert f'    {table.line}' in headlines(summary)


def test_the_report_draws_the_tornado_and_lists_the_scenarios(sens, tmp_path):
    directory, summary = sens
    text = report.markdown(Run(summary, figures={'sensitivity_robust': True}))
    section = text.split('## How far the answers move (`robust`)')[1].split('\n## ')[0]
    assert '![tornado chart of robust](sensitivity_robust.png)' in section
    assert ('| `materials.part_on_surface.lateral_friction` | 0.35 | 0.3 | 0.8 | a guess, for '
            'the tests |') in section
    assert ('| materials_part_on_surface_lateral_friction_low | '
            'materials.part_on_surface.lateral_friction 0.3 |') in section
    path = str(tmp_path / 'tornado.png')
    assert report.plot_tornado('robust', summary.experiments['robust'], path)
    with open(path, 'rb') as f:
        assert f.read(8) == b'\x89PNG\r\n\x1a\n'


def test_an_end_with_no_value_is_drawn_on_top_and_named():
    # PTH1's jaws at 6 mm: no feeder run emptied, so no vibrations to empty; the bar cannot
    # show it, and it is where the verdict flipped
    bars = report.tornado_bars({'gripper.jaw_depth_mm': {'low': 79.7, 'high': None},
                                'moves.amplitude_scale': {'low': 224.0, 'high': 81.0},
                                'materials.part_on_surface.restitution': {'low': 79.7,
                                                                          'high': 75.3}},
                                79.7)
    assert [b[0] for b in bars] == ['materials.part_on_surface.restitution',
                                    'moves.amplitude_scale',
                                    'gripper.jaw_depth_mm (high: no value)']


def test_repeats_give_the_same_rows_in_any_order_on_a_backend_switched_between_scenarios(sens):
    directory, _ = sens
    file = experiment_file.load(SENSITIVITY)
    units = [u for e in file.experiments for u in plan(file, e, {})]
    again = {}
    with LocalBackend() as backend:
        for u in reversed(units):      # every unit on another scenario than the last
            scenario_file = file.for_experiment(u.experiment)
            backend.start(scenario_file)
            again[u.key] = run_unit(scenario_file, u, backend).iteration
    for row in read_text_rows(os.path.join(directory, 'iterations.csv'), drop=('wall_time',)):
        got = again[(row['experiment'], int(row['group']), int(row['iteration']))]
        assert {k: str(v) for k, v in got.items() if k != 'wall_time'} == row


def _run(row: dict) -> tuple:
    """What a feeder run did, as iterations.csv says it."""
    return tuple(row[k] for k in ('picks', 'checks', 'vibrations', 'feeds', 'table_time'))


def test_values_outside_a_range_are_not_drawn():
    f = experiment_file.parse(sensitivity(
        'iterations: 1, of: [sweep], joint: 64, inputs: {'
        'materials.part_on_surface.spinning_friction_mm: {low: 0.05, high: 0.5, source: a}}'))
    values = np.array([dict(s.values)['materials.part_on_surface.spinning_friction_mm']
                       for s in f.experiment('robust').scenarios])
    assert values.min() >= 0 and values.max() <= 0.5


def test_a_flip_names_the_scenario_and_its_values_and_undecided_is_not_called_a_flip():
    robust = experiment_file.parse(sensitivity(
        'iterations: 1, of: [emptying], inputs: {'
        'gripper.jaw_depth_mm: {low: 2, high: 6, source: catalogue}}')).experiment('robust')
    base = Said(answers={}, verdicts={'static bin': 'FEASIBLE', 'vibrating table': 'FEASIBLE'})
    scenarios = [
        Scenario(name='gripper_jaw_depth_mm_low', values={'gripper.jaw_depth_mm': 2.0},
                 answers={}, verdicts={'static bin': 'FEASIBLE', 'vibrating table': 'FEASIBLE'}),
        Scenario(name='gripper_jaw_depth_mm_high', values={'gripper.jaw_depth_mm': 6.0},
                 answers={},
                 verdicts={'static bin': 'NOT FEASIBLE', 'vibrating table': 'UNDECIDED'})]
    bin_, table = _robustness(robust, base, scenarios)
    assert not bin_.holds and bin_.flips[0].scenario == 'gripper_jaw_depth_mm_high'
    assert bin_.line == ('static bin FEASIBLE here, but NOT FEASIBLE at gripper.jaw_depth_mm '
                         '6 (1 of 2 scenarios)')
    assert bin_.sources == {'gripper.jaw_depth_mm': 'catalogue'}
    assert table.line.endswith('the runs there do not settle it, which is not a flip to '
                               'the other side')
    same = [s.model_copy(update={'verdicts': base.verdicts}) for s in scenarios]
    assert [r.line for r in _robustness(robust, base, same)] == [
        'static bin FEASIBLE over all ranges (2 scenarios: gripper.jaw_depth_mm)',
        'vibrating table FEASIBLE over all ranges (2 scenarios: gripper.jaw_depth_mm)']


def test_a_table_flip_its_spills_make_says_whether_its_runs_tell_it_from_the_files():
    robust = experiment_file.parse(sensitivity(
        'iterations: 3, of: [emptying], inputs: {'
        'gripper.jaw_depth_mm: {low: 2, high: 6, source: catalogue}}')).experiment('robust')

    def runs(spilling, n=3, spills='FEASIBLE', time='FEASIBLE', limit=0):
        return SpillRuns(n, spilling, limit, spills, time)

    def scenarios(low, high):
        return [Scenario(name=f'gripper_jaw_depth_mm_{end}', values={'gripper.jaw_depth_mm': v},
                         answers={}, verdicts={'vibrating table': verdict})
                for end, v, verdict in (('low', 2.0, low), ('high', 6.0, high))]
    # none of 3 runs spilled at the file's values; 1 of 3 at the low end, whose time ground is
    # UNDECIDED too (its spills make the NOT FEASIBLE: p = 1); the high end UNDECIDED by its
    # time alone
    base = Said(answers={}, verdicts={'vibrating table': 'FEASIBLE'})
    spill_runs = {None: runs(0),
                  'gripper_jaw_depth_mm_low': runs(1, spills='NOT FEASIBLE', time='UNDECIDED'),
                  'gripper_jaw_depth_mm_high': runs(0, time='UNDECIDED')}
    (table,) = _robustness(robust, base, scenarios('NOT FEASIBLE', 'UNDECIDED'), spill_runs)
    low, high = table.flips
    assert low.spills_p == pytest.approx(1.0) and high.spills_p is None
    assert ("1 of these flip on their spills, with runs spilling 1 of 3 there against 0 of 3 "
            "at the file's values" in table.line)
    assert 'the least p they allow is 0.10' in table.line
    # 30 runs a side tell 15 spilling from none: the flips are said, not called a draw
    base = Said(answers={}, verdicts={'vibrating table': 'NOT FEASIBLE'})
    spill_runs = {None: runs(15, 30, spills='NOT FEASIBLE'),
                  'gripper_jaw_depth_mm_low': runs(0, 30), 'gripper_jaw_depth_mm_high': runs(0, 30)}
    (table,) = _robustness(robust, base, scenarios('FEASIBLE', 'FEASIBLE'), spill_runs)
    assert all(f.spills_p < 1e-4 for f in table.flips)
    assert 'flip on their spills' not in table.line
    # where a run may spill parts, the ground is parts per refill: no runs' test is said
    spill_runs = {k: replace(v, limit=2) for k, v in spill_runs.items()}
    (table,) = _robustness(robust, base, scenarios('FEASIBLE', 'FEASIBLE'), spill_runs)
    assert all(f.spills_p is None for f in table.flips)


def test_a_grid_maps_the_verdicts_over_two_inputs():
    f = experiment_file.parse(sensitivity(
        'iterations: 1, of: [emptying], grid: 3, inputs: {'
        'gripper.body_diameter_mm: {low: 12, high: 30, source: a}, '
        'gripper.jaw_depth_mm: {low: 3, high: 6, source: b}}'))
    robust = f.experiment('robust')
    cells = [dict(s.values) for s in robust.scenarios if s.name.startswith('grid_')]
    # (12, 3) and (30, 3) are the body's low and high at the file's 3 mm jaws: not run twice
    assert cells == [{'gripper.body_diameter_mm': d, 'gripper.jaw_depth_mm': w}
                     for d in (12.0, 21.0, 30.0) for w in (3.0, 4.5, 6.0)
                     if (d, w) not in {(12.0, 3.0), (30.0, 3.0)}]
    assert len(robust.scenarios) == 3 + 7          # the jaws' low is the file's 3 mm
    said = {(12.0, 3.0): 'FEASIBLE', (30.0, 6.0): 'NOT FEASIBLE'}
    scenarios = [Scenario(name=s.name, values=dict(s.values), answers={}, verdicts={
        'static bin': said.get(point_key(robust.inputs, dict(s.values)), 'UNDECIDED')})
        for s in robust.scenarios]
    m = _map(robust, Said(answers={}, verdicts={'static bin': 'UNDECIDED'}), scenarios)
    assert (m.rows.input, m.rows.values) == ('gripper.body_diameter_mm', [12.0, 21.0, 30.0])
    assert m.columns.values == [3.0, 4.5, 6.0]
    assert m.verdicts['static bin'][0][0] == 'FEASIBLE'      # the body's low scenario
    assert m.verdicts['static bin'][2][2] == 'NOT FEASIBLE'
    assert m.verdicts['static bin'][1][1] == 'UNDECIDED'
    text = sensitivity_section('robust', _typed({
        'of': ['emptying'], 'scenarios': [], 'iterations': 1, 'inputs': [], 'robustness': [],
        'ranges': {}, 'base': {'answers': {}, 'verdicts': {}}, 'map': m.model_dump()}), False)
    assert '| 12 | **FEASIBLE** | **UNDECIDED** | **UNDECIDED** |' in text
    # a level at the file's value: that grid point is the file's own run
    centred = experiment_file.parse(sensitivity(
        'iterations: 1, of: [emptying], grid: 3, inputs: {'
        'gripper.body_diameter_mm: {low: 4, high: 12, source: a}, '
        'gripper.jaw_depth_mm: {low: 1, high: 5, source: b}}')).experiment('robust')
    assert len(centred.scenarios) == 4 + 4         # 9 points less the file's and 4 ends
    m = _map(centred, Said(answers={}, verdicts={'static bin': 'FEASIBLE'}),
             [Scenario(name=s.name, values=dict(s.values), answers={},
                       verdicts={'static bin': 'NOT FEASIBLE'}) for s in centred.scenarios])
    assert [row[1] for row in m.verdicts['static bin']] == [
        'NOT FEASIBLE', 'FEASIBLE', 'NOT FEASIBLE']
    with pytest.raises(InvalidArgument, match=r'over the limit of 200'):
        experiment_file.parse(sensitivity(
            'iterations: 1, of: [emptying], grid: 9, inputs: {'
            'gripper.body_diameter_mm: {low: 12, high: 30, source: a}, '
            'gripper.jaw_depth_mm: {low: 3, high: 6, source: b}, '
            'materials.part_on_surface.restitution: {low: 0, high: 0.2, source: c}}'))


def test_only_the_options_whose_runs_are_repeated_are_said_to_hold(small):
    # the small file's bin, table and gripper verdicts; only the feeder's runs repeated (here
    # as copies of the file's own): the bin and the gripper were not tried on the ranges
    _, summary = small
    with open(os.path.join(os.path.dirname(__file__), 'small_experiment.yaml')) as f:
        text = f.read()
    file = experiment_file.parse(text + (
        '  - {id: robust, type: sensitivity, iterations: 1, of: [feeder], inputs: '
        '{materials.part_on_surface.restitution: {low: 0, high: 0.2, source: a}}}\n'))
    robust = file.experiment('robust')
    summaries = {**summary.experiments, **{
        f'feeder@{s.name}': summary.experiments['feeder'] for s in robust.scenarios}}
    said = sensitivity_summary(file, robust, summaries)
    assert list(said.base.verdicts) == ['vibrating table']
    assert [r.option for r in said.robustness] == ['vibrating table']
    assert said.robustness[0].holds       # the same runs: the same verdict
    # the feeder's range came from the sweep, not repeated: said with the section and a flip
    assert said.held == {'feeder': Held(what='range', source='sweep')}
    assert '`feeder` ran at the range of `sweep`' in '\n'.join(
        sensitivity_section('robust', said, False))
    flip = Flip(scenario='x_high', verdict='NOT FEASIBLE', values={'x': 1})
    flipped = _held_said([said.robustness[0].model_copy(update={
        'holds': False, 'flips': [flip],
        'line': 'vibrating table FEASIBLE here, but NOT FEASIBLE at x 1'})], said.held)
    assert flipped[0].line.endswith('at x 1 (`feeder` at the range of `sweep`, not repeated)')


def test_a_gripper_input_is_refused_for_a_gripper_sweep_whose_grippers_are_its_own():
    text = HEAD + ('  - {id: g, type: gripper_sweep, iterations: 1, parts: 10, '
                   'grippers: {body_diameter_mm: [8, 12]}}\n'
                   '  - {id: robust, type: sensitivity, iterations: 1, of: [g], inputs: '
                   '{gripper.jaw_depth_mm: {low: 2, high: 4, source: a}}}\n')
    with pytest.raises(InvalidArgument, match=r'experiments\[4\]\.inputs\.gripper\.jaw_depth_mm'
                       r'.*cannot reach the gripper_sweep g'):
        experiment_file.parse(text)
    assert experiment_file.parse(text.replace(
        'gripper.jaw_depth_mm: {low: 2, high: 4',
        'materials.part_on_surface.restitution: {low: 0, high: 0.2'))


def test_run_check_says_what_the_scenarios_add(tmp_path, capsys):
    """`run --check` prints the plan: the repeats a sensitivity adds and their scenarios, with
    --iterations applied as the run would."""
    assert run_main(['--check', '--iterations', '1', SENSITIVITY,
                     '--output', str(tmp_path)]) == 0
    out = capsys.readouterr().out
    # feeder: 1; the sensitivity: 3 inputs x (low, high) + 2 joint = 8 repeats of 1
    assert 'plan: 2 experiment(s), 9 iterations\n' in out
    assert '  feeder (feeder_emptying): 1 iterations\n' in out
    assert '  robust (sensitivity of feeder): 3 input(s), 8 scenario(s), 8 repeat(s) of 8 ' \
        'iterations\n' in out
    assert ('    materials_part_on_surface_lateral_friction_low: '
            'materials.part_on_surface.lateral_friction 0.3\n') in out
    assert out.count('    joint_') == 2
    assert 'feeder cycle, one vibration: forward (1.4, 0, 1.4 mm at 26 Hz for 0.5 s, as ' \
        'given)\n' in out
    assert run_main(['--check', '--adaptive', SENSITIVITY, '--output', str(tmp_path)]) == 0
    assert 'plan: 2 experiment(s), at most 9 iterations (sampling adaptive' \
        in capsys.readouterr().out


def test_the_trays_hopper_and_walls_are_inputs_of_the_repeats_on_the_tray():
    f = experiment_file.parse(sensitivity(
        'iterations: 1, of: [sweep, emptying], inputs: {'
        'tray.hopper_rate: {low: 5, high: 40, source: a}, '
        'tray.wall_mm: {low: 20, high: 40, source: b}, '
        'tray.hopper_speed_mm_s: {low: 50, high: 300, source: c}, '
        'tray.hopper_lip_mm: {low: 15, high: 50, source: d}}'))
    robust = f.experiment('robust')
    assert [(x.name, x.base) for x in robust.inputs] == [
        ('tray.hopper_rate', 10.0), ('tray.wall_mm', 27.0), ('tray.hopper_speed_mm_s', 100.0),
        ('tray.hopper_lip_mm', 30.0)]

    def tray(exp_id):
        return plan(f, f.experiment(exp_id), {})[0].container
    assert tray('sweep') == f.tray
    assert tray('sweep@tray_hopper_rate_low').hopper_rate == 5.0
    assert tray('sweep@tray_wall_mm_high').inner_size == (0.195, 0.15, 0.04)
    assert tray('sweep@tray_hopper_speed_mm_s_high').hopper_speed == pytest.approx(0.3)
    assert tray('sweep@tray_hopper_lip_mm_low').drop_height == pytest.approx(0.015)
    # the bin's emptying runs in its bin whatever the tray
    assert f.experiment('emptying@tray_wall_mm_high').bin_from == 'bins'


@pytest.mark.parametrize('text, field, rule', [
    ('iterations: 1, of: [emptying], inputs: {tray.hopper_rate: {low: 5, high: 40, '
     'source: x}}', r'experiments\[3\]\.inputs\.tray\.hopper_rate',
     'none of the experiments of `of` runs on it'),
    ('iterations: 1, of: [sweep], inputs: {tray.wall_mm: {low: 2, high: 40, source: x}}',
     r'experiments\[3\]\.inputs\.tray\.wall_mm\.low', 'must be >= 5'),
    ('iterations: 1, of: [sweep], inputs: {tray.hopper_speed_mm_s: {low: 0, high: 40, '
     'source: x}}', r'experiments\[3\]\.inputs\.tray\.hopper_speed_mm_s\.low', 'must be > 0'),
])
def test_a_tray_input_that_cannot_apply_is_named(text, field, rule):
    with pytest.raises(InvalidArgument, match=field + '.*' + rule):
        experiment_file.parse(sensitivity(text))


def test_a_gripper_input_of_another_kind_is_refused_in_the_one_wording():
    with pytest.raises(InvalidArgument) as err:
        experiment_file.parse(sensitivity(
            'iterations: 1, of: [emptying], inputs: {'
            'gripper.cup_diameter_mm: {low: 2, high: 4, source: a}}'))
    assert str(err.value).endswith('is a key of a suction cup, and the gripper is parallel '
                                   'jaws (gripper.type: jaws)'), str(err.value)
