"""The experiment backend over the ROS 2 graph: a worker's `world`, `validity` and
`feeder_controller` nodes, called by relative names under the worker's namespace.

Calls are made from the thread that runs the worker's iterations and wait on their futures
while the node's executor spins in other threads. A wait ends with an error, never a hang: when
the goal is canceled, or with `WorkerGone` when the server drops out of the graph (its node
died) or gives no answer within `call_timeout` (the runner then runs the iteration elsewhere).
"""

from collections.abc import Callable
import threading
import time

from feeder_controller.policy import FeederConfig
from pick_common import conversions as common
from pick_common.containers import ContainerSpec
from pick_common.errors import CodedError, PhysicsFault
from pick_common.node_runner import (
    endpoint_name,
    goal_result,
    GONE_AFTER,
    handshake,
    server_ready,
    ServerWatch,
    serving,
)
from pick_common.rclpy_adapter import LockedActionClient
from pick_common.states import PartStates, SettleReport
from pick_msgs.action import DropParts, FeedCycle, RemoveParts
from pick_msgs.msg import PartArray
from pick_msgs.srv import CheckParts, GetParts, ResetScene
from pick_validity import conversions as validity_conv
from pick_validity.results import Report
from rclpy.node import Node

from ..experiment_file import ExperimentFile, GripperVariant
from ..running.backend import FeedStep, WorkerLost

POLL = 0.1              # s between checks of a pending call


class GraphError(CodedError):
    """A call to a worker failed: `code` is a pick_msgs error code (the server's own, or
    INTERNAL when the server is missing or lost, CANCELED when the goal was canceled)."""


class WorkerGone(GraphError, WorkerLost):
    """The worker died or stopped answering in the middle of a run."""


class GraphPhysicsFault(GraphError, PhysicsFault):
    """The world answered PHYSICS_FAULT (NaN state): the runner marks the iteration."""


class GraphBackend:
    """Implements backend.Backend with service and action calls to one worker."""

    def __init__(self, node: Node, worker: str, callback_group, call_timeout: float,
                 server_timeout: float, canceled: Callable[[], bool],
                 rejoin_timeout: float = 0.0) -> None:
        self._node = node
        self._rejoin_timeout = rejoin_timeout
        self._ns = worker.strip('/')
        self._call_timeout = call_timeout
        self._server_timeout = server_timeout
        self._canceled = canceled
        name = self.name
        group = {'callback_group': callback_group}
        self._reset = node.create_client(ResetScene, name('reset_scene'), **group)
        self._get = node.create_client(GetParts, name('get_parts'), **group)
        self._check_client = node.create_client(CheckParts, name('check_parts'), **group)
        self._drop = LockedActionClient(node, DropParts, name('drop_parts'), **group)
        self._remove = LockedActionClient(node, RemoveParts, name('remove_parts'), **group)
        self._feed = LockedActionClient(node, FeedCycle, name('feed_cycle'), **group)
        self._clients = (self._reset, self._get, self._check_client, self._drop, self._remove,
                         self._feed)
        self._file: ExperimentFile | None = None
        self._parts_msg = PartArray()
        self._shaken = False    # every server answered a probe (handshake)
        # client -> the DDS ids of its servers when this iteration began (reset): a server
        # answering under other ids is a node started again, without the iteration's scene
        # or feeder state. Before the first iteration, any server will do.
        self._serving: dict = {c: frozenset() for c in self._clients}

    @property
    def worker(self) -> str:
        """The worker's namespace, relative ('' for the manager's own)."""
        return self._ns

    def name(self, endpoint: str) -> str:
        """The relative name of a worker endpoint."""
        return f'{self._ns}/{endpoint}' if self._ns else endpoint

    def destroy(self) -> None:
        for client in self._clients:
            if isinstance(client, LockedActionClient):
                client.destroy()
            else:
                self._node.destroy_client(client)

    # ------------------------------------------------------------------------- waiting
    def _endpoint(self, client) -> str:
        return self._node.resolve_service_name(endpoint_name(client))

    def _missing(self) -> list:
        """The worker's clients whose server is not in the graph now."""
        return [c for c in self._clients if not server_ready(c)]

    def rejoin(self, stop: Callable[[], bool]) -> bool:
        """Wait for a lost worker to come back (its nodes restarted: every endpoint served
        again) for at most rejoin_timeout; False if it does not, or when stop() holds."""
        deadline = time.monotonic() + self._rejoin_timeout
        while time.monotonic() < deadline and not stop():
            if not self._missing():
                return self.handshake(deadline, stop)
            time.sleep(POLL)
        return False

    def handshake(self, deadline: float, stop: Callable[[], bool]) -> bool:
        """Probe each server until it answers (node_runner.handshake)."""
        def wait(future, timeout: float) -> bool:
            answered = threading.Event()
            future.add_done_callback(lambda _: answered.set())
            return answered.wait(timeout)
        return handshake(self._node, self._clients, wait, deadline, stop)

    def wait_for_servers(self) -> None:
        """Raise WorkerGone with the missing endpoints' names unless all are there within
        server_timeout."""
        deadline = time.monotonic() + self._server_timeout
        while time.monotonic() < deadline:
            if not self._missing() and (self._shaken or self.handshake(deadline,
                                                                       self._canceled)):
                self._shaken = True
                return
            if self._canceled():
                raise GraphError(CheckParts.Response.CANCELED, 'canceled')
            time.sleep(POLL)
        missing = [self._endpoint(c) for c in self._missing()]
        if not missing:
            raise WorkerGone(CheckParts.Response.INTERNAL, (
                f'the servers of worker {self._ns!r} are in the graph but did not answer a probe '
                f'within server_timeout {self._server_timeout:g} s'))
        where = f'namespace {self._ns!r}' if self._ns else "the manager's namespace"
        raise WorkerGone(CheckParts.Response.INTERNAL, (
            f'not in the graph after {self._server_timeout:g} s: {", ".join(missing)} (are the '
            f'world, validity and feeder_controller nodes running in {where}?)'))

    def _wait(self, future, client, what: str):
        """The future's result. Every server of the worker that this iteration began with must
        stay in the graph meanwhile (a feed_cycle, say, waits on the world through the
        feeder_controller, and a world that died would leave it waiting for ever) and still be
        there when the answer came: a node that died between two calls and was started again
        answers from a new, empty state, which must not pass for the iteration's."""
        done = threading.Event()
        future.add_done_callback(lambda _: done.set())
        start = time.monotonic()
        watch = ServerWatch(self._node, self._serving)
        if self._canceled():   # before the first wait too: short calls would never notice
            future.cancel()
            raise GraphError(CheckParts.Response.CANCELED, f'canceled before {what}')
        while not done.wait(POLL):
            if self._canceled():
                future.cancel()
                raise GraphError(CheckParts.Response.CANCELED, f'canceled during {what}')
            if time.monotonic() - start > self._call_timeout:
                raise WorkerGone(CheckParts.Response.INTERNAL, (
                    f'{what}: no answer from {self._endpoint(client)} within call_timeout '
                    f'{self._call_timeout:g} s'))
            if gone := watch.gone():
                raise WorkerGone(CheckParts.Response.INTERNAL, (
                    f'{what}: {", ".join(self._endpoint(c) for c in gone)} left the graph '
                    'while the worker was answering (its node died, was stopped or restarted)'))
        deadline = time.monotonic() + GONE_AFTER
        while lost := watch.lost():
            if time.monotonic() > deadline:
                raise WorkerGone(CheckParts.Response.INTERNAL, (
                    f'{what}: {", ".join(self._endpoint(c) for c in lost)} of this '
                    'iteration left the graph (its node died, was stopped or restarted): the '
                    "answer may come from a node without the iteration's state"))
            time.sleep(POLL)
        return future.result()

    def _service(self, client, request, what: str):
        if not server_ready(client):
            self.wait_for_servers()
        response = self._wait(client.call_async(request), client, what)
        self._raise_on_error(response, what)
        return response

    def _action(self, client: LockedActionClient, goal, what: str):
        if not server_ready(client):
            self.wait_for_servers()
        handle = self._wait(client.send_goal_async(goal), client, what)
        if not handle.accepted:
            raise GraphError(CheckParts.Response.INTERNAL, f'{what}: the goal was rejected')
        try:
            answer = self._wait(handle.get_result_async(), client, what)
        except GraphError:
            handle.cancel_goal_async()
            raise
        try:
            result = goal_result(answer, what)
        except CodedError as exc:   # the goal ran, its answer is lost: run the iteration again
            raise WorkerGone(exc.code, str(exc)) from exc
        self._raise_on_error(result, what)
        return result

    def _raise_on_error(self, answer, what: str) -> None:
        """Raise the server's error. An INTERNAL error while endpoints of the worker are gone
        (the feeder_controller answers so when the world it waits on died) means the worker
        is lost, not the run: WorkerGone, and the iteration runs elsewhere."""
        if answer.error_code == common.ERROR_NONE:
            return
        missing = self._missing() if answer.error_code == CheckParts.Response.INTERNAL else []
        if missing:
            raise WorkerGone(answer.error_code, (
                f'{what}: {answer.error_msg} ({", ".join(self._endpoint(c) for c in missing)} '
                'left the graph)'))
        if answer.error_code == common.ERROR_PHYSICS_FAULT:
            raise GraphPhysicsFault(answer.error_code, f'{what}: {answer.error_msg}')
        raise GraphError(answer.error_code, f'{what}: {answer.error_msg}')

    # ------------------------------------------------------------------------- Backend
    def start(self, file: ExperimentFile) -> None:
        self._file = file
        self._part_msg = common.part_spec_to_msg(file.part)
        self.wait_for_servers()

    def reset(self, container: ContainerSpec, seed: int) -> None:
        """Begin an iteration: its servers are the ones in the graph now."""
        if self._missing():
            self.wait_for_servers()
        self._serving = serving(self._node, self._clients)
        request = ResetScene.Request(container=common.container_to_msg(container),
                                     part_model=self._part_msg, instance_count=1, seed=seed)
        self._service(self._reset, request, 'reset_scene')
        self._parts_msg = PartArray()

    def _states(self, msg: PartArray) -> PartStates:
        self._parts_msg = msg
        return common.states_from_msg(msg)

    def drop(self, count: int, zone: str) -> tuple[PartStates, SettleReport]:
        goal = DropParts.Goal(count=count, zone=DropParts.Goal.ZONE_FEEDER if zone == 'feeder'
                              else DropParts.Goal.ZONE_CONTAINER)
        result = self._action(self._drop, goal, 'drop_parts')
        return self._states(result.parts), common.settle_from_msg(result.settle)

    def remove(self, ids: list[int], settle: bool = True) -> tuple[PartStates, SettleReport]:
        goal = RemoveParts.Goal(part_ids=[int(i) for i in ids], skip_settle=not settle)
        result = self._action(self._remove, goal, 'remove_parts')
        return self._states(result.parts), common.settle_from_msg(result.settle)

    def parts(self) -> PartStates:
        return self._states(self._service(self._get, GetParts.Request(), 'get_parts').parts)

    def check(self, container: ContainerSpec, states: PartStates, targets: list[int],
              neighbours: bool, variant: GripperVariant | None = None) -> Report:
        # The messages as received (no encoding again), of the parts in `states`: all, or
        # those the runner kept (it leaves out parts fallen far from the container).
        wanted = set(states.ids.tolist())
        parts = [p for p in self._parts_msg.parts if p.id in wanted]
        if [p.id for p in parts] != states.ids.tolist():
            raise GraphError(CheckParts.Response.INTERNAL,
                             'check_parts: the parts to check are not among the last received')
        request = CheckParts.Request(container=common.container_to_msg(container),
                                     parts=parts,
                                     target_ids=[int(t) for t in targets],
                                     check_neighbours=neighbours)
        validity_conv.setup_to_request(self._file.variant_setup(variant), request)
        response = self._service(self._check_client, request, 'check_parts')
        return validity_conv.report_from_msg(response.report)

    def feed(self, valid: int, on_table: int, restart: FeederConfig | None) -> FeedStep:
        goal = FeedCycle.Goal(valid_parts=valid, parts_on_table=on_table,
                              moves=[common.vibration_to_msg(m) for m in self._file.moves])
        if restart is not None:
            goal.restart = True
            goal.feeder_parts, goal.min_count = restart.feeder_parts, restart.min_count
            goal.max_count, goal.max_vibrations = restart.max_count, restart.max_vibrations
            goal.max_feed = restart.max_feed
        result = self._action(self._feed, goal, 'feed_cycle')
        s = result.state
        return FeedStep(result.decision, result.parts_fed, s.vibrations, s.feeds,
                        s.parts_in_feeder,
                        tuple(common.settle_from_msg(r) for r in result.reports))
