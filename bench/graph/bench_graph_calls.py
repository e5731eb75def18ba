"""Where the graph's cost goes in an iteration, call by call: the same iterations of one
experiment run on the cores (LocalBackend) and through one worker's nodes (GraphBackend, from
this process, as the manager calls them, without the manager's recording), every backend call
timed. Prints per kind of call (a feed_cycle that only answers PICK apart from one that feeds
or vibrates) the calls, their time on each and what the graph adds per call, the whole
iterations' ratio, and whether the two gave the same rows (they must).

    tools/ws python -m bench.graph.bench_graph_calls [FILE] [--experiment ID] [--group N]
        [--iterations K]
    (default: bench/pth2_feeder.yaml, its first experiment, group 0, one iteration)

For a sweep, --group is the part count: e.g. `--experiment sweep --group 60 --iterations 5
src/experiment_manager/config/test_case/pth2.yaml`. bench_experiment.py measures the whole
run's ratio (with the recording); bench_calls.py the round trips by scene size.
"""

import argparse
import collections
import os
import sys
import threading
import time

from experiment_manager import experiment_file
from experiment_manager.experiment_file.plan import plan
from experiment_manager.graph.graph_backend import GraphBackend
from experiment_manager.running.local_backend import LocalBackend
from experiment_manager.running.procedures import run_unit
from feeder_controller.policy import PICK
import rclpy
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node

from bench.paper_case import one_worker

FEEDER_FILE = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'pth2_feeder.yaml')
CALLS = ('reset', 'drop', 'remove', 'parts', 'check', 'feed')


class Timed:
    """A backend whose calls are timed and counted by kind."""

    def __init__(self, backend) -> None:
        self.backend = backend
        self.seconds: dict[str, float] = collections.defaultdict(float)
        self.calls: collections.Counter = collections.Counter()

    def __getattr__(self, name: str):
        call = getattr(self.backend, name)
        if name not in CALLS:
            return call

        def timed(*args, **kwargs):
            start = time.perf_counter()
            out = call(*args, **kwargs)
            kind = name
            if name == 'feed':
                kind = 'feed (PICK)' if out.decision == PICK else 'feed (feeds, vibrates)'
            self.seconds[kind] += time.perf_counter() - start
            self.calls[kind] += 1
            return out
        return timed


def through_graph(file: experiment_file.ExperimentFile, units: list) -> tuple[Timed, list, float]:
    """The units through a worker of this process's own, on a private domain."""
    with one_worker('graph_calls') as ns:
        rclpy.init()
        node = Node('graph_calls', namespace=ns)
        executor = MultiThreadedExecutor(num_threads=4)    # as the manager's
        executor.add_node(node)
        threading.Thread(target=executor.spin, daemon=True).start()
        graph = GraphBackend(node, 'worker_0', ReentrantCallbackGroup(), 600.0, 60.0,
                             lambda: False)
        graph.start(file)
        timed = Timed(graph)
        start = time.perf_counter()
        records = [run_unit(file, u, timed) for u in units]
        return timed, records, time.perf_counter() - start


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('file', nargs='?', default=FEEDER_FILE)
    parser.add_argument('--experiment', help='its id (default: the first)')
    parser.add_argument('--group', type=int, default=0,
                        help='bin index or part count (default 0: a bin or a feeder run)')
    parser.add_argument('--iterations', type=int, default=1)
    args = parser.parse_args()
    file = experiment_file.load(args.file)
    ids = [e.id for e in file.experiments]
    if args.experiment not in (None, *ids):
        parser.error(f'--experiment: {args.experiment!r} is not one of {ids}')
    exp = file.experiment(args.experiment or ids[0])
    units = [u for u in plan(file, exp, {}) if u.group == args.group][:args.iterations]
    if not units:
        parser.error(f'--group: {exp.id!r} has no group {args.group}')

    with LocalBackend() as local:
        local.start(file)
        cores = Timed(local)
        start = time.perf_counter()
        on_cores = [run_unit(file, u, cores) for u in units]
        cores_wall = time.perf_counter() - start
    graph, on_graph, graph_wall = through_graph(file, units)

    def same(a, b) -> bool:
        return all({k: v for k, v in x.iteration.items() if k != 'wall_time'}
                   == {k: v for k, v in y.iteration.items() if k != 'wall_time'}
                   for x, y in zip(a, b, strict=True))
    print(f'{exp.id} ({exp.type}), group {args.group}, {len(units)} iteration(s) of '
          f'{os.path.basename(args.file)}')
    print(f'the iterations: cores {cores_wall:.2f} s, graph {graph_wall:.2f} s, ratio '
          f'{graph_wall / cores_wall:.3f}; same rows: {same(on_cores, on_graph)}')
    print(f'{"call":<24} {"calls":>6} {"cores s":>8} {"graph s":>8} {"added ms/call":>14}')
    for kind in sorted(graph.calls):
        n = graph.calls[kind]
        added = 1000.0 * (graph.seconds[kind] - cores.seconds[kind]) / n
        print(f'{kind:<24} {n:6d} {cores.seconds[kind]:8.2f} {graph.seconds[kind]:8.2f} '
              f'{added:14.1f}')
    os._exit(0)     # the executor thread is a daemon; nothing to close cleanly


if __name__ == '__main__':
    sys.exit(main())
