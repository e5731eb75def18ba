"""The real `feeder_controller` commanding the real `world` (a tray) over DDS."""

import math
import time

from action_msgs.msg import GoalStatus, GoalStatusArray
from geometry_msgs.msg import Vector3
from graph import NodeProcess, stop_all, unique_namespace
from pick_common.node_runner import LATCHED
from pick_common.rclpy_adapter import LockedActionClient
from pick_msgs.action import FeedCycle, RemoveParts
from pick_msgs.msg import FeederState, Vibration
from pick_msgs.srv import GetParts
import pytest
from rclpy.qos import qos_profile_action_status_default

pytestmark = pytest.mark.graph
NS = unique_namespace('cell_f')
OK = FeedCycle.Result.NONE


@pytest.fixture(scope='module')
def nodes(private_ros_domain):
    world = NodeProcess('pick_sim_world', 'world', [
        '-r', f'__ns:={NS}', '-p', 'container.kind:=tray', '-p', 'publish_markers:=false'])
    feeder = NodeProcess('feeder_controller', 'feeder_controller', ['-r', f'__ns:={NS}'])
    yield world, feeder
    stop_all((world, feeder))


class Feeder:
    def __init__(self, client, nodes) -> None:
        self.c = client
        self.cycle_client = LockedActionClient(client.node, FeedCycle, f'{NS}/feed_cycle')
        self.remove_client = LockedActionClient(client.node, RemoveParts, f'{NS}/remove_parts')
        self.parts_client = client.node.create_client(GetParts, f'{NS}/get_parts')
        self.states = []
        client.node.create_subscription(FeederState, f'{NS}/feeder/state', self.states.append,
                                        LATCHED)
        assert client.wait_for_servers(self.cycle_client, self.remove_client,
                                       self.parts_client, nodes=nodes)

    def _run(self, client, goal):
        handle = self.c.result(client.send_goal_async(goal))
        return self.c.result(handle.get_result_async(), 120.0).result

    def cycle(self, **fields) -> FeedCycle.Result:
        return self._run(self.cycle_client, FeedCycle.Goal(**fields))

    def parts(self) -> list[int]:
        return [p.id for p in self.c.result(self.parts_client.call_async(
            GetParts.Request())).parts.parts]

    def pick(self, part_id: int) -> None:
        assert self._run(self.remove_client, RemoveParts.Goal(part_ids=[part_id])).error_code == 0


def test_a_run_feeds_vibrates_picks_and_stops_at_the_limit(client, nodes):
    feeder = Feeder(client, nodes)
    # One cycle of two moves: a throw of the given stroke, then the world's default vibration
    # (a 1.4 mm flip).
    throw = Vibration(amplitude=Vector3(x=0.001, z=0.001), direction=Vibration.DIRECTION_RANDOM)
    first = feeder.cycle(restart=True, feeder_parts=30, min_count=5, max_count=10,
                         max_vibrations=3, valid_parts=0, parts_on_table=0,
                         moves=[throw, Vibration()])
    assert first.error_code == OK, first.error_msg
    assert first.decision == FeedCycle.Result.DECISION_FEED_AND_VIBRATE and first.parts_fed == 10
    drop, thrown, default = first.reports       # the world's reports of the cycle, in order
    assert drop.tray.amplitude == 0 and thrown.tray.amplitude == pytest.approx(math.hypot(
        0.001, 0.001))
    assert default.tray.amplitude == pytest.approx(0.0014)
    for r in (thrown, default):
        assert abs(r.tray.delivered_amplitude / r.tray.amplitude - 1) < 0.05
    on_table = feeder.parts()
    assert len(on_table) == 10, 'the world has the fed parts'
    assert (first.state.parts_in_feeder, first.state.parts_on_table,
            first.state.vibrations, first.state.feeds) == (20, 10, 1, 1)

    pick = feeder.cycle(valid_parts=2, parts_on_table=10)
    assert pick.decision == FeedCycle.Result.DECISION_PICK
    feeder.pick(on_table[0])
    vibrate = feeder.cycle(valid_parts=0, parts_on_table=9)
    assert vibrate.decision == FeedCycle.Result.DECISION_VIBRATE
    assert vibrate.state.parts_picked == 1 and vibrate.state.vibrations == 2
    feeder.cycle(valid_parts=0, parts_on_table=9)
    stop = feeder.cycle(valid_parts=0, parts_on_table=9)
    assert stop.decision == FeedCycle.Result.DECISION_STOP_VIBRATION_LIMIT
    assert stop.state.state == FeederState.STATE_DONE_VIBRATION_LIMIT
    assert client.wait(lambda: feeder.states and feeder.states[-1].vibrations == 3, 30.0)


def test_impossible_counts_and_bad_ranges_are_refused(client, nodes):
    feeder = Feeder(client, nodes)
    bad = feeder.cycle(restart=True, min_count=40, max_count=30)
    assert bad.error_code == FeedCycle.Result.INVALID_ARGUMENT
    assert 'min_count: 40 must be within [1, 30]' in bad.error_msg
    many = feeder.cycle(restart=True, moves=[Vibration()] * 17)
    assert many.error_code == FeedCycle.Result.INVALID_ARGUMENT
    assert 'moves: 17 moves in one cycle must be at most 16' in many.error_msg
    good = feeder.cycle(restart=True, feeder_parts=5, min_count=2, max_count=3,
                        parts_on_table=0)
    assert good.error_code == OK and good.parts_fed == 3
    more = feeder.cycle(valid_parts=0, parts_on_table=7)
    assert more.error_code == FeedCycle.Result.INVALID_ARGUMENT
    assert 'parts_on_table: 7 must be within [0, 3]' in more.error_msg
    # a hopper's dose: 2 parts a feed, and the fill goes on to max* after the vibration
    dosed = feeder.cycle(restart=True, feeder_parts=5, min_count=2, max_count=3, max_feed=2,
                         parts_on_table=0)
    assert dosed.error_code == OK and dosed.parts_fed == 2 and dosed.state.max_feed == 2
    again = feeder.cycle(valid_parts=0, parts_on_table=2)
    assert again.decision == FeedCycle.Result.DECISION_FEED_AND_VIBRATE and again.parts_fed == 1
    world_error = feeder.cycle(restart=True, parts_on_table=0, instance=5)
    assert world_error.error_code == FeedCycle.Result.UNKNOWN_INSTANCE
    assert 'world drop_parts: instances: 5 does not exist' in world_error.error_msg


@pytest.mark.parametrize('restarted', [False, True], ids=['gone', 'started again'])
def test_a_world_that_dies_mid_cycle_gets_an_error_answer_not_a_hang(client, restarted):
    """Also when a new world serves the same names at once (as `run` restarts it): the goal
    went to the dead one, which never answers."""
    ns = unique_namespace('cell_f_dies')
    args = ['-r', f'__ns:={ns}', '-p', 'container.kind:=tray', '-p', 'publish_markers:=false']
    world = NodeProcess('pick_sim_world', 'world', args)
    feeder = NodeProcess('feeder_controller', 'feeder_controller', ['-r', f'__ns:={ns}'])
    try:
        cycle = LockedActionClient(client.node, FeedCycle, f'{ns}/feed_cycle')
        assert client.wait_for_servers(cycle, nodes=(world, feeder))
        # A big feed, killed while the world drops it (its drop_parts goal is executing: a
        # world killed before the feeder's goal reached it is another case, the one below)
        executing = []
        client.node.create_subscription(
            GoalStatusArray, f'{ns}/drop_parts/_action/status',
            lambda m: executing.extend(s for s in m.status_list
                                       if s.status == GoalStatus.STATUS_EXECUTING),
            qos_profile_action_status_default)
        handle = client.result(cycle.send_goal_async(FeedCycle.Goal(
            restart=True, feeder_parts=1000, min_count=700, max_count=700)))
        result_future = handle.get_result_async()
        assert client.wait(lambda: executing, 60.0)
        assert not result_future.done()
        world.process.kill()
        killed = time.monotonic()
        if restarted:
            world = NodeProcess('pick_sim_world', 'world', args)
        # A killed node leaves the graph when its DDS lease ends (Fast DDS: 20 s), then 2 s.
        result = client.result(result_future, 60.0).result
        print(f'the feeder answered {time.monotonic() - killed:.1f} s after the kill')
        assert result.error_code == FeedCycle.Result.INTERNAL
        assert "'drop_parts' left the graph while answering" in result.error_msg
        again = client.result(client.result(cycle.send_goal_async(FeedCycle.Goal(
            restart=True, feeder_parts=10, min_count=2, max_count=4))).get_result_async(),
            60.0).result
        if restarted:
            assert again.error_code == FeedCycle.Result.NONE, again.error_msg
        else:
            assert again.error_code == FeedCycle.Result.INTERNAL    # not BUSY: the lock is free
            assert 'is the world node running there?' in again.error_msg
    finally:
        world.stop()
        assert feeder.stop() == 0, feeder.output()
