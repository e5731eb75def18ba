"""The `experiment_manager` node: runs experiment files over workers' nodes and records them.

Action `run_experiment` (feedback: ExperimentProgress); topics `progress` and `verdicts`
(latched: the decisions of the last finished run). It drives one or more
workers, each a `world`, `validity` and `feeder_controller` under its own namespace
(graph_backend.py). A goal becomes a run session (session.py): iterations are spread over the
workers (scheduler.py), and one whose worker dies or stops answering runs again on another;
results are written as iterations finish (results.py); every topic of the workers, its own
progress, the experiment file and the results go into one MCAP file per run (recording.py).
One run at a time: a second goal is answered BUSY, not queued.
"""

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
from .graph_backend import GraphBackend, GraphError
from .session import RunSession
from .topic_recorder import TopicRecorder

STOP_WAIT = 15.0        # s a shutdown waits for the run to close its files
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
        self._abort = threading.Event()     # set by a run that failed, for its other workers
        self._lock = threading.Lock()
        self._goal = None
        self._progress = self.create_publisher(ExperimentProgress, 'progress', 10)
        self._verdicts = self.create_publisher(RunVerdicts, 'verdicts', LATCHED)
        self._backends: dict[str, GraphBackend] = {}
        self._topics = TopicRecorder(f'{self.get_name()}_recorder', self.get_namespace(),
                                     self.context)
        ActionServer(self, RunExperiment, 'run_experiment', execute_callback=self._run,
                     cancel_callback=lambda _: CancelResponse.ACCEPT,
                     callback_group=self._group)
        names = ', '.join(w or 'this namespace' for w in self._workers)
        self.get_logger().info(f'workers: {names}; call_timeout {call_timeout:g} s')

    def _shutting_down(self) -> bool:
        """destroy_node was called, or a signal already shut the context down under the run."""
        return self._stopping.is_set() or not self.context.ok()

    def _cancel_requested(self) -> bool:
        goal = self._goal
        return (self._shutting_down() or self._abort.is_set()
                or (goal is not None and goal.is_cancel_requested))

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

    def _workers_of_run(self) -> list[GraphBackend]:
        """The backends of the workers to drive (found now when the parameter says '*')."""
        workers = self._workers
        if workers == ['*']:
            deadline = time.monotonic() + self._server_timeout
            workers, since = [], time.monotonic()
            while time.monotonic() < deadline and not self._cancel_requested():
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
        for worker in workers:
            if worker not in self._backends:
                self._backends[worker] = GraphBackend(
                    self, worker, self._group, self._call_timeout, self._server_timeout,
                    self._cancel_requested, self._rejoin_timeout)
                self._topics.add(worker)
        return [self._backends[w] for w in workers]

    def _publish_progress(self, p: Progress) -> None:
        msg = ExperimentProgress(header=Header(stamp=self.get_clock().now().to_msg()),
                                 experiment_id=p.experiment_id,
                                 experiment_type=p.experiment_type, phase=p.phase,
                                 iterations_total=p.total, iterations_done=p.done,
                                 elapsed=p.elapsed, eta=p.eta)
        if self._shutting_down():
            return   # the publishers may be gone
        self._progress.publish(msg)
        if self._goal is not None:
            self._goal.publish_feedback(RunExperiment.Feedback(progress=msg))
        self._topics.write(self._progress, msg)
        self._topics.flush()   # once per iteration: a killed manager's recording keeps the rest

    def _publish_verdicts(self, session: RunSession, summary: Summary) -> list[Verdict]:
        """The run's decisions, published (latched) and recorded with the run."""
        msg = RunVerdicts(header=Header(stamp=self.get_clock().now().to_msg()),
                          experiment_id=session.file.id, run_directory=session.run_dir,
                          verdicts=[Verdict(option=v.option, verdict=v.verdict,
                                            reasons=v.reasons, stops_most=v.stops)
                                    for v in verdicts(summary)])
        self._verdicts.publish(msg)
        self._topics.write(self._verdicts, msg)
        return msg.verdicts

    # ------------------------------------------------------------------------- the action
    def _run(self, goal_handle) -> RunExperiment.Result:
        """Map the goal to a run session, and what fails to an error code."""
        result = RunExperiment.Result()
        if not self._lock.acquire(blocking=False):
            result.error_code = RunExperiment.Result.BUSY
            result.error_msg = ('another experiment is running; goals are not queued: send it '
                                'again when the running one has finished')
            goal_handle.abort()
            return result
        self._goal = goal_handle
        goal = goal_handle.request
        session = RunSession(self._experiment_dirs, self._output_dirs, self._chunk_size,
                             self._topics, self.get_fully_qualified_name(), self.get_logger())
        try:
            session.open(goal.experiment_file, goal.output_dir, goal.resume)
            result.results_path = session.run_dir
            result.recording_path = session.recorder.path
            self._abort.clear()
            backends = self._workers_of_run()
            summary = session.run(backends, self._publish_progress, self._abort,
                                  [b.worker or '.' for b in backends])
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
            self._goal = None
            self._lock.release()
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
        if self._lock.acquire(timeout=STOP_WAIT):   # held while a run is in flight
            self._lock.release()
        else:
            self.get_logger().error('the run did not stop within '
                                    f'{STOP_WAIT:g} s; its recording may be cut off')
        for backend in self._backends.values():
            backend.destroy()
        self._topics.destroy()
        super().destroy_node()


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
