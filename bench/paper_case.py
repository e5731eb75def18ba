"""The paper's test case files, and a variant of one run on the cores in this process, for the
benchmarks (run them as `tools/ws python bench/NAME.py`: this directory is on the path)."""

import os
import tempfile
import time

from experiment_manager import config
from experiment_manager.experiments import Runner
from experiment_manager.local_backend import LocalBackend
from experiment_manager.results import read_csv, ResultsWriter
import yaml

TEST_CASE = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'src',
                         'experiment_manager', 'config', 'test_case')


def run_on_cores(part_file: str, experiments: list[dict],
                 **sections) -> tuple[list[dict], float]:
    """Run TEST_CASE/`part_file` with its experiments replaced by `experiments` and its
    top-level `sections` (e.g. vibration) by the ones given, on the cores; the rows of
    iterations.csv and the wall time of the run, s."""
    path = os.path.join(TEST_CASE, part_file)
    with open(path, encoding='utf-8') as f:
        data = yaml.safe_load(f)
    data.update(sections, experiments=experiments)
    file = config.parse(yaml.safe_dump(data), path)
    with tempfile.TemporaryDirectory() as out:
        start = time.perf_counter()
        with LocalBackend() as backend, ResultsWriter(out, file.text) as writer:
            Runner(file, [backend], writer).run()
        wall = time.perf_counter() - start
        return read_csv(os.path.join(out, 'iterations.csv')), wall
