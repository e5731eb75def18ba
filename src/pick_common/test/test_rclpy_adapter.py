"""What pick_common.rclpy_adapter relies on below rclpy's public API, checked against the rclpy
installed: a change of rclpy that moves any of it fails here, and the adapter must be read
again (tests/test_action_race.py then shows whether the race it closes is still there)."""

import importlib.metadata
import inspect

from pick_common import rclpy_adapter
from pick_common.node_runner import endpoint_name
from pick_msgs.action import DropParts
import pytest
import rclpy
from rclpy.action import ActionClient
from rclpy.action.client import ClientGoalHandle
from rclpy.context import Context
from rclpy.node import Node

PINNED = '7.1.6'    # constraints.txt: ros-rclpy, the version the adapter was read against


def test_the_installed_rclpy_is_the_one_the_adapter_was_read_against():
    assert importlib.metadata.version('ros-rclpy') == PINNED


def test_goal_handles_still_ask_the_client_s_private_methods_that_the_lock_wraps():
    # LockedActionClient locks these two; if a goal handle stopped calling them, its results
    # and cancels would go unlocked without an error anywhere.
    assert 'self._action_client._get_result_async(self)' in inspect.getsource(
        ClientGoalHandle.get_result_async)
    assert 'self._action_client._cancel_goal_async(self)' in inspect.getsource(
        ClientGoalHandle.cancel_goal_async)
    for name in ('_get_result_async', '_cancel_goal_async'):
        assert list(inspect.signature(getattr(ActionClient, name)).parameters) == [
            'self', 'goal_handle']
    assert inspect.iscoroutinefunction(ActionClient.execute)


def test_rcl_errors_are_the_binding_s_rclerror():
    # rcl refusing its arguments, as a user's bad --ros-args: the runner's one-line error
    with pytest.raises(rclpy_adapter.RCLError, match='failed to initialize rcl'):
        rclpy.init(args=['node', '--ros-args', '--log-level', 'nonsense'], context=Context())


def test_an_action_client_s_name_is_public_and_a_plain_one_is_refused():
    context = Context()
    rclpy.init(context=context)
    try:
        node = Node('names', context=context)
        locked = rclpy_adapter.LockedActionClient(node, DropParts, 'drop_parts')
        assert endpoint_name(locked) == 'drop_parts'
        with pytest.raises(TypeError, match='LockedActionClient'):
            endpoint_name(ActionClient(node, DropParts, 'drop_parts'))
        node.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)
