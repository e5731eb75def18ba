"""Fixtures of the experiment manager's tests: running the small experiment file on the cores."""

import os

from experiment_manager import experiment_file
from experiment_manager.analysis.results import ResultsWriter
from experiment_manager.analysis.summary import Summary
from experiment_manager.experiment_file import resolved
from experiment_manager.running.local_backend import LocalBackend
from experiment_manager.running.scheduler import Runner
import pytest

SMALL = os.path.join(os.path.dirname(__file__), 'small_experiment.yaml')


def run_small(directory: str, resume: bool = False) -> Summary:
    """Run the small file on the cores (LocalBackend) into `directory`, with its resolved.json
    as a run writes it; returns the summary."""
    file = experiment_file.load(SMALL)
    with LocalBackend() as backend, ResultsWriter(directory, file.text, resume) as writer:
        if not resume:
            resolved.write(file, directory)
        return Runner(file, [backend], writer).run()


@pytest.fixture(scope='session')
def run_file():
    return run_small


@pytest.fixture(scope='session')
def small(tmp_path_factory) -> tuple[str, Summary]:
    """The small file run once: (run directory, summary)."""
    directory = str(tmp_path_factory.mktemp('small'))
    return directory, run_small(directory)
