"""`decide`: a finished run decided again with today's rules. On a run of today's code it
gives back the run's own summary exactly; a summary written by older rules is replaced and
the verdicts that moved are marked; a directory that is no run is refused by name."""

from dataclasses import replace
import json
import os
import shutil

from experiment_manager import experiment_file
from experiment_manager.analysis import summary
from experiment_manager.analysis.redecide import redecide
from experiment_manager.commands.decide import main
from experiment_manager.experiment_file import ran, resolved
import numpy as np
from pick_common.errors import InvalidArgument
import pytest

CONFIG = os.path.join(os.path.dirname(__file__), '..', 'config')


def _copy(small, tmp_path) -> str:
    run_dir = str(tmp_path / 'run')
    shutil.copytree(small[0], run_dir)
    return run_dir


def test_today_s_run_decided_again_is_its_own_summary(small):
    with open(os.path.join(small[0], 'summary.json'), encoding='utf-8') as f:
        assert redecide(small[0]).json_text() == f.read()      # to the byte


def test_a_run_is_decided_again_from_what_it_ran_with_without_its_experiment_file(
        small, tmp_path):
    """decide reads the run's resolved.json records: with the experiment file unreadable (and
    so no part to build), the same summary to the byte; a resolved.json written before it
    kept records sends decide to the experiment file; broken records are named."""
    run_dir = _copy(small, tmp_path)
    with open(os.path.join(run_dir, 'summary.json'), encoding='utf-8') as f:
        recorded = f.read()
    yaml_path = os.path.join(run_dir, 'experiment.yaml')
    text = open(yaml_path, encoding='utf-8').read()
    with open(yaml_path, 'w', encoding='utf-8') as f:
        f.write('id: [not, a, file')
    assert redecide(run_dir).json_text() == recorded
    path = os.path.join(run_dir, resolved.NAME)
    data = json.load(open(path, encoding='utf-8'))
    del data['records']
    json.dump(data, open(path, 'w', encoding='utf-8'))
    with pytest.raises(InvalidArgument):        # no records: the file is read, and is broken
        redecide(run_dir)
    with open(yaml_path, 'w', encoding='utf-8') as f:
        f.write(text)
    assert redecide(run_dir).json_text() == recorded
    data['records'] = {'requirements': {}}
    json.dump(data, open(path, 'w', encoding='utf-8'))
    with pytest.raises(ValueError, match='resolved.json: its records do not read'):
        redecide(run_dir)


@pytest.mark.parametrize('name', ['default_experiment.yaml', 'test_case/pth0_options.yaml',
                                  'test_case/pth0_robustness.yaml',
                                  'parts/binom4_drop_test.yaml'])
def test_the_records_read_back_are_the_records_a_run_held(name):
    file = experiment_file.load(os.path.join(CONFIG, name))
    back = ran.read(json.loads(json.dumps(ran.plain(file.ran))), file.id, file.seed)
    assert (back.id, back.seed, back.requirements, back.cell) == \
        (file.id, file.seed, file.requirements, file.cell)
    assert [(a.name, a.normal, a.quasi_static, a.axis, a.level) for a in back.aspects] == \
        [(a.name, a.normal, a.quasi_static, a.axis, a.level) for a in file.aspects]
    assert all(np.array_equal(a.normals, b.normals) for a, b in zip(back.aspects, file.aspects,
                                                                    strict=True))
    assert len(back.experiments) == len(file.experiments)
    for mine, theirs in zip(back.experiments, file.experiments, strict=True):
        # kept but for what the physics is built from, and a variant's grasps as written
        held = replace(theirs, setup=None, moves=None)
        if hasattr(theirs, 'variants'):
            assert [(v.gripper, v.grasp_set, [g.name for g in v.grasps])
                    for v in mine.variants] == \
                [(v.gripper, v.grasp_set, [g.name for g in v.grasps]) for v in theirs.variants]
            mine, held = replace(mine, variants=()), replace(held, variants=())
        assert mine == held
    assert {e.type for e in back.experiments} == set(experiment_file.TYPES) \
        or name != 'default_experiment.yaml'


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
