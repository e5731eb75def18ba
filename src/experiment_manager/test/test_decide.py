"""`decide`: a finished run decided again with today's rules. On a run of today's code it
gives back the run's own summary exactly; a summary written by older rules is replaced and
the verdicts that moved are marked; a directory that is no run is refused by name."""

import json
import os
import shutil

from experiment_manager.analysis import summary
from experiment_manager.analysis.redecide import redecide
from experiment_manager.commands.decide import main


def _copy(small, tmp_path) -> str:
    run_dir = str(tmp_path / 'run')
    shutil.copytree(small[0], run_dir)
    return run_dir


def test_today_s_run_decided_again_is_its_own_summary(small):
    with open(os.path.join(small[0], 'summary.json'), encoding='utf-8') as f:
        assert redecide(small[0]).json_text() == f.read()      # to the byte


def test_an_old_summary_is_decided_again_and_what_moved_is_marked(small, tmp_path, capsys):
    run_dir = _copy(small, tmp_path)
    path = os.path.join(run_dir, 'summary.json')
    with open(path, encoding='utf-8') as f:
        old = json.load(f)
    today = summary.read(path)
    # the gripper sweep as an older rule might have said it, in a version-0 file: its first
    # gripper meets the yield
    sweep = old['experiments']['grippers']
    assert sweep['smallest'] is None and not sweep['variants'][0]['meets']
    sweep['smallest'], sweep['variants'][0]['meets'] = 0, True
    del old['schema_version']
    with open(path, 'w', encoding='utf-8') as f:
        json.dump(old, f)
    assert main([run_dir]) == 0
    out = capsys.readouterr().out
    row = next(line for line in out.splitlines() if line.startswith('  gripper (grippers)'))
    assert row.split()[2:5] == ['UNDECIDED', '[was', 'FEASIBLE]'] and out.count('[was ') == 1, out
    assert json.load(open(path, encoding='utf-8')) == old      # not written without --write
    assert main([run_dir, '--write']) == 0
    assert summary.read(path) == today
    assert json.load(open(path, encoding='utf-8'))['schema_version'] == summary.SCHEMA_VERSION
    text = open(os.path.join(run_dir, 'report.md'), encoding='utf-8').read()
    assert '| gripper (`grippers`) | **UNDECIDED** |' in text


def test_a_directory_that_is_no_run_is_refused_by_name(tmp_path, capsys):
    assert main([str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert f'run_dir: {str(tmp_path)!r}' in err or str(tmp_path) in err
    assert 'is not a run directory: it has no experiment.yaml, iterations.csv' in err


def test_a_broken_summary_is_said_with_its_directory(small, tmp_path, capsys):
    run_dir = _copy(small, tmp_path)
    with open(os.path.join(run_dir, 'summary.json'), 'w', encoding='utf-8') as f:
        f.write('{"schema_version": 7}')
    assert main([run_dir]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f'decide: {run_dir}: ') and 'schema_version 7 is newer' in err
