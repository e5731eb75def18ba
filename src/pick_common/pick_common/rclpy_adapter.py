"""The one place where the workspace relies on rclpy below its public API, each use with why.
rclpy Jazzy (7.1.6, pinned by constraints.txt) offers no public way to do these; the test
test_rclpy_adapter.py fails when the pinned rclpy changes underneath them, and
tests/test_action_race.py shows the race LockedActionClient closes.

- `RCLError`: rcl's failures (a context shut down under a call, a node rcl refuses) raise the
  binding's RCLError, which rclpy Jazzy exports nowhere else; the node runner must tell them
  from other errors.
- `LockedActionClient`: rclpy's ActionClient with its name public (rclpy keeps the name it
  was given only as `_action_name`) and its requests locked against a race, which means
  overriding the two private methods its goal handles call (`_get_result_async`,
  `_cancel_goal_async`).
"""

import threading

from rclpy.action import ActionClient
from rclpy.impl.implementation_singleton import rclpy_implementation

RCLError = rclpy_implementation.RCLError


class LockedActionClient(ActionClient):
    """An ActionClient whose requests may be sent from one thread while another spins it, and
    whose `name` is the action name it was made with (unresolved).

    rclpy 7.1.6 sends a goal (or result, or cancel) request, then registers its future. When
    the executor thread takes the answer in between, it finds no future, logs "Ignoring
    unexpected goal response" and the request waits for ever (seen here: a lost remove_parts
    answer stalled a two-worker run for call_timeout; rclpy's service Client has a lock for
    this, its ActionClient not). Here sending and registering hold a lock, and handling an
    answer first takes that lock, so an answer is handled only after its request is
    registered. Every action client of the workspace is one of these.
    """

    def __init__(self, node, action_type, action_name: str, **kwargs) -> None:
        super().__init__(node, action_type, action_name, **kwargs)
        self.name = action_name
        self._send_lock = threading.Lock()

    def send_goal_async(self, *args, **kwargs):
        with self._send_lock:
            return super().send_goal_async(*args, **kwargs)

    def _get_result_async(self, *args, **kwargs):
        with self._send_lock:
            return super()._get_result_async(*args, **kwargs)

    def _cancel_goal_async(self, *args, **kwargs):
        with self._send_lock:
            return super()._cancel_goal_async(*args, **kwargs)

    async def execute(self, taken_data):
        with self._send_lock:   # an answer taken now belongs to a request sent and registered
            pass
        return await super().execute(taken_data)
