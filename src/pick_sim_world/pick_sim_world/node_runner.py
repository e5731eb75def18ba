"""What every node of the workspace shares: the latched QoS profile, and a main() that starts
rclpy, turns a bad configuration into one line and exit code 2 (never a traceback), spins, and
shuts down cleanly on Ctrl-C or SIGINT (the Jazzy way: ros2/demos `qos_overrides_talker.py`)."""

from collections.abc import Callable
import sys
import time
import uuid

from action_msgs.srv import CancelGoal
from rcl_interfaces.msg import ParameterDescriptor, ParameterType
import rclpy
from rclpy.action import ActionClient
from rclpy.exceptions import ParameterException
from rclpy.executors import Executor, ExternalShutdownException
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.task import Future

from .errors import WorldError

# s an action server keeps a finished goal's result (rclpy's default: 900). Every status
# message lists each goal kept, and every client decodes every status message: with the default,
# a feeder run of a thousand goals made the manager spend half its time decoding goal statuses
# (py-spy). Clients here ask for the result as soon as the goal is accepted.
RESULT_KEEP = 10.0

# Latched: a late subscriber gets the last message (scene, markers, last report).
LATCHED = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL,
                     reliability=ReliabilityPolicy.RELIABLE)


def server_ids(node: Node, client) -> frozenset[bytes]:
    """The DDS ids of the endpoints that serve a client: an action's status publisher, a
    service's reply writer (ROS 2's rr/<name>Reply topic). A node started again serves under
    new ids, so a call to the one that died is seen lost although the name is served again."""
    if isinstance(client, ActionClient):
        infos = node.get_publishers_info_by_topic(
            node.resolve_service_name(client._action_name) + '/_action/status')
    else:
        infos = node.get_publishers_info_by_topic(
            f'rr{node.resolve_service_name(client.srv_name)}Reply', no_mangle=True)
    return frozenset(bytes(i.endpoint_gid) for i in infos)


PROBE_WAIT = 1.0   # s for the answer to a probe before another is sent


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
        cancel = node.create_client(CancelGoal, client._action_name + '/_action/cancel_goal')
        request = CancelGoal.Request()
        request.goal_info.goal_id.uuid = list(uuid.uuid4().bytes)
        return cancel, request
    return client, client.srv_type.Request()


def declare_mesh_dirs(node: Node) -> list[str]:
    """The read-only `mesh_dirs` parameter of the nodes that load meshes named in requests:
    the directories those files may lie in (none by default)."""
    return node.declare_parameter('mesh_dirs', Parameter.Type.STRING_ARRAY, ParameterDescriptor(
        description='directories whose mesh files requests may name (part_model.mesh_path); '
        'unset: none. The part.mesh_path parameter is not limited by it', read_only=True,
        type=ParameterType.PARAMETER_STRING_ARRAY)).value or []


def run(name: str, make_node: Callable[[], Node],
        make_executor: Callable[[], Executor] | None = None,
        args: list[str] | None = None) -> None:
    """Run one node until shutdown; exit 2 with a message when it cannot start. Executors
    need an initialised context, so they are made here, after rclpy.init."""
    try:
        rclpy.init(args=args)
    except Exception as exc:  # rcl's RCLError: bad --ros-args, unreadable params file
        print(f'{name}: could not start: {exc}', file=sys.stderr)
        sys.exit(2)
    try:
        node = make_node()
    except (WorldError, ParameterException) as exc:
        print(f'{name}: bad configuration: {exc}', file=sys.stderr)
        rclpy.try_shutdown()
        sys.exit(2)
    except _rclpy.RCLError as exc:  # rcl refused the node, e.g. ROS_SECURITY_* it cannot honour
        print(f'{name}: could not start: {exc}', file=sys.stderr)
        rclpy.try_shutdown()
        sys.exit(2)
    try:
        rclpy.spin(node, executor=make_executor() if make_executor else None)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
