"""GraphBackend, the manager's side of a worker, against real node processes over DDS."""

import threading
import uuid

from experiment_manager import experiment_file
from experiment_manager.graph.graph_backend import GraphBackend, WorkerGone
from graph import NodeProcess, SMALL, stop_all, unique_namespace, WrappedHandle
import pytest
import rclpy
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.context import Context
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node

pytestmark = pytest.mark.graph
NS = unique_namespace('cell_b')
WORLD_ARGS = ['-r', f'__ns:={NS}', '-p', 'publish_markers:=false']


@pytest.fixture
def backend(private_ros_domain):
    """A worker's three nodes, and a GraphBackend on a node spun by another thread (as in the
    manager, whose worker threads call while its executor spins)."""
    procs = [NodeProcess('pick_sim_world', 'world', WORLD_ARGS),
             NodeProcess('pick_validity', 'validity', ['-r', f'__ns:={NS}']),
             NodeProcess('feeder_controller', 'feeder_controller', ['-r', f'__ns:={NS}'])]
    context = Context()
    rclpy.init(context=context)
    node = Node('test_backend', context=context)
    executor = MultiThreadedExecutor(num_threads=2, context=context)
    executor.add_node(node)
    spinner = threading.Thread(target=executor.spin, daemon=True)
    spinner.start()
    graph = GraphBackend(node, NS, ReentrantCallbackGroup(), call_timeout=120.0,
                         server_timeout=60.0, canceled=lambda: False, rejoin_timeout=60.0)
    graph.start(experiment_file.load(SMALL))
    try:
        yield graph, procs
    finally:
        graph.destroy()
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown(context=context)
        stop_all(procs)


def test_a_world_started_again_between_two_calls_ends_the_iteration(backend):
    """`run` restarts a dead node at once: the next call of the iteration would be answered by
    a world without the iteration's parts. It must end the iteration (WorkerGone: it runs
    again), not go on with an empty scene."""
    graph, procs = backend
    bin_spec = experiment_file.load(SMALL).experiment('bins').bins[0]
    graph.reset(bin_spec, seed=5)
    states, _ = graph.drop(10, 'container')
    assert len(states.ids) == 10
    assert procs[0].stop() == 0       # SIGINT: its endpoints leave the graph at once
    procs[0] = NodeProcess('pick_sim_world', 'world', WORLD_ARGS)
    assert graph.rejoin(lambda: False), 'the world started again did not come back'
    with pytest.raises(WorkerGone, match='get_parts: .*get_parts.* of this iteration left'):
        graph.parts()
    # A new iteration begins with the servers there now, and goes on normally.
    graph.reset(bin_spec, seed=5)
    again, _ = graph.drop(10, 'container')
    assert again.poses.tolist() == states.poses.tolist()


class AskingForAnotherGoal(WrappedHandle):
    """Asks for the result of a goal id the server never had: what it answers a goal it
    dropped after result_timeout (tests/test_action_result.py)."""

    def send_result_request(self, request):
        request.goal_id.uuid = list(uuid.uuid4().bytes)
        return self._handle.send_result_request(request)


def test_a_result_the_world_no_longer_had_ends_the_iteration(backend):
    """The world did the operation, but its answer is an empty result (status UNKNOWN) that
    would read as a success with no parts: the iteration must run again (WorkerGone)."""
    graph, _ = backend
    graph.reset(experiment_file.load(SMALL).experiment('bins').bins[0], seed=5)
    states, _ = graph.drop(3, 'container')
    client = graph._remove
    client._client_handle = AskingForAnotherGoal(client._client_handle)
    try:
        with pytest.raises(WorkerGone, match='remove_parts: the server no longer had the goal'):
            graph.remove([int(states.ids[0])])
    finally:
        WrappedHandle.unwrap(client)
