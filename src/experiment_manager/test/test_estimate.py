"""The time left of a run: iterations weighed by what their experiment, their type or all
finished iterations cost per part, not counted."""

import os

from experiment_manager import experiment_file
from experiment_manager.experiment_file.plan import count_iterations, experiment_iterations
from experiment_manager.running.estimate import Costs, mean_units, TYPE_WEIGHT
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


def test_nothing_finished_means_unknown(small):
    by_id, _ = small
    assert Costs().left([(by_id['feeder'], 1)], workers=2) == 0.0


def test_iterations_left_are_weighed_by_their_cost_not_counted(small):
    by_id, _ = small
    sweep, feeder = by_id['sweep'], by_id['feeder']
    costs = Costs()
    for n in sweep.counts:                  # 2..14 parts, 0.1 s per part
        costs.add(sweep, n, 0.1 * n)
    # A feeder run not timed yet: taken at the rate of all (0.1 s per part) times its parts,
    # weighed as a feeder run's part (TYPE_WEIGHT).
    assert costs.left([(feeder, 1)], workers=1) == pytest.approx(
        0.1 * feeder.parts * TYPE_WEIGHT['feeder_emptying'])
    # Once one has run (30 s for 12 parts), the other takes what it took: counting
    # iterations would say 0.8 s, the sweep's mean.
    costs.add(feeder, feeder.parts, 30.0)
    assert costs.left([(feeder, 1)], workers=1) == pytest.approx(30.0)
    # the sweep's own rate for its iterations left (mean 8 parts), spread over two workers
    assert costs.left([(sweep, 4), (feeder, 1)], workers=2) == pytest.approx(
        (4 * 0.1 * mean_units(sweep) + 30.0) / 2)
    assert mean_units(sweep) == pytest.approx(8.0)


def test_a_gripper_sweep_costs_its_parts_times_its_grippers(small):
    by_id, _ = small
    grippers, emptying = by_id['grippers'], by_id['emptying']
    costs = Costs()
    costs.add(emptying, emptying.parts, 3.0)          # 0.1 s per part
    assert mean_units(grippers) == grippers.parts * len(grippers.variants)
    assert costs.left([(grippers, 2)], workers=1) == pytest.approx(
        2 * 0.1 * grippers.parts * len(grippers.variants))
