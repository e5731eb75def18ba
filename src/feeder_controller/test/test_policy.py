"""The optimal-range policy, step by step and over whole simulated runs."""

from feeder_controller.policy import (
    FEED_AND_VIBRATE,
    FeederConfig,
    FeederPolicy,
    PICK,
    STOP_EMPTY,
    STOP_VIBRATION_LIMIT,
    VIBRATE,
)
import numpy as np
from pick_common.errors import InvalidArgument
import pytest


def _run(policy: FeederPolicy, valid_of, limit: int = 10_000) -> list[int]:
    """Drive a run: valid_of(on_table) says how many parts are valid; picks remove one."""
    decisions = []
    on_table = 0
    for _ in range(limit):
        step = policy.decide(valid_of(on_table), on_table)
        decisions.append(step.decision)
        if step.decision == PICK:
            on_table -= 1
        if step.feed:
            policy.fed(step.feed)
            on_table += step.feed
        if step.vibrates:
            policy.vibrated()
        if step.decision in (STOP_EMPTY, STOP_VIBRATION_LIMIT):
            return decisions
    raise AssertionError('the run did not stop')


def test_first_step_fills_the_table_to_max_and_vibrates():
    policy = FeederPolicy(FeederConfig(feeder_parts=100, min_count=20, max_count=30))
    step = policy.decide(0, 0)
    assert step.decision == FEED_AND_VIBRATE and step.feed == 30


def test_pick_when_valid_vibrate_within_range_feed_below_it():
    policy = FeederPolicy(FeederConfig(feeder_parts=100, min_count=20, max_count=30))
    policy.decide(0, 0)
    policy.fed(30)
    policy.vibrated()
    assert policy.decide(3, 30).decision == PICK
    assert policy.decide(0, 29).decision == VIBRATE
    assert policy.decide(0, 20).decision == VIBRATE        # min* is within the range
    step = policy.decide(0, 19)
    assert step.decision == FEED_AND_VIBRATE and step.feed == 11
    assert policy.state.picked == 11


def test_a_dosed_feed_fills_the_table_over_several_vibrations():
    policy = FeederPolicy(FeederConfig(feeder_parts=100, min_count=20, max_count=30,
                                       max_feed=12))
    fed = []
    on_table = 0
    while (step := policy.decide(0, on_table)).decision == FEED_AND_VIBRATE:
        policy.fed(step.feed)
        policy.vibrated()
        on_table += step.feed
        fed.append(step.feed)
    # up to max* as without a dose, 12 parts a feed, a vibration after each
    assert fed == [12, 12, 6] and step.decision == VIBRATE and on_table == 30
    step = policy.decide(0, 15)
    assert step.decision == FEED_AND_VIBRATE and step.feed == 12     # not the 15 short
    policy.fed(12)
    assert policy.decide(1, 27).decision == PICK        # a valid part is picked first
    step = policy.decide(0, 26)                         # then the filling goes on to max*
    assert step.decision == FEED_AND_VIBRATE and step.feed == 4


def test_an_empty_feeder_feeds_what_it_has_then_only_vibrates():
    policy = FeederPolicy(FeederConfig(feeder_parts=35, min_count=20, max_count=30))
    policy.decide(0, 0)
    policy.fed(30)
    step = policy.decide(0, 10)
    assert step.decision == FEED_AND_VIBRATE and step.feed == 5
    policy.fed(5)
    assert policy.decide(0, 10).decision == VIBRATE
    assert policy.decide(0, 0).decision == STOP_EMPTY


def test_a_run_where_every_part_becomes_valid_empties_the_feeder():
    policy = FeederPolicy(FeederConfig(feeder_parts=200, min_count=22, max_count=27,
                                       max_vibrations=10_000))
    rng = np.random.default_rng(0)
    decisions = _run(policy, lambda n: min(n, int(rng.integers(0, 3))))
    assert decisions[-1] == STOP_EMPTY
    assert policy.state.picked == 200 and decisions.count(PICK) == 200
    assert policy.state.in_feeder == 0 and policy.state.on_table == 0


def test_the_vibration_limit_stops_a_run_that_finds_no_valid_part():
    policy = FeederPolicy(FeederConfig(feeder_parts=50, min_count=5, max_count=10,
                                       max_vibrations=7))
    decisions = _run(policy, lambda n: 0)
    assert decisions[-1] == STOP_VIBRATION_LIMIT and policy.state.vibrations == 7


@pytest.mark.parametrize(('config', 'rule'), [
    (FeederConfig(min_count=40, max_count=30), r'min_count: 40 must be within \[1, 30\]'),
    (FeederConfig(feeder_parts=0), r'feeder_parts: 0 must be within'),
    (FeederConfig(max_count=0), r'max_count: 0 must be within'),
    (FeederConfig(max_vibrations=-1), r'max_vibrations: -1 must be within'),
    (FeederConfig(max_feed=-2), r'max_feed: -2 must be within'),
])
def test_bad_configurations_are_refused(config, rule):
    with pytest.raises(InvalidArgument, match=rule):
        FeederPolicy(config)


def test_counts_that_cannot_be_true_are_refused():
    policy = FeederPolicy(FeederConfig(feeder_parts=100, min_count=20, max_count=30))
    with pytest.raises(InvalidArgument, match=r'parts_on_table: 5 must be within \[0, 0\]'):
        policy.decide(0, 5)
    policy.decide(0, 0)
    policy.fed(30)
    with pytest.raises(InvalidArgument, match=r'valid_parts: 31 must be within \[0, 30\]'):
        policy.decide(31, 30)
    with pytest.raises(InvalidArgument, match=r'fed: 80 must be within \[1, 70\]'):
        policy.fed(80)
