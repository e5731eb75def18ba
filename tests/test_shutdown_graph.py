"""Every node stops cleanly on SIGINT and on SIGTERM, also with work in flight: exit code 0 and
no native crash, many times over. (Under launch, `world` once died with SIGSEGV in librcl on
SIGINT: issue 24.)"""

import signal

from graph import NodeProcess, unique_namespace
from pick_msgs.action import DropParts, FeedCycle
from pick_msgs.srv import CheckParts
import pytest
from rclpy.action import ActionClient

pytestmark = pytest.mark.graph
ROUNDS = 4                      # starts and stops per node and signal
SIGNALS = pytest.mark.parametrize('signum', [signal.SIGINT, signal.SIGTERM],
                                  ids=['SIGINT', 'SIGTERM'])
WORLD = ['-p', 'container.kind:=tray', '-p', 'publish_markers:=false']


def _stopped(proc: NodeProcess, signum: int) -> None:
    proc.process.send_signal(signum)
    code = proc.process.wait(30)
    assert code == 0, f'{proc.describe_exit()} on {signal.Signals(signum).name}:\n' \
        f'{proc.output(tail=40)}'
    assert 'Fatal Python error' not in proc.output()


def _in_flight(client, future) -> None:
    """Wait until the goal was accepted and its result is still to come."""
    handle = client.result(future)
    assert handle.accepted
    assert not handle.get_result_async().done()


@SIGNALS
def test_the_world_stops_cleanly_while_it_drops_parts(client, signum):
    for k in range(ROUNDS):
        ns = unique_namespace(f'stop_world_{signum}_{k}')
        world = NodeProcess('pick_sim_world', 'world', ['-r', f'__ns:={ns}', *WORLD])
        try:
            drop = ActionClient(client.node, DropParts, f'{ns}/drop_parts')
            assert client.wait_for_servers(drop, nodes=(world,))
            # 300 parts stream in layers for seconds of wall time: stopped mid-operation.
            _in_flight(client, drop.send_goal_async(DropParts.Goal(count=300)))
            _stopped(world, signum)
        finally:
            world.stop()
            drop.destroy()


@SIGNALS
def test_the_feeder_controller_stops_cleanly_while_a_cycle_runs(client, signum):
    for k in range(ROUNDS):
        ns = unique_namespace(f'stop_feeder_{signum}_{k}')
        world = NodeProcess('pick_sim_world', 'world', ['-r', f'__ns:={ns}', *WORLD])
        feeder = NodeProcess('feeder_controller', 'feeder_controller', ['-r', f'__ns:={ns}'])
        cycle = ActionClient(client.node, FeedCycle, f'{ns}/feed_cycle')
        try:
            assert client.wait_for_servers(cycle, nodes=(world, feeder))
            # A big feed: the cycle waits on the world's drop when the signal comes.
            _in_flight(client, cycle.send_goal_async(FeedCycle.Goal(
                restart=True, feeder_parts=1000, min_count=300, max_count=300)))
            _stopped(feeder, signum)
        finally:
            feeder.stop()
            cycle.destroy()
            assert world.stop() == 0, world.output(tail=40)


@SIGNALS
def test_the_validity_node_stops_cleanly(client, signum):
    for k in range(ROUNDS):
        ns = unique_namespace(f'stop_validity_{signum}_{k}')
        validity = NodeProcess('pick_validity', 'validity', ['-r', f'__ns:={ns}'])
        check = client.node.create_client(CheckParts, f'{ns}/check_parts')
        try:
            assert client.wait_for_servers(check, nodes=(validity,))
            _stopped(validity, signum)
        finally:
            validity.stop()
            client.node.destroy_client(check)
