"""Where the recording subscriptions run, and what it costs the calls the manager waits on.

Starts a worker (world, validity, feeder_controller) and drives one feeder_emptying iteration
through GraphBackend from a node on a multi-threaded executor, three ways: no recording
subscriptions; the five recording subscriptions on that same node and executor; the five on
their own node and single-threaded executor (TopicRecorder, what the manager does). Prints the
wall time of the iteration and of each kind of call.

    tools/ws python -m bench.graph.bench_recorder_executor
"""

import collections
import os
import subprocess
import sys
import threading
import time

from experiment_manager import experiment_file
from experiment_manager.experiment_file.plan import plan
from experiment_manager.graph.graph_backend import GraphBackend
from experiment_manager.graph.topic_recorder import QOS, RECORDED, TopicRecorder
from experiment_manager.running.procedures import run_unit
import rclpy
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node

from bench.paper_case import one_worker

FILE = """id: probe
seed: 1
experiments:
  - {id: feeder, type: feeder_emptying, iterations: 1, parts: 60, optimal_range: [51, 61],
     max_vibrations: 300}
"""


MODES = ('none', 'same executor', 'own executor')


def iteration(ns: str, mode: str) -> tuple[float, dict]:
    node = Node('probe', namespace=ns)
    executor = MultiThreadedExecutor(num_threads=4)
    executor.add_node(node)
    group = ReentrantCallbackGroup()
    keep = []   # the TopicRecorder lives as long as the iteration
    if mode == 'same executor':
        for topic, msg_type in RECORDED:
            node.create_subscription(msg_type, f'worker_0/{topic}', lambda data: None, QOS,
                                     raw=True, callback_group=group)
    elif mode == 'own executor':
        keep.append(TopicRecorder(f'probe_rec_{os.getpid()}', ns))
        keep[-1].add('worker_0')
    thread = threading.Thread(target=executor.spin, daemon=True)
    thread.start()
    backend = GraphBackend(node, 'worker_0', group, 600.0, 30.0, lambda: False)
    times: dict[str, float] = collections.defaultdict(float)
    for name in ('reset', 'drop', 'remove', 'parts', 'check', 'feed'):
        call = getattr(backend, name)

        def timed(*args, _call=call, _name=name, **kwargs):
            start = time.perf_counter()
            try:
                return _call(*args, **kwargs)
            finally:
                times[_name] += time.perf_counter() - start
        setattr(backend, name, timed)
    file = experiment_file.parse(FILE)
    backend.start(file)
    start = time.perf_counter()
    run_unit(file, plan(file, file.experiments[0], {})[0], backend)
    total = time.perf_counter() - start
    keep.clear()
    return total, times


def main() -> int:
    if len(sys.argv) == 3:    # one mode, in a process of its own (a fresh rclpy)
        rclpy.init()
        total, times = iteration(sys.argv[1], sys.argv[2])
        calls = ', '.join(f'{k} {v:.1f}' for k, v in sorted(times.items()))
        print(f'recording subscriptions: {sys.argv[2]:<14} iteration {total:7.1f} s  '
              f'({calls} s)', flush=True)
        os._exit(0)   # the executor threads are daemons; nothing to close cleanly
    with one_worker('probe') as ns:
        print('one feeder_emptying iteration (60 parts, range 51-61, 300 vibrations)',
              flush=True)
        for mode in MODES:
            subprocess.run([sys.executable, '-m', __spec__.name, ns, mode], check=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
