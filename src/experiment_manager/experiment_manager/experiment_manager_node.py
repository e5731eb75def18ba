"""The `experiment_manager` node: runs experiment files over workers' nodes and records them.

Action `run_experiment` (feedback: ExperimentProgress); topic `progress`. It drives one or more
workers, each a `world`, `validity` and `feeder_controller` under its own namespace
(graph_backend.py), with the experiment logic of experiments.py: iterations are spread over the
workers, and one whose worker dies or stops answering runs again on another. It writes results
as iterations finish (results.py), and records every topic of the workers, its own progress, the
experiment file and the results into one MCAP file per run (recording.py). One run at a time: a
second goal is answered BUSY, not queued.
"""

from datetime import datetime
import json
import os
import threading
import time
import traceback

from ament_index_python.packages import get_package_share_directory
from pick_msgs.action import RunExperiment
from pick_msgs.msg import ExperimentProgress
from pick_sim_world import conversions as world_conv
from pick_sim_world.errors import check_inside, InvalidArgument, WorldError
from pick_sim_world.node_runner import run
from rcl_interfaces.msg import (
    FloatingPointRange,
    IntegerRange,
    ParameterDescriptor,
    ParameterType,
)
from rclpy.action import ActionServer, CancelResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.exceptions import InvalidNamespaceException
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from rclpy.validate_namespace import validate_namespace
from std_msgs.msg import Header

from . import config, pictures, report
from .experiments import Progress, Runner
from .graph_backend import GraphBackend, GraphError
from .recording import Recorder
from .results import ResultsWriter
from .topic_recorder import TopicRecorder

STOP_WAIT = 15.0        # s a shutdown waits for the run to close its files
DISCOVERY_SETTLE = 3.0  # s the worker list must stay the same before discovery ends
BUILTIN_FILES = os.path.join(get_package_share_directory('experiment_manager'), 'config')
RESULT_FILES = ('iterations.csv', 'checks.csv', 'picks.csv', 'parts.csv', 'summary.json')


def run_directory(output_dir: str, file_id: str) -> str:
    """A new directory name <output_dir>/<id>_<YYYYmmdd-HHMMSS>[_k] that does not exist yet."""
    stamp = datetime.now().strftime('%Y%m%d-%H%M%S')
    base = os.path.join(os.path.abspath(os.path.expanduser(output_dir)), f'{file_id}_{stamp}')
    path, k = base, 1
    while os.path.exists(path):
        k += 1
        path = f'{base}_{k}'
    return path


class ExperimentManagerNode(Node):
    """Translates run_experiment goals into runs of experiments.Runner on the graph."""

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
        call_timeout = self.declare_parameter('call_timeout', 600.0, ParameterDescriptor(
            description='longest wait for one call to a node of the worker, s', read_only=True,
            floating_point_range=[FloatingPointRange(from_value=1.0, to_value=86400.0)])).value
        server_timeout = self.declare_parameter('server_timeout', 10.0, ParameterDescriptor(
            description="longest wait for the worker's services and actions at the start of a "
            'run, s', read_only=True,
            floating_point_range=[FloatingPointRange(from_value=0.1, to_value=3600.0)])).value
        self._rejoin_timeout = self.declare_parameter('rejoin_timeout', 60.0, ParameterDescriptor(
            description='longest wait for a lost worker to come back (its nodes restarted, as '
            '`run` does) before the run goes on without it, s; 0: do not wait', read_only=True,
            floating_point_range=[FloatingPointRange(from_value=0.0, to_value=3600.0)])).value
        self._chunk_size = self.declare_parameter('recording.chunk_size', 1 << 20,
                                                  ParameterDescriptor(
            description='bytes of messages per MCAP chunk; a killed run loses at most one',
            read_only=True, integer_range=[IntegerRange(from_value=1024,
                                                        to_value=1 << 30)])).value
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
        self._topics.write(self._progress.topic_name, msg)
        self._topics.flush()   # once per iteration: a killed manager's recording keeps the rest

    # ------------------------------------------------------------------------- the action
    def _run(self, goal_handle) -> RunExperiment.Result:
        result = RunExperiment.Result()
        if not self._lock.acquire(blocking=False):
            result.error_code = RunExperiment.Result.BUSY
            result.error_msg = ('another experiment is running; goals are not queued: send it '
                                'again when the running one has finished')
            goal_handle.abort()
            return result
        self._goal = goal_handle
        writer = recorder = None
        try:
            goal = goal_handle.request
            check_inside('experiment_file', goal.experiment_file, self._experiment_dirs,
                         'experiment_dirs')
            file = config.load(goal.experiment_file)
            if file.part.mesh_path:
                check_inside('part.mesh', file.part.mesh_path, self._experiment_dirs,
                             'experiment_dirs')
            if goal.resume:
                if not goal.output_dir:
                    raise InvalidArgument('output_dir', '', 'must name the run '
                                                 'directory to resume')
                run_dir = os.path.abspath(os.path.expanduser(goal.output_dir))
            else:
                run_dir = run_directory(goal.output_dir or file.output_dir, file.id)
            check_inside('output_dir', run_dir, self._output_dirs, 'output_dirs')
            writer = ResultsWriter(run_dir, file.text, goal.resume)
            result.results_path = run_dir
            recorder = self._open_recording(run_dir, file, goal.resume)
            result.recording_path = recorder.path
            self._abort.clear()
            backends = self._workers_of_run()
            self.get_logger().info(f'running {file.path} into {run_dir} on '
                                   f'{len(backends)} worker(s): '
                                   f'{", ".join(b.worker or "." for b in backends)}')
            runner = Runner(file, backends, writer, self._publish_progress, self._abort)
            try:
                summary = runner.run()
            finally:
                for k in runner.lost_workers:
                    self.get_logger().warning(f'worker {backends[k].worker or "."} was lost '
                                              '(missing at the start, or during the run)')
                for k in runner.rejoined:
                    self.get_logger().warning(f'worker {backends[k].worker or "."} was lost '
                                              'and came back')
            result.summary_json = json.dumps(summary)
            try:
                pictures.write(file, run_dir)
                result.report_path = report.write(run_dir)
            except Exception as exc:  # the results stand without their report
                self.get_logger().error(f'the report could not be written: {exc}\n'
                                        f'{traceback.format_exc()}')
            goal_handle.succeed()
        except (WorldError, GraphError) as exc:
            result.error_code = (exc.code if isinstance(exc, GraphError)
                                 else world_conv.error_code(exc))
            result.error_msg = str(exc)
            self.get_logger().error(f'run_experiment: {exc}')
            self._end(goal_handle, result)
        except Exception as exc:  # a bug: answer, log, keep serving
            result.error_code = RunExperiment.Result.INTERNAL
            result.error_msg = f'internal error: {type(exc).__name__}: {exc}'
            self.get_logger().error(f'{result.error_msg}\n{traceback.format_exc()}')
            self._end(goal_handle, result)
        finally:
            if recorder is not None:
                self._close_recording(recorder, writer)
            if writer is not None:
                writer.close()
                if result.error_code:
                    result.error_msg += (f' (finished iterations are kept in {writer.directory};'
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

    def _open_recording(self, run_dir: str, file: config.ExperimentFile,
                        resume: bool) -> Recorder:
        path, k = os.path.join(run_dir, 'recording.mcap'), 1
        while resume and os.path.exists(path):
            k += 1
            path = os.path.join(run_dir, f'recording_{k}.mcap')
        recorder = Recorder(path, self._chunk_size)
        recorder.attach('experiment.yaml', file.text.encode(), 'application/yaml')
        recorder.metadata('run', {'experiment_id': file.id, 'seed': str(file.seed),
                                  'experiment_file': file.path, 'run_directory': run_dir,
                                  'resumed': str(bool(resume)),
                                  'node': self.get_fully_qualified_name()})
        recorder.flush()
        self._topics.start(recorder)
        return recorder

    def _close_recording(self, recorder: Recorder, writer: ResultsWriter | None) -> None:
        self._topics.stop()
        try:
            for name in RESULT_FILES if writer is not None else ():
                path = writer.path(name)
                if os.path.exists(path):
                    with open(path, 'rb') as f:
                        recorder.attach(name, f.read(), 'application/json'
                                        if name.endswith('.json') else 'text/csv')
        finally:
            recorder.close()

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
