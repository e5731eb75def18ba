"""The race of rclpy's ActionClient when a goal is sent from one thread while another spins it:
the answer can be handled before the request's future is registered, and the goal then waits
for ever. The window is widened here by a send that pauses after the request is out; the plain
ActionClient loses the answer (rclpy 7.1.6; when an rclpy update fixes it, that case fails and
LockedActionClient can go), the manager's LockedActionClient does not."""

import time

from graph import spun_node, WrappedHandle
from pick_common.rclpy_adapter import LockedActionClient
from pick_msgs.action import DropParts
import pytest
from rclpy.action import ActionClient, ActionServer


class SlowToRegister(WrappedHandle):
    """Pauses after each goal request is sent: the answer arrives and is taken by the spinning
    thread before send_goal_async registers the request."""

    def send_goal_request(self, request):
        sequence = self._handle.send_goal_request(request)
        time.sleep(0.3)
        return sequence


@pytest.mark.parametrize('client_type, answered', [(ActionClient, False),
                                                   (LockedActionClient, True)])
def test_a_goal_sent_while_another_thread_spins_gets_its_answer(client_type, answered,
                                                                private_ros_domain):
    def execute(goal_handle):
        goal_handle.succeed()
        return DropParts.Result()

    with spun_node('action_race', lambda node: (
            ActionServer(node, DropParts, 'race_drop', execute_callback=execute),
            client_type(node, DropParts, 'race_drop'))) as (_, client):
        try:
            assert client.wait_for_server(timeout_sec=10.0)
            client._client_handle = SlowToRegister(client._client_handle)
            future = client.send_goal_async(DropParts.Goal(count=1))
            deadline = time.monotonic() + 3.0
            while not future.done() and time.monotonic() < deadline:
                time.sleep(0.01)
            assert future.done() == answered
        finally:
            WrappedHandle.unwrap(client)
