"""Each study of studies/ runs and prints what its docstring promises: a study that docs/ cites
must still run. The studies of finished runs run on a small recorded run, made here on the
cores (no graph): the experiment manager's small file without its gripper sweep, once
adaptively (the replays need a run's looks) and once at fixed counts (compare_runs needs two
runs of the same seeds); the physics studies at their small size (`--small`)."""

import ast
import os
import re
import subprocess
import sys

from experiment_manager import experiment_file
from experiment_manager.analysis.results import ResultsWriter
from experiment_manager.running.local_backend import LocalBackend
from experiment_manager.running.scheduler import Runner
import pytest

TOP = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..')
SMALL = os.path.join(TOP, 'src', 'experiment_manager', 'test', 'small_experiment.yaml')


@pytest.fixture(scope='module')
def runs(tmp_path_factory) -> dict[str, str]:
    """{'adaptive': run directory, 'fixed': run directory} of the small file's bins, bin
    emptying, sweep and feeder."""
    with open(SMALL, encoding='utf-8') as f:
        text = f.read().split('  - {id: grippers')[0]
    out = {}
    for mode in ('adaptive', 'fixed'):
        file = experiment_file.parse(text + f'sampling: {{mode: {mode}, batch: 2}}\n', SMALL)
        directory = str(tmp_path_factory.mktemp(mode))
        with LocalBackend() as backend, ResultsWriter(directory, file.text) as sink:
            Runner(file, [backend], sink).run()
        out[mode] = directory
    return out


def _study(*args: str) -> str:
    done = subprocess.run([sys.executable, '-m', *args], cwd=TOP, capture_output=True,
                          text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    return done.stdout


def test_run_stages_says_where_parts_were_turned_down(runs):
    out = _study('studies.run_stages', runs['fixed'])
    assert 'bins (bin_static)' in out and 'feeder (feeder_emptying)' in out, out
    assert 'per check: checked' in out


def test_compare_runs_sets_two_runs_side_by_side_on_their_seeds(runs, tmp_path):
    picture = str(tmp_path / 'compare.png')
    out = _study('studies.compare_runs', runs['fixed'], runs['adaptive'], '--picture', picture)
    assert 'emptied' in out and os.path.basename(runs['fixed']) in out, out
    with open(picture, 'rb') as f:
        assert f.read(8) == b'\x89PNG\r\n\x1a\n'


def test_replay_decisions_prices_an_adaptive_runs_decisions(runs):
    out = _study('studies.replay_decisions', runs['adaptive'])
    assert 'in all:' in out and 'worker-min replayed against' in out, out
    assert 'bins:' in out and 'feeder:' in out


def test_replay_race_replays_the_bins_race(runs):
    out = _study('studies.replay_race', runs['adaptive'])
    assert 'best bin' in out and 'looks' in out, out


def test_sweep_sampling_replays_a_sweeps_looks_two_ways(runs):
    out = _study('studies.sweep_sampling', runs['fixed'], '--orders', '3', '--batch', '1')
    assert 'a batch at every count: settled' in out and 'placed where n* narrows most' in out, out


def test_feeder_decisions_tables_decisions_on_few_runs(runs, tmp_path):
    out = _study('studies.feeder_decisions', 'table', runs['fixed'], '--draws', '20')
    assert "time to the table's decision" in out, out
    picture = str(tmp_path / 'fit.png')
    assert _study('studies.feeder_decisions', 'plot', runs['fixed'], '--out',
                  picture).strip() == picture
    written = _study('studies.feeder_decisions', 'files', str(tmp_path / 'files')).split()
    assert [os.path.basename(p) for p in written] == [
        'feeder_pth0.yaml', 'feeder_pth1.yaml', 'feeder_pth2.yaml']
    for path in written:
        experiment_file.load(path)      # what it writes is a file a run reads


def test_drop_tests_set_published_drops_beside_the_simulation(tmp_path):
    picture = str(tmp_path / 'drops.png')
    out = _study('studies.drop_tests', '--drops', '64', '--only', 'murray_thick', 'binom4',
                 '--figure', picture)
    assert 'murray_thick (' in out and 'binom4 (' in out and 'G-test p' in out, out
    assert out.count('measured') >= 7 and 'quasi-static' in out
    with open(picture, 'rb') as f:
        assert f.read(8) == b'\x89PNG\r\n\x1a\n'


def test_feeder_landing_measures_the_pile_after_every_feed():
    out = _study('studies.feeder_landing', '--part', 'pth0.yaml', '--runs', '1', '--parts',
                 '30', '--range', '10,20', '--set-back-mm', '10', '--max-feed', '8')
    assert ("pth0.yaml: at most 8 parts a feed, the file's cycle, hopper lip 30 mm, 10 parts/s "
            'at 100 mm/s') in out
    # the zone moved 10 mm off the -X wall, its far edge kept
    assert 'feeder zone at -68.12, 0.00 mm, 38.75 x 120.00 mm, walls 27 mm' in out
    assert re.search(r'feeds let out \d+ of the \d+ parts asked', out)
    assert ' feeds: pile top median ' in out and "parts over a wall's top after a feed" in out
    assert 'spilled per run: ' in out and '  spills: ' in out and '  time: ' in out


# The physics studies docs/physics.md cites, each at its small size (`--small`: a few parts and
# one seed), and a line of the figures it prints: a study a page cites is one that still runs.
PHYSICS = [
    ('moves', 'toward centre mm'), ('roll', 'valid at'), ('gripper_stages', 'valid per scene'),
    ('feeds', '| pth0 | 10 | 1 |'), ('lean', '| 1/480 s |'), ('creep', 'settled'),
    ('spills', 'default: spilled'), ('throws', 'moves with a thrown part'),
    ('standing', 'head down/side/leaning/on leads'), ('convergence', '| default |'),
    ('answers', 'valid at 40'), ('vibration', 'valid per check'),
    ('part_files', 'on the tray, 2 seeds'),
]


@pytest.mark.parametrize('study, line', PHYSICS, ids=[s for s, _ in PHYSICS])
def test_a_physics_study_runs_at_its_small_size_and_prints_its_figures(study, line):
    out = _study(f'studies.{study}', '--small')
    assert line in out, out


def _benchmarks_imported(text: str) -> list[str]:
    tree = ast.parse(text)
    imported = [n.module or '' for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)]
    imported += [a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names]
    return [m for m in imported if m.split('.')[0] == 'bench']


def test_no_study_imports_a_benchmark():
    for name in sorted(os.listdir(os.path.join(TOP, 'studies'))):
        if name.endswith('.py'):
            with open(os.path.join(TOP, 'studies', name), encoding='utf-8') as f:
                assert not _benchmarks_imported(f.read()), name
    # the check can fail: an import of a benchmark, lazy too, is seen; its words are not
    assert _benchmarks_imported('"""from bench/ ..."""\ndef f():\n    from bench import x\n')
    assert not _benchmarks_imported('"""Apart\nfrom bench/, which times."""\n')
