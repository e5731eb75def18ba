"""What rclpy answers when a goal's result is asked for after its server dropped the goal, and
that the workspace's clients take it as an error (node_runner.goal_result), not as a success.

rclpy's ActionServer keeps a finished goal for its result_timeout (ours: RESULT_KEEP) and
answers a later result request with status UNKNOWN and an empty result: its error_code 0 is
our NONE, so read as it comes it is a success with no parts and no settle report."""

import threading
import time

from action_msgs.msg import GoalStatus
from graph import spun_node
from pick_common.errors import CodedError
from pick_common.node_runner import goal_result
from pick_common.rclpy_adapter import LockedActionClient
from pick_msgs.action import RemoveParts
import pytest
from rclpy.action import ActionServer

KEEP = 0.5          # s the test's server keeps a finished goal
WAIT = 30.0         # s for each answer (a busy machine is slow, never this slow)


def test_a_result_asked_for_after_the_server_dropped_the_goal_is_an_error(private_ros_domain):
    def execute(goal_handle):
        goal_handle.succeed()
        return RemoveParts.Result(removed_ids=[7])

    with spun_node('action_result', lambda node: (
            ActionServer(node, RemoveParts, 'result_remove', execute_callback=execute,
                         result_timeout=KEEP),
            LockedActionClient(node, RemoveParts, 'result_remove'))) as (_, client):
        assert client.wait_for_server(timeout_sec=WAIT)
        sent = client.send_goal_async(RemoveParts.Goal(part_ids=[7]))
        assert _done(sent), 'no answer to the goal'
        handle = sent.result()
        assert handle.accepted
        asked = handle.get_result_async()       # asked at once: the result itself
        assert _done(asked)
        assert asked.result().status == GoalStatus.STATUS_SUCCEEDED
        assert list(goal_result(asked.result(), 'remove_parts').removed_ids) == [7]
        # the server drops the goal KEEP s after it ended (it publishes no status then): ask
        # again until it answers otherwise, each ask an answer waited for
        deadline = time.monotonic() + WAIT
        while True:
            late = handle.get_result_async()
            assert _done(late)
            answer = late.result()
            if answer.status != GoalStatus.STATUS_SUCCEEDED or time.monotonic() > deadline:
                break
        assert answer.status == GoalStatus.STATUS_UNKNOWN
        assert answer.result.error_code == 0 and not list(answer.result.removed_ids)
        with pytest.raises(CodedError, match='remove_parts: the server no longer had the goal'):
            goal_result(answer, 'remove_parts')


def test_goal_result_passes_the_result_of_every_terminal_status():
    for status in (GoalStatus.STATUS_SUCCEEDED, GoalStatus.STATUS_ABORTED,
                   GoalStatus.STATUS_CANCELED):
        response = RemoveParts.Impl.GetResultService.Response(
            status=status, result=RemoveParts.Result(error_code=5, error_msg='x'))
        assert goal_result(response, 'remove_parts').error_code == 5


def _done(future) -> bool:
    event = threading.Event()
    future.add_done_callback(lambda _: event.set())
    return event.wait(WAIT)
