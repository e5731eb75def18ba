"""The paper's test case files, a variant of one, and a run of it on the cores in this process:
what the studies (and the benchmarks) share. A study runs from the top of the workspace
(`tools/ws python -m studies.NAME`)."""

import argparse
import os
import sys
import tempfile
import time

from experiment_manager import experiment_file
from experiment_manager.analysis.results import read_csv, ResultsWriter
from experiment_manager.analysis.summary import Summary
from experiment_manager.running.local_backend import LocalBackend
from experiment_manager.running.scheduler import Runner
from pick_sim_world.config import PhysicsConfig
import yaml

TEST_CASE = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'src',
                         'experiment_manager', 'config', 'test_case')


def variant(part_file: str, experiments: list[dict], part: dict | None = None,
            **sections) -> experiment_file.ExperimentFile:
    """TEST_CASE/`part_file` with its experiments replaced by `experiments`, its top-level
    `sections` (e.g. vibration, gripper) by the ones given, and the keys of its part section
    in `part` changed, parsed."""
    path = os.path.join(TEST_CASE, part_file)
    with open(path, encoding='utf-8') as f:
        data = yaml.safe_load(f)
    data.update(sections, experiments=experiments)
    data['part'].update(part or {})
    return experiment_file.parse(yaml.safe_dump(data), path)


def run_on_cores(part_file: str, experiments: list[dict], physics: PhysicsConfig | None = None,
                 **sections) -> tuple[list[dict], float]:
    """Run variant(part_file, experiments, **sections) on the cores with `physics` (the
    world's defaults when None); the rows of iterations.csv and the wall time of the run, s."""
    rows, _, wall = summarise_on_cores(part_file, experiments, physics, **sections)
    return rows, wall


def summarise_on_cores(part_file: str, experiments: list[dict],
                       physics: PhysicsConfig | None = None,
                       **sections) -> tuple[list[dict], Summary, float]:
    """run_on_cores with the run's summary too: the rows, the summary and the wall time,
    s."""
    file = variant(part_file, experiments, **sections)
    with tempfile.TemporaryDirectory() as out:
        start = time.perf_counter()
        summary = run_file(file, out, physics=physics)
        wall = time.perf_counter() - start
        return read_csv(os.path.join(out, 'iterations.csv')), summary, wall


def run_file(file: experiment_file.ExperimentFile, directory: str, workers: int = 1,
             physics: PhysicsConfig | None = None) -> Summary:
    """Run `file` on the cores in this process, on `workers` local workers with `physics`
    (the world's defaults when None), its result files written into `directory`; the
    summary."""
    backends = [LocalBackend(physics) for _ in range(workers)]
    try:
        with ResultsWriter(directory, file.text) as writer:
            return Runner(file, backends, writer).run()
    finally:
        for backend in backends:
            backend.close()


def parse_args(parser: argparse.ArgumentParser, small: list[str],
               argv: list[str] | None = None) -> argparse.Namespace:
    """A study's arguments, with `--small`: the study at the size its smoke test runs it at
    (tests/test_studies.py), `small`'s arguments before the ones given (which win)."""
    parser.add_argument('--small', action='store_true',
                        help=f'a small size, for a smoke test: {" ".join(small)}')
    argv = sys.argv[1:] if argv is None else list(argv)
    return parser.parse_args(small + argv if '--small' in argv else argv)
