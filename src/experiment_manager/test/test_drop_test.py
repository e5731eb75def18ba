"""The drop_test experiment: single parts dropped onto a plate, the aspects they rest on
against the quasi-static prediction and a real drop test's counts, and a sensitivity grid that
calibrates the materials on those counts; and the file's contact materials as pairs."""

import math
import os

from experiment_manager import experiment_file
from experiment_manager.analysis import part_sheet, report
from experiment_manager.analysis import summary as summary_model
from experiment_manager.analysis.calibration import (
    calibrate,
    CHI2_HALF,
    file_keys,
    log_likelihood,
    noise,
)
from experiment_manager.analysis.headlines import headlines
from experiment_manager.analysis.report.base import Run
from experiment_manager.analysis.results import read_csv, ResultsWriter
from experiment_manager.running.local_backend import LocalBackend
from experiment_manager.running.scheduler import Runner
from pick_common.errors import InvalidArgument
import pytest

FILE = """id: drops
seed: 3
part: {model: to220}
experiments:
  - {id: drop, type: drop_test, iterations: 30, height_mm: 80,
     measured: {'+y': 11, '-y': 12, '+x': 3, '-x': 4}}
"""


def _run(text: str, directory: str) -> summary_model.Summary:
    file = experiment_file.parse(text)
    with LocalBackend() as backend, ResultsWriter(directory, file.text) as writer:
        return Runner(file, [backend], writer).run()


def test_a_drop_test_counts_the_aspects_its_parts_rest_on_beside_the_measured(tmp_path):
    summary = _run(FILE, str(tmp_path))
    s = summary.experiments['drop']
    assert s.height_mm == 80.0 and s.drops + s.other == 30
    names = [a.name for a in s.aspects]
    assert names[:2] == ['+y', '-y']        # a TO-220 lies on its broad faces most often
    counts = {a.name: a.count for a in s.aspects}
    for a in s.aspects:
        assert a.ci95[0] <= a.share <= a.ci95[1]
        assert a.measured == {'+y': 11, '-y': 12, '+x': 3, '-x': 4}.get(a.name)
    assert sum(counts.values()) == s.drops
    assert s.measured.drops == 30 and 0.0 <= s.measured.p <= 1.0
    # each iteration's row names the aspect its part came to rest on
    rows = read_csv(os.path.join(str(tmp_path), 'iterations.csv'))
    assert sorted(r['aspect'] for r in rows if r['aspect'] != 'other') == sorted(
        name for name, k in counts.items() for _ in range(k))
    part_sheet.write_account(experiment_file.parse(FILE), str(tmp_path))   # as a run does
    report.write(str(tmp_path))
    text = open(os.path.join(str(tmp_path), 'report.md'), encoding='utf-8').read()
    assert '## Drop test (`drop`)' in text and 'G-test p' in text
    assert '(aspects.png)' in text and os.path.getsize(os.path.join(str(tmp_path),
                                                                    'aspects.png')) > 10_000
    assert os.path.exists(os.path.join(str(tmp_path), 'drop_drop.png'))
    (line,) = headlines(summary)
    assert line.startswith(f'  drop (drop_test): {s.drops} drops at rest on +y ')
    assert 'against 30 measured: G-test p' in line


def test_measured_counts_must_name_the_part_s_aspects():
    with pytest.raises(InvalidArgument) as err:
        experiment_file.parse(FILE.replace("'+x': 3", "'top': 3"))
    assert err.value.field == 'experiments[0].measured.top'
    assert '+y' in err.value.rule and '-x' in err.value.rule


def test_calibration_picks_the_scenario_whose_shares_made_the_counts():
    made = {'a': 60, 'b': 30, 'c': 10}
    points = [({'e': 0.1}, {'a': 20, 'b': 40, 'c': 40}), ({'e': 0.3}, {'a': 58, 'b': 32, 'c': 10}),
              ({'e': 0.5}, {'a': 62, 'b': 28, 'c': 10}), ({'e': 0.7}, {'a': 90, 'b': 10, 'c': 0})]
    fit = calibrate('drop', made, points)
    assert fit.best == {'e': 0.3} or fit.best == {'e': 0.5}
    # the far scenarios lie outside the interval; the two alike ones inside it
    assert fit.intervals['e'] == [0.3, 0.5]
    assert log_likelihood(made, points[3][1]) > float('-inf')     # smoothed: 0 counts allowed
    assert fit.p > 0.5


def test_file_keys_nest_as_the_file_does():
    assert file_keys({'materials.part_on_surface.restitution': (0.2, 0.1, 0.3),
                      'materials.part_on_surface.lateral_friction': (0.4, 0.3, 0.5)}) == [
        'materials:', '  part_on_surface:',
        '    lateral_friction: 0.4    # 95 %: 0.3 to 0.5',
        '    restitution: 0.2    # 95 %: 0.1 to 0.3']


def test_a_sensitivity_grid_over_a_measured_drop_test_calibrates_it(tmp_path):
    text = FILE + """  - id: fit
    type: sensitivity
    of: [drop]
    iterations: 30
    grid: 2
    inputs:
      materials.part_on_surface.restitution: {low: 0.1, high: 0.6, source: to fit}
"""
    summary = _run(text, str(tmp_path))
    (fit,) = summary.experiments['fit'].calibration
    values = [p.values['materials.part_on_surface.restitution'] for p in fit.points]
    assert sorted(values) == [0.1, 0.3, 0.6]     # the file's 0.3 and the grid's ends
    low, high = fit.intervals['materials.part_on_surface.restitution']
    assert low <= fit.best['materials.part_on_surface.restitution'] <= high
    assert fit.keys[:2] == ['materials:', '  part_on_surface:']
    printed = headlines(summary)
    assert '    calibrated on drop (G-test p' in '\n'.join(printed)
    assert any(line.startswith('          restitution: ') for line in printed)
    # 30 simulated drops a point: the noise alone reorders points often, and it is said
    assert fit.noise_sd > 0 and 0 < fit.noise_outside <= 1
    assert any(line.startswith("    the simulation's own noise: two points") for line in printed)
    page = report.markdown(Run(summary))
    assert "\nThe simulation's own noise: two points of the likeliest's shares" in page
    # the keys pasted into the file give its values and say they were calibrated, and where
    pasted = experiment_file.parse(FILE.replace('experiments:', '\n'.join(fit.keys)
                                                + '\nexperiments:'))
    (pair, bases, said), _ = pasted.material_account
    assert pair == 'part_on_surface' and dict(bases)['restitution'] == 'calibrated'
    assert said == 'calibrated to the drop test drop (30 drops measured)'


HEIGHTS = FILE + """  - id: fit
    type: sensitivity
    of: [drop]
    iterations: 30
    grid: 3
    inputs:
      drop_test.height_mm: {low: 40, high: 120, source: the effective height of our drops}
"""


def test_a_sensitivity_varies_the_height_its_drop_tests_drop_from():
    f = experiment_file.parse(HEIGHTS)
    (x,) = f.experiment('fit').inputs
    assert x.base == 80.0                     # the drop test's own height_mm
    heights = {e.id: e.bin.drop_height for e in f.experiments if e.id.startswith('drop')}
    assert heights == pytest.approx({'drop': 0.08, 'drop@drop_test_height_mm_low': 0.04,
                                     'drop@drop_test_height_mm_high': 0.12})
    # the part's setup is the file's in every repeat: only the plate's height moves
    assert all(e.setup == f.setup for e in f.experiments if '@' in e.id)


@pytest.mark.parametrize('text, rule', [
    (HEIGHTS.replace('of: [drop]', 'of: [drop, bins]').replace(
        '  - id: fit', '  - {id: bins, type: bin_static, iterations: 1, parts: 10, '
        'bins_mm: [[100, 100, 20]]}\n  - id: fit'), 'bins is a bin_static: name drop tests'),
    (HEIGHTS.replace('of: [drop]', 'of: [drop, drop2]').replace(
        '  - id: fit', '  - {id: drop2, type: drop_test, iterations: 5, height_mm: 50}\n'
        '  - id: fit'), 'the drop tests named drop from 50, 80 mm'),
])
def test_a_drop_height_input_is_refused_where_it_means_nothing_or_two_things(text, rule):
    with pytest.raises(InvalidArgument) as err:
        experiment_file.parse(text)
    assert err.value.field == 'experiments[2].inputs.drop_test.height_mm'
    assert rule in err.value.rule


def test_few_simulated_drops_separate_scenarios_less_than_many():
    # the simulated shares are estimates: the same shares from 40 drops rank two scenarios
    # less surely than from 4000 (a plain multinomial would give the same gap for both)
    made = {'a': 60, 'b': 40}

    def gap(n):
        return (log_likelihood(made, {'a': 0.6 * n, 'b': 0.4 * n})
                - log_likelihood(made, {'a': 0.45 * n, 'b': 0.55 * n}))
    assert 0 < gap(40) < 0.7 * gap(4000)


def test_the_noise_of_a_ranking_is_measured_and_falls_with_more_simulated_drops():
    # binom4's measured counts against ~400 simulated drops of like shares (docs/drop-tests.md)
    made = {'a': 4, 'b': 119, 'c': 167, 'd': 104, 'e': 10}
    few = {'a': 14, 'b': 88, 'c': 183, 'd': 100, 'e': 7}
    sd = noise(made, few)
    assert sd == noise(made, dict(few))                 # seeded: the same counts, the same
    assert sd > CHI2_HALF                               # the interval is the noise's
    assert noise(made, {k: 16 * v for k, v in few.items()}) < 0.5 * sd
    outside = calibrate('drop', made, [({'e': 0.1}, few)]).noise_outside
    assert outside == pytest.approx(math.erfc(CHI2_HALF / (sd * math.sqrt(2))))
    assert noise(made, {}) == 0.0


def test_a_fitted_drop_height_is_said_beside_the_keys_not_as_one():
    made = {'a': 60, 'b': 40}
    points = [({'drop_test.height_mm': h, 'materials.part_on_surface.restitution': 0.3},
               {'a': a, 'b': 100 - a}) for h, a in ((40, 30), (80, 59), (120, 90))]
    fit = calibrate('drop', made, points)
    assert fit.best['drop_test.height_mm'] == 80
    assert not any(line.startswith('drop_test') for line in fit.keys)
    assert fit.keys[-1] == ('# drop_test.height_mm: 80    # 95 %: 80 to 80 (the height the '
                               "simulated drops fit yours best from; no key of the cell's)")
    pasted = experiment_file.parse(FILE.replace('experiments:', '\n'.join(fit.keys)
                                                + '\nexperiments:'))
    assert pasted.setup.part.part_on_surface.restitution == pytest.approx(0.3)


@pytest.mark.parametrize('key', ['lateral_friction', 'restitution', 'rolling_friction_mm'])
def test_a_part_s_former_material_key_is_refused_naming_the_pairs(key):
    with pytest.raises(InvalidArgument) as err:
        experiment_file.parse(FILE.replace('part: {model: to220}',
                                           f'part: {{model: to220, {key}: 0.3}}'))
    assert err.value.field == f'part.{key}'
    assert f'materials.part_on_surface.{key}' in err.value.rule
    assert f'materials.part_on_part.{key}' in err.value.rule


def test_the_part_s_account_says_how_each_material_value_was_got_and_where_from():
    from experiment_manager.analysis.part_sheet import describe, validator
    f = experiment_file.parse(FILE.replace('experiments:', """materials:
  part_on_surface: {restitution: 0.4, source: 'our drop test, 2026-11', basis: calibrated}
  part_on_part: {lateral_friction: 0.45, restitution: 0.2, basis: {restitution: measured}}
experiments:"""))
    lines = [line for line in describe(f, validator(f)) if 'contact' in line]
    # the value given takes the pair's basis; those left to the defaults keep the defaults'
    assert 'friction 0.35 (published), rolling arm 0.1 mm (assumed)' in lines[0]
    assert lines[0].endswith('restitution 0.4 (calibrated); from our drop test, 2026-11')
    assert 'friction 0.45 (not said)' in lines[1] and 'restitution 0.2 (measured)' in lines[1]
    assert 'source not said' in lines[1]
    f = experiment_file.parse(FILE)
    lines = [line for line in describe(f, validator(f)) if 'contact' in line]
    assert len(lines) == 2
    assert all('from the defaults: friction: The Engineering ToolBox' in line for line in lines)
    assert all('restitution 0.3 (assumed)' in line for line in lines)


@pytest.mark.parametrize('basis, field, said', [
    ('guessed', 'materials.part_on_surface.basis', 'guessed'),
    ('{colour: measured}', 'materials.part_on_surface.basis.colour', 'colour'),
    ('{lateral_friction: measured}', 'materials.part_on_surface.basis.lateral_friction',
     'does not give'),
])
def test_a_basis_that_is_no_basis_or_of_a_value_not_given_is_refused(basis, field, said):
    with pytest.raises(InvalidArgument) as err:
        experiment_file.parse(FILE.replace('experiments:', f"""materials:
  part_on_surface: {{restitution: 0.4, basis: {basis}}}
experiments:"""))
    assert err.value.field == field
    assert said in str(err.value)


def test_a_bad_contact_pair_is_named_not_a_traceback():
    with pytest.raises(InvalidArgument) as err:
        experiment_file.parse(FILE.replace('experiments:', """materials:
  part_on_surface: {restitution: 1.4, colour: red}
experiments:"""))
    text = str(err.value)
    assert 'materials.part_on_surface.restitution' in text and '1.4' in text
    assert 'materials.part_on_surface.colour' in text


def test_the_chart_draws_aspects_no_part_landed_on(tmp_path):
    from experiment_manager.analysis.report.plots import plot_drop_test
    from experiment_manager.analysis.summary import DropTest
    s = DropTest.model_validate({
        'type': 'drop_test', 'drops': 12, 'height_mm': 80.0, 'other': 0,
        'faults': {'physics_fault': 0, 'tunnelled': 0, 'thrown': 0, 'unsettled': 0,
                   'flagged': []},
        'physics': {'spilled': 0, 'tunnelled': 0, 'thrown': 0, 'max_speed': 0.0,
                    'unsettled': 0, 'max_penetration': 0.0, 'tray_error': 0.0},
        'aspects': [{'name': '+y', 'normal': [0, 1, 0], 'count': 12, 'share': 1.0,
                     'ci95': [0.7575, 1.0 - 1e-17], 'quasi_static': 0.5},
                    {'name': '-z', 'normal': [0, 0, -1], 'count': 0, 'share': 0.0,
                     'ci95': [1e-17, 0.2425], 'quasi_static': 0.5}]})
    assert plot_drop_test('drop', s, str(tmp_path / 'drop.png'))
