"""What every node of the workspace shares: the latched QoS profile; parameters declared from
a table of limits (`declare`); one answer to a failed request (`answer_error`); one watch on
the servers of a call in flight (`ServerWatch`); the probe that a server can answer us
(`handshake`); and a main() that starts rclpy, turns a bad configuration into one line and
exit code 2 (never a traceback), spins, and shuts down cleanly on Ctrl-C or SIGINT (the Jazzy
way: ros2/demos `qos_overrides_talker.py`)."""

from collections.abc import Callable, Iterable, Mapping
import signal
import sys
import time
import traceback
import uuid

from action_msgs.msg import GoalStatus
from action_msgs.srv import CancelGoal
from rcl_interfaces.msg import (
    FloatingPointRange,
    IntegerRange,
    ParameterDescriptor,
    ParameterType,
)
import rclpy
from rclpy.action import ActionClient
from rclpy.exceptions import InvalidHandle, ParameterException
from rclpy.executors import Executor, ExternalShutdownException, SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.task import Future

from . import interrupts
from .conversions import error_code, ERROR_INTERNAL
from .errors import CodedError, Limit, PickError
from .rclpy_adapter import LockedActionClient, RCLError

# s an action server keeps a finished goal's result (rclpy's default: 900). Every status
# message lists each goal kept, and every client decodes every status message: with the default,
# a feeder run of a thousand goals made the manager spend half its time decoding goal statuses
# (py-spy). Clients here ask for the result as soon as the goal is accepted.
RESULT_KEEP = 10.0
SPIN_WAKE = 0.5     # s: the longest a node's executor waits before it looks at its context

# Latched: a late subscriber gets the last message (scene, markers, last report).
LATCHED = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL,
                     reliability=ReliabilityPolicy.RELIABLE)


def endpoint_name(client) -> str:
    """The name a service or action client was made with, as given (unresolved). An action
    client must be a LockedActionClient: rclpy's own keeps its name private."""
    if isinstance(client, LockedActionClient):
        return client.name
    if isinstance(client, ActionClient):
        raise TypeError('an action client of the workspace is a '
                        'pick_common.rclpy_adapter.LockedActionClient (it has a public name)')
    return client.srv_name


def server_ids(node: Node, client) -> frozenset[bytes]:
    """The DDS ids of the endpoints that serve a client: an action's status publisher, a
    service's reply writer (ROS 2's rr/<name>Reply topic). A node started again serves under
    new ids, so a call to the one that died is seen lost although the name is served again."""
    if isinstance(client, ActionClient):
        infos = node.get_publishers_info_by_topic(
            node.resolve_service_name(endpoint_name(client)) + '/_action/status')
    else:
        infos = node.get_publishers_info_by_topic(
            f'rr{node.resolve_service_name(endpoint_name(client))}Reply', no_mangle=True)
    return frozenset(bytes(i.endpoint_gid) for i in infos)


PROBE_WAIT = 1.0   # s for the answer to a probe before another is sent
GONE_AFTER = 2.0   # s a server must stay absent from the graph before a call to it fails


def server_ready(client) -> bool:
    """Whether the graph has a server for an action or service client now."""
    if isinstance(client, ActionClient):
        return client.server_is_ready()
    return client.service_is_ready()


def serving(node: Node, clients: Iterable) -> dict:
    """client -> the DDS ids of its servers now (server_ids), to hand a ServerWatch."""
    return {c: server_ids(node, c) for c in clients}


def goal_result(response, what: str):
    """The result of an action's get_result answer `response`. Raises CodedError (INTERNAL)
    when the server no longer had the goal: rclpy drops a finished goal RESULT_KEEP s after it
    ended (its server's result_timeout) and answers a later request with status UNKNOWN and
    an empty result, whose error_code 0 would read as a success with no parts and no report
    (rclpy's ActionServer._execute_get_result_request; tests/test_action_result.py)."""
    if response.status == GoalStatus.STATUS_UNKNOWN:
        raise CodedError(ERROR_INTERNAL, (
            f'{what}: the server no longer had the goal when its result was asked for (a server '
            f'keeps a finished goal for its result_timeout, ours {RESULT_KEEP:g} s): the request '
            'came too late, or the server was started again'))
    return response.result


class ServerWatch:
    """Whether the servers that took a call are still there while it is in flight.

    A server whose node died never answers, and one started again answers from a new, empty
    state, which must not pass for the old one's: `lost` names the clients none of whose
    servers in `serving` (client -> server ids, taken when the work began; empty ids: any
    server will do) is in the graph now; `gone` names them only once they have been lost for
    `gone_after` s in a row (discovery can miss a live server for a moment). Used by the
    manager's calls to a worker and by the feeder controller's calls to the world.
    """

    def __init__(self, node: Node, serving: Mapping, gone_after: float = GONE_AFTER) -> None:
        self._node = node
        self._serving = dict(serving)
        self._gone_after = gone_after
        self._lost_since: float | None = None

    def lost(self) -> list:
        return [c for c, ids in self._serving.items()
                if not (ids & server_ids(self._node, c) if ids else server_ready(c))]

    def gone(self) -> list:
        lost, now = self.lost(), time.monotonic()
        if not lost:
            self._lost_since = None
            return []
        if self._lost_since is None:
            self._lost_since = now
        return lost if now - self._lost_since > self._gone_after else []


def handshake(node: Node, clients, wait: Callable[[Future, float], bool], deadline: float,
              stop: Callable[[], bool] = lambda: False) -> bool:
    """Probe each client's server (probe()) until it answers, so that it can answer us.
    wait(future, timeout) says whether the future completed in time (spinning, or waiting on
    an executor spun elsewhere). False at the deadline (monotonic s) or once stop() holds."""
    for client in clients:
        service, request = probe(node, client)
        try:
            while True:
                future = service.call_async(request)
                if wait(future, PROBE_WAIT):
                    break
                service.remove_pending_request(future)
                if time.monotonic() > deadline or stop():
                    return False
        finally:
            if service is not client:
                node.destroy_client(service)
    return True


def probe(node: Node, client) -> tuple[object, object]:
    """A (service client, request) that the server of `client` answers without doing
    anything: an action's cancel_goal for a goal id nobody has, or a service's empty request
    (our services answer it, or refuse it, without a change). Its answer shows that the server
    has matched this process's new reply readers: discovery is not symmetric, and rmw_fastrtps
    drops a reply whose reader the server has not matched within 100 ms ("failed to send
    response (timeout)", seen here under load for a first goal). Destroy the service client
    when it is not `client`."""
    if isinstance(client, ActionClient):
        cancel = node.create_client(CancelGoal, endpoint_name(client) + '/_action/cancel_goal')
        request = CancelGoal.Request()
        request.goal_info.goal_id.uuid = list(uuid.uuid4().bytes)
        return cancel, request
    return client, client.srv_type.Request()


def describe(text: str, limit: Limit | None = None) -> ParameterDescriptor:
    """A read-only parameter descriptor stating `limit` (the one the core checks)."""
    descriptor = ParameterDescriptor(description=text, read_only=True)
    if limit is not None and limit.integer:
        descriptor.integer_range = [IntegerRange(from_value=int(limit.low),
                                                 to_value=int(limit.high))]
    elif limit is not None:
        descriptor.floating_point_range = [FloatingPointRange(from_value=float(limit.low),
                                                              to_value=float(limit.high))]
    return descriptor


def declare(node: Node, name: str, default, text: str, limit: Limit | None = None):
    """Declare a read-only parameter and return its value, checked against `limit` (rclpy
    refuses a value outside the range at declaration; the check also enforces an open lower
    bound, which a descriptor cannot state). Every node declares its parameters this way, so
    that each range is written once, in the core's table of limits."""
    value = node.declare_parameter(name, default, describe(text, limit)).value
    return value if limit is None else limit.check(name, value)


def answer_error(response, exc: BaseException, logger, what: str) -> None:
    """Fill a response's (or result's) error_code and error_msg from an exception raised while
    serving `what`, and log it once: a core error (PickError) gets its code, a failed call to
    another node (CodedError) the code it carries; anything else is a bug, answered INTERNAL
    and logged with its traceback, and the node keeps serving."""
    if isinstance(exc, PickError):
        response.error_code = error_code(exc)
        response.error_msg = str(exc)
        logger.warning(f'{what} refused: {exc}')
    elif isinstance(exc, CodedError):
        response.error_code = exc.code
        response.error_msg = str(exc)
        logger.error(f'{what} failed: {exc}')
    else:
        response.error_code = ERROR_INTERNAL
        response.error_msg = f'internal error: {type(exc).__name__}: {exc}'
        logger.error(f'{what}: {response.error_msg}\n'
                     f'{"".join(traceback.format_exception(exc))}')


def declare_mesh_dirs(node: Node) -> list[str]:
    """The read-only `mesh_dirs` parameter of the nodes that load meshes named in requests:
    the directories those files may lie in (none by default)."""
    return node.declare_parameter('mesh_dirs', Parameter.Type.STRING_ARRAY, ParameterDescriptor(
        description='directories whose mesh files requests may name (part_model.mesh_path); '
        'unset: none. The part.mesh_path parameter is not limited by it', read_only=True,
        type=ParameterType.PARAMETER_STRING_ARRAY)).value or []


def _destroy_quietly(node: Node | None) -> None:
    """Destroy a node whose start failed; its handles may already be gone with the context."""
    if node is None:
        return
    try:
        node.destroy_node()
    except (RCLError, InvalidHandle):
        pass


def run(name: str, make_node: Callable[[], Node],
        make_executor: Callable[[], Executor] | None = None,
        args: list[str] | None = None) -> None:
    """Run one node until shutdown; exit 2 with a message when it cannot start, 0 when a
    signal stops it, also while it starts. Executors need an initialised context, so they are
    made here, after rclpy.init."""
    # rclpy's signal handler shuts the context down and then calls the handler it found
    # installed; Python's own SIGINT handler raises KeyboardInterrupt wherever the main thread
    # is, and once that was inside threading's Thread.start (the executor starting a worker),
    # which left a lock broken and the world exiting 1 ('release unlocked lock', in CI). A
    # handler that does nothing lets the spin loop below see the shutdown.
    signal.signal(signal.SIGINT, interrupts.record)
    try:
        rclpy.init(args=args)
    except Exception as exc:  # rcl's RCLError: bad --ros-args, unreadable params file
        print(f'{name}: could not start: {exc}', file=sys.stderr)
        sys.exit(2)
    if interrupts.received:
        # before rclpy's handler, or after it and already shut down by it: a stop either way
        rclpy.try_shutdown()
        print(f'{name}: stopped while starting', file=sys.stderr)
        return
    node = None
    try:
        node = make_node()
        executor = make_executor() if make_executor else SingleThreadedExecutor()
        executor.add_node(node)
    except (PickError, ParameterException, RCLError, InvalidHandle) as exc:
        if not rclpy.ok():
            # A signal shut the context down while the node was starting, and the start then
            # failed on something the shutdown took: the world's first scene ('publisher's
            # context is invalid') or the executor's guard condition ('the given context is
            # not valid', both seen in CI). A stop, not a failure.
            _destroy_quietly(node)
            print(f'{name}: stopped while starting', file=sys.stderr)
            return
        _destroy_quietly(node)
        rclpy.try_shutdown()
        if isinstance(exc, InvalidHandle):
            raise
        # RCLError: rcl refused the node, e.g. ROS_SECURITY_* it cannot honour.
        what = 'could not start' if isinstance(exc, RCLError) else 'bad configuration'
        print(f'{name}: {what}: {exc}', file=sys.stderr)
        sys.exit(2)
    try:
        # Not rclpy.spin: on SIGTERM, rclpy's signal thread wakes the executor and only then
        # shuts the context down, so an executor that wakes in between sees the context still
        # up and waits again, for ever in a node that nothing else wakes (a validity node
        # stopped 1 time in 48 under load). A bounded wait sees the shutdown.
        while node.context.ok():
            executor.spin_once(timeout_sec=SPIN_WAKE)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except (RCLError, InvalidHandle):
        # A signal shut the context down while the executor was taking or finishing work:
        # the handles it used are gone ('feedback publisher is invalid'). That is the
        # shutdown itself; with the context still up it is a failure.
        if node.context.ok():
            raise
    finally:
        executor.remove_node(node)     # as rclpy.spin does
        node.destroy_node()
        rclpy.try_shutdown()
