"""`run`: bring up the graph on this machine and run experiment files through it.

    run [EXPERIMENT_FILE ...] [--output DIR | --resume RUN_DIR] [--iterations N] [--adaptive]
        [--workers N] [--respawns N] [--namespace NS] [--logs DIR]
    run --board FILE.kicad_pcb [--models DIR] [--boards-per-hour N] [--output DIR] ...

Starts N workers (`world`, `validity` and `feeder_controller` under <NS>/worker_<k>, default: a
worker per CPU) and `experiment_manager` under <NS> as separate processes (DDS between them, as
on a cell), sends `run_experiment` for each file in turn, shows a progress bar, and prints where
the results and the recording are. A worker node that dies is reported and started again (up to
--respawns times); the manager runs the iteration it lost again and takes the worker back, and
the run fails only when no worker is left. Each node may read and write only where the goals
need (mesh_dirs, experiment_dirs, output_dirs). Without a file it runs the built-in default
(`share/experiment_manager/config/default_experiment.yaml`), or with --resume the file the run
directory keeps. --iterations N caps every experiment at N iterations (a quick look at a long
study; the run directory keeps the file that ran); --adaptive runs each experiment only until
its decision is settled (sampling.py), at most its iterations. A board file (`board:` in place
of `part:`), or --board in the built-in cell, runs as its parts' files, and ends with the
board's one answer (commands/boards.py, docs/boards.md).

Exit codes: 0 done; 1 the run failed (the message says why; finished iterations are kept);
2 bad input (the experiment file, an option); 130 interrupted (Ctrl-C: the run is canceled and
its files closed).
"""

import argparse
import json
import os
import sys
import tempfile
import time

from ament_index_python.packages import get_package_share_directory
from pick_common.errors import InvalidArgument
from pick_common.node_runner import handshake
from pick_common.rclpy_adapter import LockedActionClient
from pick_msgs.action import RunExperiment
import rclpy
from rclpy.exceptions import InvalidNamespaceException
from rclpy.node import Node
from rclpy.signals import SignalHandlerOptions
from rclpy.validate_namespace import validate_namespace
from tqdm import tqdm

from .. import experiment_file
from ..analysis import summary as summary_model
from ..analysis import wording
from ..analysis.headlines import headlines
from . import interrupt
from .boards import (
    board_file,
    BoardRun,
    cell_file,
    decided,
    expand_boards,
    interrupted,
    options,
)
from .claim import claim, NamespaceInUse
from .supervisor import Graph, report_dead, spin_until, start_graph

MAX_WORKERS = 64
START_TIMEOUT = 60.0    # s for the manager's action server to appear
RESPAWNS = 3            # times a worker node that died is started again, per run
STOP_TIMEOUT = 30.0     # s for a canceled run to close its files


def default_workers() -> int:
    """A worker per CPU this process may use (PyBullet steps on one thread), at most 8."""
    return min(len(os.sched_getaffinity(0)), 8)


def default_file() -> str:
    return os.path.join(get_package_share_directory('experiment_manager'), 'config',
                        'default_experiment.yaml')


class ProgressBar:
    """The run's progress on `stream`: on a terminal, one tqdm line redrawn within the
    terminal's width (`columns`, or the terminal's own as it is resized), the phase cut at its
    end; otherwise (a log), a line per 5 % and per experiment."""

    def __init__(self, stream=sys.stderr, columns: int | None = None) -> None:
        self.stream, self.columns = stream, columns
        self.tty = stream.isatty()
        # an adaptive run's estimate is of the most it may take (running/estimate.py): said so
        self.at_most = False
        self._bar: tqdm | None = None
        self._last = (None, -1)

    @staticmethod
    def _clock(seconds: float) -> str:
        s = int(seconds)
        return f'{s // 3600}:{s // 60 % 60:02d}:{s % 60:02d}'

    def update(self, p) -> None:
        eta = (('at most ' if self.at_most else '') + self._clock(p.eta)) if p.eta else '?'
        status = f'{self._clock(p.elapsed)} elapsed, eta {eta}  {p.phase}'
        if not self.tty:
            fraction = p.iterations_done / p.iterations_total if p.iterations_total else 0.0
            key = (p.experiment_id, int(fraction * 20))
            if key != self._last:
                self._last = key
                self.stream.write(f'{p.iterations_done}/{p.iterations_total}  {status}\n')
                self.stream.flush()
            return
        if self._bar is None:
            self._bar = tqdm(total=p.iterations_total, file=self.stream, ncols=self.columns,
                             dynamic_ncols=self.columns is None, ascii=' #', mininterval=0,
                             bar_format='{n_fmt}/{total_fmt} [{bar:24}] {desc}')
        self._bar.total, self._bar.n = p.iterations_total, p.iterations_done
        self._bar.set_description_str(status, refresh=False)
        self._bar.refresh()

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None


def _parse(argv: list[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog='run', description=__doc__.split('\n\n')[0])
    parser.add_argument('experiment_files', nargs='*', metavar='experiment_file',
                        help='experiment YAML files, run in turn (default: the built-in one)')
    where = parser.add_mutually_exclusive_group()
    where.add_argument('--output', help="directory for the run's directory (default: the "
                       "file's output_dir)")
    where.add_argument('--resume', metavar='RUN_DIR',
                       help='finish the interrupted run in RUN_DIR (with the file it keeps, '
                       'RUN_DIR/experiment.yaml, unless a file is given: it must be the same)')
    parser.add_argument('--board', metavar='FILE.kicad_pcb',
                        help='decide every through-hole part of a KiCad board in the built-in '
                        'cell (config/board_cell.yaml: every option, jaws and a cup); a board '
                        'file of your own is an experiment file with board: (docs/boards.md)')
    parser.add_argument('--models', metavar='DIR', help="with --board: KiCad's 3D library "
                        "folder (default: KiCad's KICAD<n>_3DMODEL_DIR variables)")
    parser.add_argument('--boards-per-hour', type=float, metavar='N',
                        help="with --board: the line's boards per hour (default: the built-in "
                        "cell's)")
    parser.add_argument('--namespace', default='/',
                        help='namespace of the graph (default /): worker k runs in '
                        '<namespace>/worker_<k>')
    parser.add_argument('--workers', type=int, metavar='N', default=default_workers(),
                        help=f'worker processes to start (default {default_workers()}: a '
                        "worker per CPU, at most 8); a board's parts are cut on as many "
                        'processes, with --check too')
    parser.add_argument('--iterations', type=int, metavar='N',
                        help='cap every experiment at N iterations')
    parser.add_argument('--adaptive', action='store_true',
                        help="sample each experiment until its decision is settled, at most "
                        "its iterations (the file's sampling.mode: adaptive)")
    parser.add_argument('--respawns', type=int, metavar='N', default=RESPAWNS,
                        help=f'times a worker node that died is started again (default '
                        f'{RESPAWNS}; 0: never, and the manager does not wait for it)')
    parser.add_argument('--logs', help="directory for the nodes' logs (default: a temporary "
                        'directory, printed)')
    parser.add_argument('--check', action='store_true',
                        help="only read each file, draw its part sheet (its part, mass "
                        "centre, collision pieces, and the gripper at each grasp's pick and "
                        "place) into --output or the file's output_dir, and print what the "
                        "run would run (with --iterations and --adaptive as given); no graph "
                        "is started")
    args = parser.parse_args(argv)
    if args.check and (args.resume or not (args.experiment_files or args.board)):
        parser.error('--check reads the experiment files given: give one or more')
    if args.board and (args.experiment_files or args.resume):
        parser.error('--board runs one board in the built-in cell: give no experiment file '
                     'and no --resume (a board file of your own is an experiment file)')
    if (args.models or args.boards_per_hour is not None) and not args.board:
        parser.error('--models and --boards-per-hour go with --board')
    if args.resume and len(args.experiment_files) > 1:
        parser.error('--resume finishes one run: give one experiment file')
    if (args.iterations is not None or args.adaptive) and args.resume:
        parser.error('--resume runs the file of the run directory: no --iterations or '
                     '--adaptive')
    if not 0 <= args.respawns <= 100:
        parser.error(f'--respawns {args.respawns} must be within [0, 100]')
    if args.iterations is not None and not 1 <= args.iterations <= experiment_file.MAX_ITERATIONS:
        parser.error(f'--iterations {args.iterations} must be within '
                     f'[1, {experiment_file.MAX_ITERATIONS}]')
    if not 1 <= args.workers <= MAX_WORKERS:
        parser.error(f'--workers {args.workers} must be within [1, {MAX_WORKERS}]')
    try:
        validate_namespace(args.namespace)
    except InvalidNamespaceException as exc:
        parser.error(f'--namespace {args.namespace!r}: {exc}')
    return args


def _goals(args: argparse.Namespace,
           temporary: list[str]) -> list[tuple[RunExperiment.Goal, str, str, bool]]:
    """A goal per file with the file's mesh ('' for none), the path as given (the goal's may
    be a reduced copy) and whether it runs adaptively, every file checked first. Raises
    InvalidArgument naming the file (InvalidFile when it has several errors). The copies that
    --iterations and --adaptive write are added to `temporary`, for the caller to remove."""
    goals = []
    files = args.experiment_files or [os.path.join(args.resume, 'experiment.yaml')
                                      if args.resume else default_file()]
    for given in expand_boards(_board_given(args) or files, args, args.boards):
        path = part = os.path.abspath(given)
        try:
            file = next((b.read[path] for b in args.boards if path in b.read), None) \
                or experiment_file.load(path)
        except InvalidArgument as exc:
            named = [InvalidArgument(f'{path}: {e.field}', e.value, e.rule) for e in
                     (exc.errors if isinstance(exc, experiment_file.InvalidFile) else [exc])]
            raise (named[0] if len(named) == 1 else experiment_file.InvalidFile(named)) from None
        if args.iterations is not None or args.adaptive:
            # the run directory keeps the file that ran; this copy goes when run ends
            fd, path = tempfile.mkstemp(prefix=f'{file.id}_', suffix='.yaml')
            temporary.append(path)
            with os.fdopen(fd, 'w') as f:
                f.write(experiment_file.reduced(file, args.iterations, args.adaptive))
        # a board's part that an earlier run of the board left interrupted resumes there
        board = next((b for b in args.boards if part in b.by_path), None)
        cut = board and not args.resume and interrupted(board.directory, file.id, path)
        output = os.path.abspath(os.path.expanduser(args.resume or cut or args.output
                                                    or file.output_dir))
        goals.append((RunExperiment.Goal(experiment_file=path, resume=bool(args.resume or cut),
                                         output_dir=output), file.part.mesh_path, given,
                      args.adaptive or file.sampling.adaptive))
    return goals


def _board_given(args: argparse.Namespace) -> list[str]:
    """With --board: the board file of the built-in cell with that board, written into the
    output directory; else []."""
    if not args.board:
        return []
    return [board_file(args.board, args.models, args.boards_per_hour,
                       cell_file(get_package_share_directory('experiment_manager')),
                       os.path.abspath(os.path.expanduser(args.output or 'results')))]


def main(argv: list[str] | None = None) -> int:
    args = _parse(sys.argv[1:] if argv is None else argv)
    args.boards = []        # the boards run, for their one answer at the end
    if args.check:
        from .check import check  # the sheet's drawing is loaded only to draw it
        return check(_board_given(args) or args.experiment_files, args.output,
                     args.iterations, args.adaptive, args.workers)
    temporary: list[str] = []
    try:
        return _main(args, temporary)
    finally:
        for path in temporary:
            os.remove(path)


def _main(args: argparse.Namespace, temporary: list[str]) -> int:
    try:
        goals = _goals(args, temporary)     # fail here, before any process starts
    except InvalidArgument as exc:
        print(f'run: {exc}', file=sys.stderr)
        return 2
    if not goals:           # a board whose every part was done before: its answer again
        return _board_answers(args.boards)
    log_dir = args.logs or tempfile.mkdtemp(prefix='pick_run_logs_')
    os.makedirs(log_dir, exist_ok=True)
    print(f'run: {len(goals)} experiment file(s); node logs in {log_dir}', file=sys.stderr)
    interrupt.install()     # spin_until stops between two spin_once calls, never inside one
    # No rclpy signal handlers: Ctrl-C (or SIGTERM) must leave the context alive to cancel the
    # run and wait for the manager to close its files (rclpy's handler shuts it down first).
    rclpy.init(args=['--ros-args', '-r', f'__ns:={args.namespace}'],
               signal_handler_options=SignalHandlerOptions.NO)
    node = Node('experiment_cli')
    bar = ProgressBar()
    lock = client = graph = None
    try:
        lock = claim(node, args.namespace, args.workers)   # released after our nodes stop
        graph = Graph(start_graph(args.namespace, log_dir, args.workers,
                                  [g.experiment_file for g, *_ in goals],
                                  [m for _, m, *_ in goals],
                                  [g.output_dir for g, *_ in goals], args.respawns),
                      args.respawns)
        client = LockedActionClient(node, RunExperiment, 'run_experiment')
        for goal, _, given, adaptive in goals:
            bar.at_most = adaptive
            code = _run(node, client, goal, given, graph, bar, args.boards)
            if code:
                return code
        return _board_answers(args.boards)
    except (FileNotFoundError, NamespaceInUse) as exc:   # before any goal was sent
        print(f'run: {exc}', file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        if client is not None:
            print('\nrun: interrupted; the run was canceled (its files are closed by the '
                  'manager)', file=sys.stderr)
        return 130
    finally:
        bar.close()
        if client is not None:
            client.destroy()
        node.destroy_node()
        rclpy.try_shutdown()
        for p in graph.procs if graph else []:   # SIGINT: the manager cancels its run and
            p.stop()                              # closes its files
        if lock is not None:
            lock.close()        # the namespace is free once our nodes are gone


def _board_answers(boards: list[BoardRun]) -> int:
    """Each board's one answer, printed and written; 0."""
    for board in boards:
        print('\n'.join(board.lines()))
        print(f'board:     {board.write()}')
    return 0


def _run(node: Node, client: LockedActionClient, goal, given: str, graph: Graph, bar,
         boards: list[BoardRun]) -> int:
    print(f'run: {given}', file=sys.stderr)
    manager = graph.manager
    if not report_dead(node, client.server_is_ready, graph, START_TIMEOUT, bar) \
            or not client.server_is_ready():
        print(f'run: the experiment manager did not start (run_experiment did not appear '
              f'within {START_TIMEOUT:g} s)', file=sys.stderr)
        return 1
    if not handshake(node, [client], lambda future, timeout: spin_until(
            node, future.done, [manager], timeout) is None and future.done(),
            time.monotonic() + START_TIMEOUT, lambda: not manager.running()):
        print('run: the experiment manager did not answer a probe of run_experiment within '
              f'{START_TIMEOUT:g} s', file=sys.stderr)
        return 1
    send = client.send_goal_async(goal, feedback_callback=lambda f: bar.update(f.feedback.progress))
    spin_until(node, send.done, [manager], START_TIMEOUT)
    handle = send.result()
    if handle is None or not handle.accepted:
        print('run: the experiment manager did not accept the goal', file=sys.stderr)
        return 1
    result_future = handle.get_result_async()
    try:
        if not report_dead(node, result_future.done, graph, float('inf'), bar):
            return 1
    except KeyboardInterrupt:
        handle.cancel_goal_async()
        spin_until(node, result_future.done, [manager], STOP_TIMEOUT)
        raise
    result = result_future.result().result
    bar.close()
    if result.error_code:
        print(f'run: failed: {result.error_msg}', file=sys.stderr)
        return 2 if result.error_code == RunExperiment.Result.INVALID_ARGUMENT else 1
    print(f'results:   {result.results_path}')
    print(f'recording: {result.recording_path}')
    print(f'summary:   {os.path.join(result.results_path, "summary.json")}')
    if result.report_path:
        print(f'report:    {result.report_path}')
    summary = summary_model.validate(summary_model.migrate(json.loads(result.summary_json)))
    print('\n'.join(headlines(summary)))
    decided(boards, given, options(summary),
            result.results_path)
    # the manager's decisions in one table, each with the stage that stops most parts and
    # its first reason (the report gives them all)
    print('verdicts:\n' + '\n'.join(wording.verdict_table(
        [(v.option, v.verdict, v.stops_most, v.reasons[0]) for v in result.verdicts])))
    return 0
