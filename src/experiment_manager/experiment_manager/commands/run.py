"""`run`: bring up the graph on this machine and run experiment files through it.

    run [EXPERIMENT_FILE ...] [--output DIR | --resume RUN_DIR] [--iterations N] [--adaptive]
        [--workers N] [--at-once N] [--respawns N] [--namespace NS] [--logs DIR]
    run --board FILE.kicad_pcb [--models DIR] [--boards-per-hour N] [--output DIR] ...

Starts N workers (`world`, `validity` and `feeder_controller` under <NS>/worker_<k>, default: a
worker per CPU) and `experiment_manager` under <NS> as separate processes (DDS between them, as
on a cell), sends `run_experiment` for each file, the next while the one before runs (--at-once
2: it fills the workers the one before leaves idle, and gets them only then), shows the progress
of the earliest, and prints where each file's results and recording are. A worker node that dies
is reported and started again (up to --respawns times); the manager runs the iteration it lost
again and takes the worker back, and the run fails only when no worker is left. Each node may
read and write only where the goals need (mesh_dirs, experiment_dirs, output_dirs). Without a
file it runs the built-in default (`share/experiment_manager/config/default_experiment.yaml`),
or with --resume the file the run directory keeps. --iterations N caps every experiment at N
iterations (a quick look at a long study; the run directory keeps the file that ran); --adaptive
runs each experiment only until its decision is settled (sampling.py), at most its iterations. A
board file (`board:` in place of `part:`), or --board in the built-in cell, runs as its parts'
files, and ends with the board's one answer (commands/boards.py, docs/boards.md).

Exit codes: 0 done; 1 the run failed (the message says why; finished iterations are kept);
2 bad input (the experiment file, an option); 130 interrupted (Ctrl-C: the run is canceled and
its files closed).
"""

import argparse
from dataclasses import dataclass
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

from .. import experiment_file
from ..analysis import summary as summary_model
from ..analysis import wording
from ..analysis.headlines import headlines
from ..running.workers import RUNS_AT_ONCE
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
from .progress_bar import ProgressBar
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
    parser.add_argument('--at-once', type=int, metavar='N', default=RUNS_AT_ONCE,
                        help=f'files run at once (default {RUNS_AT_ONCE}: the next fills the '
                        'workers the one before leaves idle; 1: one after another)')
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
    if not 1 <= args.at_once <= RUNS_AT_ONCE:
        parser.error(f'--at-once {args.at_once} must be within [1, {RUNS_AT_ONCE}] (the most the '
                     'manager runs at once)')
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
        code = _run(node, client, goals, graph, bar, args.boards, args.at_once)
        return code or _board_answers(args.boards)
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


@dataclass
class Flying:
    """A goal sent: the file as given, whether it runs adaptively, its handle and result."""
    given: str
    adaptive: bool
    handle: object = None
    result: object = None


def _run(node: Node, client: LockedActionClient, goals: list, graph: Graph, bar,
         boards: list[BoardRun], at_once: int) -> int:
    """Run the goals, `at_once` at a time: the next is sent while the one before runs, and
    fills the workers it leaves idle (the manager's RUNS_AT_ONCE). The bar shows the earliest
    goal in flight. A goal that fails cancels the others and ends the run."""
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
    pending, flying = list(goals), []
    try:
        while pending or flying:
            while pending and len(flying) < at_once:
                goal, _, given, adaptive = pending.pop(0)
                sent = Flying(given, adaptive)
                if not _send(node, client, goal, sent, flying, bar, manager):
                    return 1
            if not report_dead(node, lambda: any(f.result.done() for f in flying), graph,
                               float('inf'), bar):
                return 1
            for done in [f for f in flying if f.result.done()]:
                flying.remove(done)
                code = _finished(done, bar, boards)
                if code:
                    return code
    finally:
        if flying:      # a goal failed, the manager died or Ctrl-C: the others end with it
            _cancel(node, flying, manager)
    return 0


def _send(node: Node, client: LockedActionClient, goal, sent: Flying, flying: list[Flying],
          bar, manager) -> bool:
    """Send a goal; False (said why) when the manager did not accept it."""
    print(f'run: {sent.given}', file=sys.stderr)

    def feedback(f) -> None:
        if flying and flying[0] is sent:      # the bar shows the earliest goal in flight
            bar.at_most = sent.adaptive
            bar.update(f.feedback.progress)
    send = client.send_goal_async(goal, feedback_callback=feedback)
    spin_until(node, send.done, [manager], START_TIMEOUT)
    sent.handle = send.result()
    if sent.handle is None or not sent.handle.accepted:
        print('run: the experiment manager did not accept the goal', file=sys.stderr)
        return False
    sent.result = sent.handle.get_result_async()
    flying.append(sent)
    return True


def _cancel(node: Node, flying: list[Flying], manager) -> None:
    """Cancel the goals in flight and wait for each to close its files."""
    for f in flying:
        f.handle.cancel_goal_async()
    for f in flying:
        spin_until(node, f.result.done, [manager], STOP_TIMEOUT)
    flying.clear()


def _finished(done: Flying, bar, boards: list[BoardRun]) -> int:
    """Print a goal's result; its exit code (0 when it succeeded)."""
    result = done.result.result().result
    bar.close()
    if result.error_code:
        print(f'run: {done.given} failed: {result.error_msg}', file=sys.stderr)
        return 2 if result.error_code == RunExperiment.Result.INVALID_ARGUMENT else 1
    print(f'results:   {result.results_path}')
    print(f'recording: {result.recording_path}')
    print(f'summary:   {os.path.join(result.results_path, "summary.json")}')
    if result.report_path:
        print(f'report:    {result.report_path}')
    summary = summary_model.validate(summary_model.migrate(json.loads(result.summary_json)))
    print('\n'.join(headlines(summary)))
    decided(boards, done.given, options(summary),
            result.results_path)
    # the manager's decisions in one table, each with the stage that stops most parts and
    # its first reason (the report gives them all)
    print('verdicts:\n' + '\n'.join(wording.verdict_table(
        [(v.option, v.verdict, v.stops_most, v.reasons[0]) for v in result.verdicts])))
    return 0
