"""The `experiment_manager` node: runs experiment files over workers' nodes and records them.

Action `run_experiment` (feedback: ExperimentProgress); topics `progress` and `verdicts`
(latched: the decisions of the last finished run). It drives one or more
workers, each a `world`, `validity` and `feeder_controller` under its own namespace
(graph_backend.py). A goal becomes a run session (session.py): iterations are spread over the
workers (scheduler.py), and one whose worker dies or stops answering runs again on another;
results are written as iterations finish (results.py); every topic of the workers, its own
progress, the experiment file and the results go into one MCAP file per run (recording.py).
Up to RUNS_AT_ONCE runs at a time, side by side on the same workers (running/workers.py): the
first begun takes a free worker first, a later one fills what it leaves idle (a board's next
part while the last iterations of the one before run); a goal beyond them is answered BUSY,
not queued.
"""

from collections.abc import Callable
from dataclasses import dataclass, field
import itertools
import os
import threading
import time

from ament_index_python.packages import get_package_share_directory
from pick_common.errors import InvalidArgument, Limit
from pick_common.node_runner import answer_error, declare, LATCHED, run
from pick_msgs.action import RunExperiment
from pick_msgs.msg import ExperimentProgress, RunVerdicts, Verdict
from rcl_interfaces.msg import ParameterDescriptor, ParameterType
from rclpy.action import ActionServer, CancelResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.exceptions import InvalidNamespaceException
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from rclpy.validate_namespace import validate_namespace
from std_msgs.msg import Header

from ..analysis.summary import Summary
from ..analysis.verdicts import verdicts
from ..running.scheduler import Progress
from ..running.workers import RUNS_AT_ONCE, Workers
from .graph_backend import GraphBackend, GraphError
from .session import RunSession
from .topic_recorder import TopicRecorder

STOP_WAIT = 15.0        # s a shutdown waits for the runs to close their files
DISCOVERY_SETTLE = 3.0  # s the worker list must stay the same before discovery ends
BUILTIN_FILES = os.path.join(get_package_share_directory('experiment_manager'), 'config')
# The range of each numeric parameter (s, bytes).
LIMITS = {
    'call_timeout': Limit(1.0, 86400.0),
    'server_timeout': Limit(0.1, 3600.0),
    'rejoin_timeout': Limit(0.0, 3600.0),
    'recording.chunk_size': Limit(1024, 1 << 30, integer=True),
}


class ExperimentManagerNode(Node):
    """Translates run_experiment goals into run sessions (session.py) on the graph."""

    def __init__(self) -> None:
        super().__init__('experiment_manager')
        workers = self.declare_parameter('workers', ['*'], ParameterDescriptor(
            description='namespaces of the workers (world, validity and feeder_controller) to '
            "drive, relative to this node's ('' for its own); ['*']: every worker found under "
            'this namespace at the start of each run', read_only=True)).value
        self._workers = [check_worker(w) for w in workers]
        if '*' in self._workers and len(self._workers) > 1:
            raise InvalidArgument('workers', workers, "'*' stands alone: discover, or name them")
        if len(set(self._workers)) < len(self._workers):
            raise InvalidArgument('workers', workers, 'names a worker twice')
        def get(name: str, default, text: str):
            return declare(self, name, default, text, LIMITS[name])

        call_timeout = get('call_timeout', 600.0,
                           'longest wait for one call to a node of the worker, s')
        server_timeout = get('server_timeout', 10.0, "longest wait for the worker's services "
                             'and actions at the start of a run, s')
        self._rejoin_timeout = get('rejoin_timeout', 60.0, (
            'longest wait for a lost worker to come back (its nodes restarted, as `run` does) '
            'before the run goes on without it, s; 0: do not wait'))
        self._chunk_size = get('recording.chunk_size', 1 << 20, 'bytes of messages per MCAP '
                               'chunk; a killed run loses at most one')

        def dirs(name: str, default: list[str], text: str) -> list[str]:
            return self.declare_parameter(name, default, ParameterDescriptor(
                description=text, read_only=True,
                type=ParameterType.PARAMETER_STRING_ARRAY)).value

        self._experiment_dirs = dirs('experiment_dirs', ['.', BUILTIN_FILES], (
            'directories whose experiment files (and the meshes they name) goals may name; '
            "'.' is the node's working directory"))
        self._output_dirs = dirs('output_dirs', ['.'], 'directories under which goals may '
                                 'write run directories')
        self._group = ReentrantCallbackGroup()
        self._call_timeout, self._server_timeout = call_timeout, server_timeout
        self._stopping = threading.Event()
        self._runs = threading.Condition()
        self._active: list[Active] = []          # the runs going on, in the order begun
        self._pool = Workers(taken=self._taken)
        self._progress = self.create_publisher(ExperimentProgress, 'progress', 10)
        self._verdicts = self.create_publisher(RunVerdicts, 'verdicts', LATCHED)
        self._backends: dict[str, GraphBackend] = {}
        self._topics = TopicRecorder(f'{self.get_name()}_recorder', self.get_namespace(),
                                     self.context)
        self._accepted: dict[bytes, int] = {}     # goal id -> its place in the order accepted
        self._count = itertools.count()
        ActionServer(self, RunExperiment, 'run_experiment', execute_callback=self._run,
                     handle_accepted_callback=self._accept,
                     cancel_callback=self._cancel,
                     callback_group=self._group)
        names = ', '.join(w or 'this namespace' for w in self._workers)
        self.get_logger().info(f'workers: {names}; call_timeout {call_timeout:g} s')

    def _shutting_down(self) -> bool:
        """destroy_node was called, or a signal already shut the context down under the run."""
        return self._stopping.is_set() or not self.context.ok()

    def _accept(self, goal_handle) -> None:
        """A goal accepted: its place in the order (the first has the workers first), then
        its execution (rclpy's default)."""
        with self._runs:
            self._accepted[bytes(goal_handle.goal_id.uuid)] = next(self._count)
        goal_handle.execute()

    def _cancel(self, goal_handle) -> CancelResponse:
        """A cancel request: the run ends at once, even one waiting for a worker beside
        another (its calls in flight stop at their next look, as they did); a run whose
        runner is not made yet is stopped when it is (_made)."""
        with self._runs:
            for active in self._active:
                if bytes(active.goal.goal_id.uuid) == bytes(goal_handle.goal_id.uuid):
                    active.canceled.set()
                    if active.session.runner is not None:
                        self._made(active, active.session.runner)
        return CancelResponse.ACCEPT

    def _stopped(self, active: 'Active') -> bool:
        """Whether a run's calls are to stop: it was canceled or failed, or the node is
        shutting down."""
        return self._shutting_down() or active.abort.is_set() or active.cancel_came

    def _active_of(self, runner) -> 'Active | None':
        return next((a for a in list(self._active) if a.session.runner is runner), None)

    def _made(self, active: 'Active', runner) -> None:
        """A run's runner is made: stopped at once if its goal was canceled before."""
        with self._runs:
            if active.cancel_came:
                runner.stop(GraphError(RunExperiment.Result.CANCELED,
                                       'run_experiment was canceled'))

    def _taken(self, backend: GraphBackend, runner) -> None:
        """A run took a worker (Workers): the worker's topics go to that run's recording."""
        active = self._active_of(runner)
        if active is not None:
            self._topics.route(backend.worker, active.session.recorder)

    def _worker_canceled(self, worker: str) -> bool:
        """Whether the calls to `worker` are to stop: the node is shutting down, or the run
        holding the worker was canceled or failed."""
        if self._shutting_down():
            return True
        runner = self._pool.holder(self._backends[worker])
        active = self._active_of(runner) if runner is not None else None
        return active is not None and self._stopped(active)

    def _discover(self) -> list[str]:
        """Namespaces under this node's that hold a whole worker (the world's reset_scene, the
        validity node's check_parts, the feeder's feed_cycle), relative to this node's."""
        base = self.get_namespace().rstrip('/')
        names = {name for name, _ in self.get_service_names_and_types()}
        found = []
        for name in names:
            if name.endswith('/check_parts') and (name == base + '/check_parts'
                                                  or name.startswith(base + '/')):
                ns = name[:-len('/check_parts')]
                if {f'{ns}/reset_scene', f'{ns}/feed_cycle/_action/send_goal'} <= names:
                    found.append(ns[len(base):].strip('/'))
        return sorted(found)

    def _workers_of_run(self, stopped: Callable[[], bool]) -> list[GraphBackend]:
        """The backends of the workers to drive (found now when the parameter says '*'),
        the search given up once `stopped()`."""
        workers = self._workers
        if workers == ['*']:
            deadline = time.monotonic() + self._server_timeout
            workers, since = [], time.monotonic()
            while time.monotonic() < deadline and not stopped():
                now = self._discover()
                if now != workers:
                    workers, since = now, time.monotonic()
                elif workers and time.monotonic() - since > DISCOVERY_SETTLE:
                    break
                time.sleep(0.1)
            if not workers:
                raise GraphError(RunExperiment.Result.INTERNAL, (
                    f'no worker found within server_timeout {self._server_timeout:g} s: no '
                    f'namespace under {self.get_namespace()} holds reset_scene, check_parts '
                    'and feed_cycle (are the world, validity and feeder_controller nodes '
                    'running?)'))
        with self._runs:        # two runs beginning at once make one backend of a worker
            for worker in workers:
                if worker not in self._backends:
                    self._backends[worker] = GraphBackend(
                        self, worker, self._group, self._call_timeout, self._server_timeout,
                        lambda w=worker: self._worker_canceled(w), self._rejoin_timeout)
                    self._topics.add(worker)
            return [self._backends[w] for w in workers]

    def _publish_progress(self, p: Progress, goal_handle, session: RunSession) -> None:
        msg = ExperimentProgress(header=Header(stamp=self.get_clock().now().to_msg()),
                                 experiment_id=p.experiment_id,
                                 experiment_type=p.experiment_type, phase=p.phase,
                                 iterations_total=p.total, iterations_done=p.done,
                                 elapsed=p.elapsed, eta=p.eta)
        if self._shutting_down():
            return   # the publishers may be gone
        self._progress.publish(msg)
        goal_handle.publish_feedback(RunExperiment.Feedback(progress=msg))
        self._topics.write(self._progress, msg, session.recorder)
        # once per iteration: a killed manager's recording keeps the rest
        self._topics.flush(session.recorder)

    def _publish_verdicts(self, session: RunSession, summary: Summary) -> list[Verdict]:
        """The run's decisions, published (latched) and recorded with the run."""
        msg = RunVerdicts(header=Header(stamp=self.get_clock().now().to_msg()),
                          experiment_id=session.file.id, run_directory=session.run_dir,
                          verdicts=[Verdict(option=v.option, verdict=v.verdict,
                                            reasons=v.reasons, stops_most=v.stops)
                                    for v in verdicts(summary)])
        self._verdicts.publish(msg)
        self._topics.write(self._verdicts, msg, session.recorder)
        return msg.verdicts

    # ------------------------------------------------------------------------- the action
    def _run(self, goal_handle) -> RunExperiment.Result:
        """Map the goal to a run session, and what fails to an error code."""
        result = RunExperiment.Result()
        goal = goal_handle.request
        session = RunSession(self._experiment_dirs, self._output_dirs, self._chunk_size,
                             self._topics, self.get_fully_qualified_name(), self.get_logger())
        with self._runs:
            active = Active(session, self._accepted.pop(bytes(goal_handle.goal_id.uuid)),
                            goal_handle)
            if len(self._active) >= RUNS_AT_ONCE:
                result.error_code = RunExperiment.Result.BUSY
                result.error_msg = (f'{len(self._active)} experiments are running, the most '
                                    'the manager runs at once (goals are not queued): send it '
                                    'again when one has finished')
                goal_handle.abort()
                return result
            self._active.append(active)
        try:
            session.open(goal.experiment_file, goal.output_dir, goal.resume)
            result.results_path = session.run_dir
            result.recording_path = session.recorder.path
            backends = self._workers_of_run(lambda: self._stopped(active))
            summary = session.run(
                backends, lambda p: self._publish_progress(p, goal_handle, session),
                active.abort,
                [b.worker or '.' for b in backends], self._pool, active.rank,
                lambda runner: self._made(active, runner))
            result.summary_json = summary.json_text()
            result.verdicts = self._publish_verdicts(session, summary)
            result.report_path = session.write_report()
            goal_handle.succeed()
        except Exception as exc:  # core and worker errors get their code, bugs INTERNAL
            answer_error(result, exc, self.get_logger(), 'run_experiment')
            self._end(goal_handle, result)
        finally:
            session.close()
            if session.writer is not None and result.error_code:
                result.error_msg += (f' (finished iterations are kept in {session.run_dir};'
                                     ' resume the run there to finish it)')
            with self._runs:
                self._active.remove(active)
                self._runs.notify_all()
        return result

    def _end(self, goal_handle, result) -> None:
        if goal_handle.is_cancel_requested or self._shutting_down():
            result.error_code = RunExperiment.Result.CANCELED
        if self._shutting_down():
            return   # the action server is being destroyed
        if goal_handle.is_cancel_requested:
            goal_handle.canceled()
        else:
            goal_handle.abort()

    def destroy_node(self) -> None:
        """On shutdown, stop a run at its next call and let it close its files."""
        self._stopping.set()
        with self._runs:
            if not self._runs.wait_for(lambda: not self._active, STOP_WAIT):
                self.get_logger().error(f'{len(self._active)} run(s) did not stop within '
                                        f'{STOP_WAIT:g} s; their recordings may be cut off')
        for backend in self._backends.values():
            backend.destroy()
        self._topics.destroy()
        super().destroy_node()


@dataclass(frozen=True, eq=False)
class Active:
    """A run going on: its session, its goal's place in the order accepted, its goal, whether
    it failed (`abort`, set by its runner for its other workers) and whether a cancel came."""
    session: RunSession
    rank: int       # the goal's place in the order accepted
    goal: object    # rclpy's ServerGoalHandle
    abort: threading.Event = field(default_factory=threading.Event)
    # set by the cancel callback, which runs before rclpy marks the goal canceled
    canceled: threading.Event = field(default_factory=threading.Event)

    @property
    def cancel_came(self) -> bool:
        return self.canceled.is_set() or self.goal.is_cancel_requested


def check_worker(worker: str) -> str:
    """A worker namespace of the `workers` parameter, relative ('' for the manager's own),
    or '*'."""
    worker = worker.strip('/')
    if worker in ('', '*'):
        return worker
    try:
        validate_namespace('/' + worker)
    except InvalidNamespaceException as exc:
        raise InvalidArgument('workers', worker, f'is not a valid namespace: {exc}') from None
    return worker


def main(args=None) -> None:
    run('experiment_manager', ExperimentManagerNode,
        lambda: MultiThreadedExecutor(num_threads=4), args)
