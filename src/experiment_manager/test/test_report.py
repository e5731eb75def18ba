"""The report: verdicts from the metrics, the paper's numbers for its test-case ids, the plots,
Markdown and HTML of the same content."""

import copy
import json
import os
import shutil

from experiment_manager import config, pictures, report
from experiment_manager.report import FEASIBLE, NOT_ANALYSED, NOT_FEASIBLE
import pytest


@pytest.fixture(scope='module')
def run_dir(small, tmp_path_factory):
    directory = str(tmp_path_factory.mktemp('report') / 'run')
    shutil.copytree(small[0], directory)
    return directory


def _summary(run_dir):
    with open(os.path.join(run_dir, 'summary.json')) as f:
        return json.load(f)


def test_a_run_gets_its_report_files(run_dir):
    path = report.write(run_dir)
    assert path == os.path.join(run_dir, 'report.html')
    for name in ('fig14_bins.png', 'fig15_table.png'):
        with open(os.path.join(run_dir, name), 'rb') as f:
            assert f.read(8) == b'\x89PNG\r\n\x1a\n', name
    text = open(os.path.join(run_dir, 'report.md')).read()
    page = open(path).read()
    for heading in ('## Verdict', '## Static bins', '## Bin emptying', '## Vibrating table sweep',
                    '## Feeder emptying', '## Physics faults'):
        assert heading in text
        assert f'<h2>{heading[3:]}' in page
    separators = [line for line in text.splitlines() if line.startswith('| --- |')]
    assert page.count('<table>') == len(separators) == 4 and 'fig15_table.png' in page
    assert 'paper' not in text.split('## Verdict')[1]      # id `small`: no paper numbers
    assert 'No iteration was flagged' in text


def test_verdicts_follow_the_emptied_runs_and_the_capacity(run_dir):
    s = _summary(run_dir)
    s['requirements']['capacity'] = 10
    s['experiments']['emptying'].update(emptied=1, iterations=1)
    s['experiments']['feeder'].update(emptied=1, iterations=1)
    assert [v['verdict'] for v in report.verdicts(s, {})] == [FEASIBLE, FEASIBLE]
    s['experiments']['feeder']['emptied'] = 0
    assert [v['verdict'] for v in report.verdicts(s, {})] == [FEASIBLE, NOT_FEASIBLE]
    s['requirements']['capacity'] = 480         # 30 parts cannot last a refill interval
    bin_verdict = report.verdicts(s, {})[0]
    assert bin_verdict['verdict'] == NOT_FEASIBLE
    assert 'fewer than the 480 a refill interval needs' in bin_verdict['reasons'][-1]
    del s['experiments']['emptying'], s['experiments']['feeder']
    assert [v['verdict'] for v in report.verdicts(s, {})] == [NOT_ANALYSED, NOT_ANALYSED]


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
    assert '1 iteration(s) flagged: physics_fault 1 (see Physics faults)' in text


def test_pictures_re_simulate_the_recorded_iteration(run_dir):

    captions = pictures.write(config.load(os.path.join(run_dir, 'experiment.yaml')), run_dir)
    assert set(captions) == {'bin.png', 'tray.png'}
    for name, caption in captions.items():
        assert 'poses identical to the recorded ones' in caption, caption
        with open(os.path.join(run_dir, name), 'rb') as f:
            assert f.read(8) == b'\x89PNG\r\n\x1a\n'
    assert 'green: the first pick' in captions['bin.png']
    report.write(run_dir)
    text = open(os.path.join(run_dir, 'report.md')).read()
    assert '## Pictures' in text and '![bin.png](bin.png)' in text
