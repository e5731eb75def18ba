"""The time left of a run: iterations weighed by what their experiment, their type or all
finished iterations cost per part, not counted."""

import os

from experiment_manager import experiment_file
from experiment_manager.experiment_file.plan import count_iterations, experiment_iterations
from experiment_manager.running.estimate import Costs, mean_units, PRIOR
import pytest

SMALL = os.path.join(os.path.dirname(__file__), 'small_experiment.yaml')


@pytest.fixture(scope='module')
def small():
    file = experiment_file.load(SMALL)
    return {e.id: e for e in file.experiments}, file


def test_the_iterations_of_each_experiment_add_up_to_the_run(small):
    by_id, file = small
    assert [experiment_iterations(e) for e in file.experiments] == [4, 1, 8, 1, 2]
    assert sum(experiment_iterations(e) for e in file.experiments) == count_iterations(file)


def test_before_anything_finished_the_measured_prior_says_it(small):
    by_id, _ = small
    feeder = by_id['feeder']
    assert Costs().left([(feeder, 1)], workers=2) == pytest.approx(
        PRIOR['feeder_emptying'] * feeder.parts)
    assert Costs().left([], workers=2) == 0.0


def test_iterations_left_are_weighed_by_their_cost_not_counted(small):
    by_id, _ = small
    sweep, feeder = by_id['sweep'], by_id['feeder']
    costs = Costs()
    for n in sweep.counts:                  # 2..14 parts, twice the sweep's PRIOR per part
        costs.add(sweep, n, 2 * PRIOR['table_sweep'] * n)
    # A feeder run not timed yet: its type's PRIOR, scaled as the sweep ran against its own
    # (twice as slow here: another machine, a heavier part).
    assert costs.left([(feeder, 1)], workers=1) == pytest.approx(
        2 * PRIOR['feeder_emptying'] * feeder.parts)
    # Once one has run (30 s), the other takes what it took: counting iterations would say
    # the sweep's mean.
    costs.add(feeder, feeder.parts, 30.0)
    assert costs.left([(feeder, 1)], workers=1) == pytest.approx(30.0)
    # the sweep's own rate for its iterations left (mean 8 parts), spread over two workers,
    # but never less than the dearest iteration left: one feeder run is not split
    sweep_left = 4 * 2 * PRIOR['table_sweep'] * mean_units(sweep)
    assert costs.left([(sweep, 4), (feeder, 1)], workers=2) == pytest.approx(
        max((sweep_left + 30.0) / 2, 30.0))
    assert mean_units(sweep) == pytest.approx(8.0)


def test_a_gripper_sweep_costs_its_parts_times_its_grippers(small):
    by_id, _ = small
    grippers, emptying = by_id['grippers'], by_id['emptying']
    costs = Costs()
    costs.add(emptying, emptying.parts, emptying.parts * PRIOR['bin_emptying'])   # as PRIOR
    assert mean_units(grippers) == grippers.parts * len(grippers.variants)
    assert costs.left([(grippers, 2)], workers=1) == pytest.approx(
        2 * PRIOR['gripper_sweep'] * grippers.parts * len(grippers.variants))
