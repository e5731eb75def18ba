"""What one call to a worker costs over the graph, by the parts in the scene: the round trip of
`get_parts`, of `check_parts` (one target, neighbours checked) and of `remove_parts` without a
settle (no physics: only the graph's work), in the widest bin of the test case's PTH2 file,
from GraphBackend as the manager makes them, with the world's `markers` on and off
(`publish_markers`). Median of 30, 10 and 20 calls.

    tools/ws python -m bench.graph.bench_calls [--parts 30 150 480]

The cores make none of these round trips; their cost is what the graph adds to an iteration
per call (bench_experiment.py measures the sum).
"""

import argparse
import os
import statistics
import subprocess
import sys
import threading
import time

from experiment_manager import experiment_file
from experiment_manager.experiment_file import BIN_STATIC
from experiment_manager.experiment_file.plan import plan
from experiment_manager.graph.graph_backend import GraphBackend
import rclpy
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node

from bench.paper_case import one_worker, TEST_CASE

# 480 radial capacitors (PTH2) fit its widest bin, 300 x 300 x 22 mm
PTH2 = os.path.join(TEST_CASE, 'pth2.yaml')


def timed(call, n: int) -> float:
    """The median wall time of n calls, ms."""
    times = []
    for _ in range(n):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return 1000.0 * statistics.median(times)


def probe(ns: str, parts: int) -> str:
    """The three medians for a bin of `parts` parts, from a node spun like the manager's."""
    rclpy.init()
    node = Node('calls_probe', namespace=ns)
    executor = MultiThreadedExecutor(num_threads=4)
    executor.add_node(node)
    threading.Thread(target=executor.spin, daemon=True).start()
    backend = GraphBackend(node, 'worker_0', ReentrantCallbackGroup(), 600.0, 30.0,
                           lambda: False)
    file = experiment_file.load(PTH2)
    backend.start(file)
    units = plan(file, next(e for e in file.experiments if e.type == BIN_STATIC), {})
    unit = max(units, key=lambda u: u.container.inner_size[0] * u.container.inner_size[1])
    backend.reset(unit.container, 1)
    states, _ = backend.drop(parts, 'container')
    ids = iter(states.ids.tolist())
    get = timed(backend.parts, 30)
    check = timed(lambda: backend.check(unit.container, states, [int(states.ids[0])], True), 10)
    remove = timed(lambda: backend.remove([next(ids)], settle=False), 20)
    return f'{get:9.1f} {check:11.1f} {remove:12.1f}'


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--parts', type=int, nargs='+', default=[30, 150, 480])
    parser.add_argument('--probe', nargs=2, help=argparse.SUPPRESS)   # NS PARTS, in a child
    args = parser.parse_args()
    if args.probe:      # one scene, in a process of its own (a fresh rclpy)
        print(probe(args.probe[0], int(args.probe[1])), flush=True)
        os._exit(0)     # the executor thread is a daemon; nothing to close cleanly
    print('median round trip, ms      get_parts check_parts remove_parts')
    for markers in ('true', 'false'):
        with one_worker(f'calls_{markers}', ['-p', f'publish_markers:={markers}']) as ns:
            for parts in args.parts:
                out = subprocess.run([sys.executable, '-m', __spec__.name, '--probe', ns,
                                      str(parts)],
                                     check=True, capture_output=True, text=True, timeout=600)
                print(f'{parts:4d} parts, markers {markers:<5} {out.stdout.strip()}', flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
