"""The report: verdicts from the metrics, the paper's numbers for its test-case ids, the plots,
Markdown and HTML of the same content."""

import copy
import json
import math
import os
import re
import shutil

from experiment_manager import experiment_file
from experiment_manager.analysis import decisions, pictures, report, summary, verdicts
from experiment_manager.analysis.report import Run
from experiment_manager.analysis.report.table import feeding
from experiment_manager.analysis.verdicts import FEASIBLE, NOT_ANALYSED, NOT_FEASIBLE, UNDECIDED
from experiment_manager.experiment_file import resolved
from pick_common.stats import binomial_bounds, rate_interval
from pick_validity.results import STAGE_PLACEABILITY
import pytest


@pytest.fixture(scope='module')
def run_dir(small, tmp_path_factory):
    directory = str(tmp_path_factory.mktemp('report') / 'run')
    shutil.copytree(small[0], directory)
    return directory


def _summary(run_dir):
    with open(os.path.join(run_dir, 'summary.json')) as f:
        return json.load(f)


def _verdicts(s: dict) -> list:
    """The verdicts of a summary edited as JSON (checked against the model first)."""
    return verdicts.verdicts(summary.validate(s))


def _markdown(s: dict, figures=None) -> str:
    return report.markdown(Run(summary.validate(s), figures=figures or {}))


def test_a_run_gets_its_report_files(run_dir):
    path = report.write(run_dir)
    assert path == os.path.join(run_dir, 'report.html')
    for name in ('fig14_bins.png', 'fig15_table.png', 'grippers.png'):
        with open(os.path.join(run_dir, name), 'rb') as f:
            assert f.read(8) == b'\x89PNG\r\n\x1a\n', name
    text = open(os.path.join(run_dir, 'report.md')).read()
    page = open(path).read()
    for heading in ('## Verdict', '## Static bins', '## Bin emptying', '## Vibrating table sweep',
                    '## Feeder emptying', '## Gripper sweep', '## Physics health',
                    '## Why parts were turned down'):
        assert heading in text
        assert f'<h2>{heading[3:]}' in page
    separators = [line for line in text.splitlines() if line.startswith('| --- |')]
    assert page.count('<table>') == len(separators) == 8 and 'fig15_table.png' in page
    assert 'grippers.png' in page
    assert 'paper' not in text.split('## Verdict')[1]      # id `small`: no paper numbers
    assert 'No iteration was flagged' in text
    assert re.search(r'The cell would pick [\d.]+ parts per hour \(mean of 1 run; required '
                     r'60\): 4 s per pick', text)
    # how the parts reached the tray, from the file's keys (the default tray, no dose)
    assert ('The hopper let the parts out of its outlet 30 mm over the plate (`hopper_lip_mm`), '
            'at x -97.5 mm across y -60 to 60 mm (the outer edge of `feeder_zone_mm`), 10 parts '
            'a second (`hopper_rate`) moving onto the tray at 100 mm/s (`hopper_speed_mm_s`), '
            'for the time a dose takes at that rate, a part waiting where the pile stood at the '
            'outlet, of the 195 x 150 mm tray with 27 mm walls (`tray_mm`), a dose of the whole '
            'shortfall to max* (`max_feed` would limit it). The file sets no `hopper_lip_mm`, '
            '`hopper_rate`, `hopper_speed_mm_s`, `feeder_zone_mm`, `tray_mm`: the run took '
            'their defaults.') in text
    tray = resolved.read(run_dir)['tray']
    dosed = feeding(tray, 12)
    assert dosed.endswith('at most 12 parts a feed, the fill to max* going on over several '
                          'vibrations (`max_feed`).')
    old = {k: v for k, v in tray.items() if not k.startswith('hopper_') or k == 'hopper_lip_mm'}
    assert feeding(old, 0).startswith(     # a run's record from before the hopper metered
        'The hopper fed the parts from 30 mm over the plate (`hopper_lip_mm`), or from just '
        'above the pile where it stood higher, onto the feeder zone x -97.5 to -48.75 mm, '
        'y -60 to 60 mm (`feeder_zone_mm`) of the 195 x 150 mm tray')
    assert feeding(tray, 0, ('hopper_lip_mm',)).endswith(
        'The file sets no `hopper_lip_mm`: the run took its default.')
    # a header people read, and each verdict coloured by what it says
    assert ('Part `radial_capacitor`; gripper parallel jaws: body diameter 8 mm, body length '
            '60 mm, jaw height 15 mm, jaw depth 3 mm, finger clearance 1 mm; seed 11.') in text
    for v in _verdicts(_summary(run_dir)):
        assert f'<strong class="{report.VERDICT_CLASS[v.verdict]}">{v.verdict}</strong>' in page


def test_the_report_warns_where_the_optimal_range_runs_past_the_counts_tested(run_dir):
    s = _summary(run_dir)
    sweep = s['experiments']['sweep']
    last = max(p['n'] for p in sweep['per_n'])
    sweep.update(n_star=last - 4, optimal_range=[last - 6, last - 2])
    assert 'Warning' not in _markdown(s)
    # n*'s interval, and a note when it reaches beyond the range
    sweep['n_star_ci95'] = [last - 5, last - 3]
    text = _markdown(s)
    assert (f'n* = {last - 4} parts on the table (95 % interval {last - 5}-{last - 3}, '
            'bootstrap); optimal range') in text and '**Note**' not in text
    sweep['n_star_ci95'] = [last - 10, last]
    assert f'could put it anywhere in {last - 10}-{last}.' in _markdown(s)
    del sweep['n_star_ci95']
    sweep.update(n_star=last, optimal_range=[last - 2, last + 2])
    assert (f'**Warning**: the optimal range runs past the last count tested ({last} parts): '
            'beyond it the fit is an extrapolation, and n* sits at that count') in \
        _markdown(s)


def _rates(s: dict, emptied: int, accepted: int, n: int, spilled: int = 0,
           seconds: float = 1000.0, spilling: int = 1) -> None:
    """Bins emptied, k of n, and feeder runs emptied in about `seconds` (spread by 1 %),
    `accepted` of n (the others not emptied), the first `spilling` runs spilling `spilled`
    parts each, with the decisions metrics gives them."""
    required = s['requirements']['success_rate']
    s['experiments']['emptying'].update(
        emptied=emptied, iterations=n,
        decision=decisions.rate(emptied, n, required, 'bins emptied').as_dict())
    runs = [{'time': seconds * (1 + 0.01 * (i % 3)) if i < accepted else math.inf,
             'spilled': spilled if i < spilling else 0} for i in range(n)]
    s['experiments']['feeder'].update(
        emptied=accepted, iterations=n,
        decision={'time': decisions.table_time(runs, 4 * 3600.0, required).as_dict(),
                  'spills': decisions.spills(runs, 0, required).as_dict()})
    s['experiments']['feeder']['physics']['spilled'] = spilled * spilling


def test_the_table_verdict_rests_on_the_time_to_empty_and_the_spills(run_dir):
    s = _summary(run_dir)
    s['requirements'].update(capacity=10, success_rate=0.9)
    _rates(s, 3, 3, 3)              # three runs in about 17 min: far inside 4 h ...
    table = _verdicts(s)[1]
    # ... but none spilling in 3 runs does not settle the spills: refills may still spill up
    # to 63 % of the time; 29 runs without a spill would put it under 10 %
    assert table.verdict == UNDECIDED, table
    assert table.reasons[0].startswith("0 part(s) spilled over the tray's walls in 3 runs")
    assert 'at most 100 %' in table.reasons[0] and 'at least 36.8 %' in table.reasons[0]
    assert '29 iterations would settle it' in table.reasons[0]
    assert table.reasons[1].startswith('3 runs emptied in 16.7 min to 17.0 min: 90 % of '
                                       'refills empty within ')
    assert 'one-sided 95 % tolerance bound, Gumbel' in table.reasons[1]
    assert table.reasons[2] == 'grounds settled: time FEASIBLE; not settled: spills'
    assert table.grounds['time'].interval == 'one-sided 95 % tolerance bound, Gumbel'
    _rates(s, 3, 30, 30)            # thirty runs, none spilling: both grounds settled
    table = _verdicts(s)[1]
    assert table.verdict == FEASIBLE, table
    assert table.reasons[2] == 'grounds settled: time FEASIBLE, spills FEASIBLE'
    _rates(s, 3, 3, 3, seconds=3.9 * 3600.0)   # just inside the interval: not settled
    table = _verdicts(s)[1]
    assert table.verdict == UNDECIDED
    assert table.reasons[2] == 'grounds settled: none; not settled: time, spills'
    _rates(s, 3, 2, 3)              # a run that did not empty counts as over: distribution-free
    table = _verdicts(s)[1]
    assert table.verdict == UNDECIDED and '1 of 3 runs over the interval or not emptied' \
        in table.reasons[0] and '(a run over the interval or not emptied)' in \
        table.reasons[0]
    _rates(s, 3, 0, 30)             # none of 30 emptied
    assert _verdicts(s)[1].verdict == NOT_FEASIBLE
    _rates(s, 3, 5, 5, spilled=2)   # 1 of 5 runs spilled: the bounds straddle 90 %
    feeder = s['experiments']['feeder']
    refills = s['requirements']['parts_per_hour'] / feeder['parts']
    assert (f"Spilled per refill of {feeder['parts']}: 0.4; per hour at the required "
            f"{s['requirements']['parts_per_hour']:g} parts per hour: {0.4 * refills:.3g}.") \
        in _markdown(s)
    table = _verdicts(s)[1]
    assert table.verdict == UNDECIDED
    assert '4 of 5 refills spilling at most 0 part(s)' in table.reasons[0]
    assert 'iterations would settle it if the rate seen held' in table.reasons[0]
    _rates(s, 3, 3, 3, spilled=1, spilling=3)   # every run spilled: at most 63 % do not
    table = _verdicts(s)[1]
    assert table.verdict == NOT_FEASIBLE
    # the ground that decides is said first (run prints only the first reason)
    assert table.reasons[0].startswith("3 part(s) spilled over the tray's walls in 3 runs")
    assert table.reasons[1].startswith('3 runs emptied in')
    assert table.reasons[2] == 'grounds settled: time FEASIBLE, spills NOT FEASIBLE'
    text = _markdown(s)
    assert '| vibrating table | time | time to empty the feeder, 90 % of refills | FEASIBLE |' \
        in text and '| one-sided 95 % tolerance bound, Gumbel | 3 |' in text


def test_the_exact_interval_of_a_rate():
    # Clopper-Pearson's closed forms: k = n gives (alpha/2)^(1/n) to 1, k = 0 its mirror.
    assert rate_interval(40, 40) == pytest.approx((0.025 ** (1 / 40), 1.0))
    assert rate_interval(0, 1) == pytest.approx((0.0, 0.975))
    low, high = rate_interval(5, 10)        # symmetric about a half
    assert low == pytest.approx(1 - high) and 0.18 < low < 0.19
    assert rate_interval(0, 0) == (None, None)


def test_the_iterations_that_would_decide_a_rate():
    # one-sided: all succeeding, 0.05^(1/n) >= 0.9 from n = 29 (28.4 solves it)
    assert decisions.iterations_to_decide(1, 1, 0.9) == 29
    assert decisions.iterations_to_decide(0, 1, 0.9) == 2     # 0 of 2: at most 0.776
    assert binomial_bounds(2, 2)[0] > 0.1 >= binomial_bounds(1, 1)[0]
    assert decisions.iterations_to_decide(9, 10, 0.9) is None   # the rate seen is the required
    assert decisions.iterations_to_decide(0, 0, 0.9) is None


def test_verdicts_rest_on_the_interval_of_the_rate_and_on_the_capacity(run_dir):
    s = _summary(run_dir)
    s['requirements'].update(capacity=10, success_rate=0.9)
    # One iteration that succeeded decides nothing: it reads so, with the count that would.
    _rates(s, 1, 1, 1)
    static, table = _verdicts(s)[:2]
    assert (static.verdict, table.verdict) == (UNDECIDED, UNDECIDED)
    assert static.reasons[0] == (
        '1 of 1 bins emptied: at least 5 % and at most 100 % (one-sided 95 % exact bounds '
        '(Clopper-Pearson)); required 90 % (requirements.success_rate); not settled: 29 '
        'iterations would settle it if the rate seen held')
    assert table.reasons[0].endswith('not settled: 3 runs give the fitted bound')
    _rates(s, 29, 29, 29)       # 29 of 29 clear 90 % one-sidedly (the two-sided interval: 36)
    assert [v.verdict for v in _verdicts(s)][:2] == [FEASIBLE, FEASIBLE]
    _rates(s, 0, 0, 40)         # the paper's static bins: 0 of 40
    assert [v.verdict for v in _verdicts(s)][:2] == [NOT_FEASIBLE, NOT_FEASIBLE]
    _rates(s, 36, 36, 40)       # 90 % seen, at the requirement itself
    assert 'no number of iterations would' in _verdicts(s)[0].reasons[0]
    # A tunnelled iteration (left out of the figures) leaves no option feasible, and says so
    # first.
    _rates(s, 40, 40, 40)
    s['experiments']['feeder']['faults'].update(
        tunnelled=1, flagged=[{'group': 0, 'iteration': 3, 'fault': 'tunnelled'}])
    table = _verdicts(s)[1]
    assert table.verdict == NOT_FEASIBLE
    assert table.reasons[0] == '1 iteration flagged: tunnelled 1 (see Physics health)'
    s['experiments']['feeder']['stops'] = {'stop: empty': 1, 'stop: vibration limit': 2}
    assert 'runs ended by: feeder and table empty 1, vibration limit 2)' in \
        _verdicts(s)[1].reasons[4]
    # 30 parts cannot last a refill interval: that decides, and is said first, whatever the
    # rate would have said (here: not enough iterations to decide)
    s['requirements']['capacity'] = 480
    _rates(s, 1, 1, 1)
    bin_verdict = _verdicts(s)[0]
    assert bin_verdict.verdict == NOT_FEASIBLE
    # the bin the emptying ran in, by its size in mm, as a person writes it
    x, y, z = (f'{v:g}' for v in s['experiments']['emptying']['bin_mm'])
    assert bin_verdict.option == f'static bin {x} x {y} x {z} mm'
    assert bin_verdict.reasons[0] == ('the bin was filled with 30 parts, fewer than the 480 '
                                         'a refill interval needs')
    assert bin_verdict.reasons[1].startswith('1 of 1 bins emptied')
    del s['experiments']['emptying'], s['experiments']['feeder'], s['experiments']['grippers']
    assert [v.verdict for v in _verdicts(s)] == [NOT_ANALYSED, NOT_ANALYSED]


def test_the_gripper_verdict_names_the_smallest_gripper_that_meets_the_yield(run_dir):
    s = _summary(run_dir)
    g = s['experiments']['grippers']
    for v in g['variants']:
        v.update(meets=False, valid_ci95=[0.1, 0.9])     # every interval below min_valid 1
    g['smallest'] = None
    verdict = _verdicts(s)[2]
    assert verdict.verdict == NOT_FEASIBLE and verdict.option == 'gripper (`grippers`)'
    assert verdict.reasons[0].startswith('no gripper of the sweep gives 1 valid parts per '
                                            'check at 95 % confidence; the most: D ')
    # One interval that reaches min_valid, and one scene that gives none: not decided. A
    # count's interval is said from 0.
    g['variants'][0]['valid_ci95'] = [-0.5, 1.5]
    assert verdicts.interval_text(summary.Variant.model_validate(g['variants'][0])) == '0 to 1.5'
    g['variants'][1]['valid_ci95'] = [None, None]
    verdict = _verdicts(s)[2]
    assert verdict.verdict == UNDECIDED
    assert verdict.reasons[1] == ('not enough scenes to decide: 2 grippers of the sweep had '
                                     'an interval reaching 1, or too few scenes for one')
    g['variants'][1].update(meets=True, valid_ci95=[1.5, 2.5])
    g['smallest'] = 1
    verdict = _verdicts(s)[2]
    assert verdict.verdict == FEASIBLE
    assert verdict.option == ('gripper D 8, W 3, V 15, L 60, clearance 1 mm; grasps upright '
                                 '(`grippers`)')
    assert '95 % interval 1.5 to 2.5' in verdict.reasons[0]
    assert '8 grippers x grasp sets checked on the same 2 scenes of 14 parts' in \
        verdict.reasons[1]
    text = _markdown(s)
    assert '| D 8, W 3, V 15, L 60, clearance 1 mm; grasps upright |' in text
    assert '| 1.5 to 2.5 |' in text and '| **smallest** |' in text
    g['faults']['tunnelled'] = 1        # a scene left out: no answer to rely on
    assert _verdicts(s)[2].verdict == NOT_FEASIBLE


def test_the_papers_numbers_stand_beside_ours_for_its_test_case(run_dir, tmp_path):
    shutil.copytree(run_dir, tmp_path / 'run')
    s = copy.deepcopy(_summary(run_dir))
    s['id'] = 'pth1'
    s['experiments']['feeder']['faults'].update(physics_fault=1, flagged=[
        {'group': 0, 'iteration': 0, 'fault': 'physics_fault'}])
    (tmp_path / 'run' / 'summary.json').write_text(json.dumps(s))
    report.write(str(tmp_path / 'run'))
    text = (tmp_path / 'run' / 'report.md').read_text()
    assert '| paper | 40 | 480 | 0 | 2.7 | 0 | 6 | 1.67 |' in text
    assert '| paper | 50 | 480 | 17-27 | 50 | 167 |' in text
    assert 'paper: n* = 22, 17-27' in text
    assert '| `feeder` | 1 | 1 | 0 | 0 |' in text
    assert '1 iteration flagged: physics_fault 1 (see Physics health)' in text


def _as_paper_says(summary: dict, paper: dict) -> dict:
    """summary given the paper's figures and findings (pth0), within the 1.25 ratio."""
    s = copy.deepcopy(summary)
    s['id'] = 'pth0'
    e, b = s['experiments']['emptying'], s['experiments']['bins']
    w, f = s['experiments']['sweep'], s['experiments']['feeder']
    e.update(emptied=0, iterations=40)
    e['first_check']['valid']['mean'] = 0.0040      # paper 0.0036: ratio 1.11
    e['removed']['mean'] = 0.7
    b['bins'][b['best_bin']]['size_mm'] = b['best_bin_mm'] = [100.0, 175.0, 15.0]
    b['bins'][b['best_bin']]['fractions']['container_free']['mean'] = 0.25
    # 2500 - 0.25 (n - 49)^2 over n = 1..100: a peak at 49, 26 % lower at n = 100
    none = {'n': 1, 'mean': 0.0, 'min': 0.0, 'max': 0.0, 'std': 0.0}
    w.update(per_n=[{'n': n, 'valid': none} for n in range(1, 101)],
             coefficients=[-0.25, 24.5, 2500.0 - 0.25 * 49.0 ** 2], n_star=49, fit_max=2500.0,
             no_valid=False)
    f.update(emptied=50, iterations=50)
    f['vibrations_to_empty']['mean'] = 130.0
    return s


def test_against_the_paper_says_which_findings_hold_and_why_figures_differ(run_dir):
    paper = verdicts.PAPER['pth0']
    s = _as_paper_says(_summary(run_dir), paper)
    text = '\n'.join(verdicts.against_paper(summary.validate(s), paper))
    assert text.count('| agrees |') == 3 and '| differs |' not in text, text
    assert 'rise to n* = 49, then fall: 26 % below the peak at n = 100 (fit)' in text
    assert '| best bin (mm) | 100 x 175 x 15 | 100 x 175 x 15 | the same |' in text
    assert '| parts on the table at the optimum, n* | 49 | 49 | 1.00 |' in text
    assert 'None does.' in text and '\n- ' not in text

    s['experiments']['emptying']['emptied'] = 1
    s['experiments']['sweep']['coefficients'] = [-0.01, 0.98, 2500.0 - 0.01 * 49.0 ** 2]
    s['experiments']['feeder'].update(emptied=47, runs_spilling=3)
    s['experiments']['feeder']['physics']['spilled'] = 4
    s['experiments']['feeder']['vibrations_to_empty']['mean'] = 250.0
    text = '\n'.join(verdicts.against_paper(summary.validate(s), paper))
    assert '| static bins never emptied (0 of 40) | 1 of 40 emptied | differs |' in text
    assert 'then level off: 1 % below the peak' in text
    assert '| the tray emptied in every feeder run (50 of 50) | 47 of 50 emptied | differs |' \
        in text
    assert '| vibrations to empty the feeder (mean) | 250 | 123.1 | 2.03 |' in text
    reasons = [line for line in text.splitlines() if line.startswith('- ')]
    assert [r.split(':')[0] for r in reasons[:3]] == ['- Static bins', '- Table optimum',
                                                      '- Feeder']
    assert reasons[3] == ("- 4 parts spilled over the tray's walls, in 3 of 50 feeder runs; a "
                          'run may spill 0.')

    s['experiments']['sweep'].update(n_star=100)
    assert "still rising at the sweep's last count, n = 100" in '\n'.join(
        verdicts.against_paper(summary.validate(s), paper))
    s['experiments']['sweep'].update(no_valid=True, fit_max=0.0)
    assert 'no valid part at any count: the gripper cannot pick this part' in '\n'.join(
        verdicts.against_paper(summary.validate(s), paper))
    assert '**No valid part at any count**' in _markdown(s)
    s['experiments']['sweep'].update(no_valid=False, fit_max=2500.0)
    page = report.to_html(_markdown(s), 'pth0')
    against = page.split('<h2>Against the paper</h2>')[1].split('<h2>')[0]
    assert against.count('<li>') == 4


def test_pictures_re_simulate_the_recorded_iteration(run_dir):
    file = experiment_file.load(os.path.join(run_dir, 'experiment.yaml'))
    captions = pictures.write(file, run_dir)
    # a part stopped at each stage that stopped one: in the bin drawn, at the tray's count
    # drawn, or (placeability, drawn without a scene) in any experiment's first iteration
    def stops(exp, group=None):
        return {int(r['stage']) for r in pictures._rows(run_dir, 'parts', exp)
                if r['check'] == '0' and int(r['grasp']) >= 0
                and (group is None or int(r['group']) == group)}
    drawn = stops('emptying') | stops('sweep', int(captions['tray.png'].split()[0]))
    expected = {'bin.png', 'tray.png', 'feed.png'} | {
        f'stopped_{name}.png' for stage, (name, _) in pictures.STOPPED.items()
        if stage in drawn and stage != STAGE_PLACEABILITY}
    if any(STAGE_PLACEABILITY in stops(e.id) for e in file.experiments):
        expected.add('stopped_placeability.png')
    # the small run's scenes stop parts at one stage or more (at neighbours alone since the
    # world simulates in centimetres): at least one stopped part is drawn
    assert len(expected) >= 3 and set(captions) == expected, captions
    for name, caption in captions.items():
        if name in ('bin.png', 'tray.png'):
            assert 'poses identical to the recorded ones' in caption, caption
        with open(os.path.join(run_dir, name), 'rb') as f:
            assert f.read(8) == b'\x89PNG\r\n\x1a\n'
    # the first feed drawn as it left the tray, then after the cycle, as recorded
    assert 'poses identical to the recorded first check' in captions['feed.png']
    assert 'the tray after the first feed of `feeder`' in captions['feed.png']
    if 'stopped_placeability.png' in captions:
        assert 'mm past the placing surface' in captions['stopped_placeability.png']
    assert 'green: the first pick' in captions['bin.png']
    report.write(run_dir)
    text = open(os.path.join(run_dir, 'report.md')).read()
    assert '## Pictures' in text and '![bin.png](bin.png)' in text


SPILLING = """
id: spilling
seed: 7
part: {model: radial_capacitor}
tray_mm: [195, 150, 6]        # walls lower than a capacitor is long: a throw spills
moves: [spread]
experiments:
  - {id: feeder, type: feeder_emptying, iterations: 1, parts: 30, optimal_range: [10, 20],
     max_vibrations: 10}
"""


def test_a_run_that_spilled_is_drawn_before_and_after_the_move_that_spilled(tmp_path):
    from experiment_manager.analysis.results import read_csv, ResultsWriter
    from experiment_manager.running import resimulate
    from experiment_manager.running.local_backend import LocalBackend
    from experiment_manager.running.scheduler import Runner
    file = experiment_file.parse(SPILLING)
    with LocalBackend() as backend, ResultsWriter(str(tmp_path), file.text) as writer:
        Runner(file, [backend], writer).run()
    spilled = int(read_csv(str(tmp_path / 'iterations.csv'))[0]['spilled'])
    assert spilled > 0
    captions = pictures.write(file, str(tmp_path), {'spill.png': resimulate.spill_picture})
    caption = captions['spill.png']
    move = int(re.search(r're-simulated to (?:move|feed) (\d+) of the run', caption)[1])
    over = int(re.search(r'(\d+) part\(s\) went over', caption)[1])
    assert f'it spilled {spilled} parts' in caption and 1 <= over <= spilled
    assert 1 <= move <= 10 and 'landing beside the tray: part ' in caption
    with open(tmp_path / 'spill.png', 'rb') as f:
        assert f.read(8) == b'\x89PNG\r\n\x1a\n'


def test_why_parts_were_turned_down_is_counted_per_stage():
    from experiment_manager.analysis import stages
    rows = [{'experiment': 'sweep', 'checked': 10, 'outside': 1, 'candidates': 8,
             'placeable': 3, 'container_free': 3, 'valid': 2},
            {'experiment': 'sweep', 'checked': 5, 'outside': 0, 'candidates': 5,
             'placeable': 1, 'container_free': 0, 'valid': 0}]
    stops = stages.turned_down(rows)
    assert stops == {'sweep': {'in_container': 14, 'candidacy': 1, 'placeability': 9,
                               'container collision': 1, 'neighbour collision': 1, 'valid': 2}}
    text = '\n'.join(stages.lines(stops))
    assert '`sweep`: placeability stops most, 64.3 % of the parts in the container' in text


def test_the_page_keeps_a_pipe_in_its_cell_and_escapes_raw_html(run_dir):
    s = _summary(run_dir)
    s['id'] = 'small <script>alert(1)</script>'
    s['experiments']['grippers']['variants'][0]['grasp_set'] = 'side|upright'
    page = report.to_html(_markdown(s), s['id'])
    assert '<script>' not in page and '&lt;script&gt;' in page
    # the grasp set's '|' stays in its cell: every row of the gripper table has nine cells
    table = page.split('<h2>Gripper sweep')[1].split('</table>')[0]
    rows = table.split('<tr>')[1:]
    assert len(rows) == 9 and all(r.count('<td>') + r.count('<th>') == 9 for r in rows), table
    assert 'grasps side|upright' in table
