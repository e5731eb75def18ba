"""An experiment file on the cores in this process (LocalBackend), through the graph with one
worker and with two (the `run` command: node processes over DDS), in one run: wall time per
iteration and type, the graph's ratio to the cores, the throughput of two workers against
one, the peak memory of each worker's processes and the CPU time of each node over the run
against the cores' (this process's), and whether the result files of the three are identical
(they must be).

    tools/ws python -m bench.experiment.bench_experiment [FILE] [--iterations N] [--workers 1 2]
        [--rounds R] [--paper-case RUN_DIR ...]
    (default: the built-in experiment file)

--rounds R runs the three R times in turn and prints the ratio and the throughput of each
round and their medians (the table sums the rounds): on this shared machine single runs of the
same code spread by 10 % and more (docs/benchmarks.md), more than most levers.

--iterations N caps every experiment of FILE at N iterations (as `run --iterations` does), so
that a test-case file can be the workload: e.g. `--iterations 2
src/experiment_manager/config/test_case/pth2.yaml`, about 17 min.

--paper-case adds the wall time of the paper's full test case from the run directories of a
run made before (6.1 hours on this machine, so not run here: `make run
RUN_ARGS="--output DIR src/experiment_manager/config/test_case/pth0.yaml ...pth1.yaml
...pth2.yaml"`, resumed with `--resume RUN_DIR` if it was interrupted): the recordings' spans,
summed over resumes.
"""

import argparse
import collections
import os
import re
import statistics
import subprocess
import sys
import tempfile
import threading
import time

from experiment_manager import experiment_file
from experiment_manager.analysis.results import read_text_rows, ResultsWriter
from experiment_manager.analysis.rows import FILES
from experiment_manager.commands.launcher import executable
from experiment_manager.commands.run import default_file
from experiment_manager.running.local_backend import LocalBackend
from experiment_manager.running.scheduler import Runner
from pick_common.errors import InvalidArgument

from bench.paper_case import print_full_case


def rows(directory: str, name: str, drop: tuple[str, ...] = ()) -> list[dict]:
    return read_text_rows(os.path.join(directory, f'{name}.csv'), drop)


def per_type(directory: str) -> tuple[dict[str, float], dict[str, int]]:
    """Summed iteration wall time and iteration count per experiment type."""
    wall: dict[str, float] = collections.defaultdict(float)
    count: dict[str, int] = collections.defaultdict(int)
    for r in rows(directory, 'iterations'):
        wall[r['type']] += float(r['wall_time'])
        count[r['type']] += 1
    return wall, count


def span_times(directory: str) -> tuple[float, float]:
    """When the run directory was made (experiment.yaml) and its last summary written: the
    run's iterations without starting the processes or writing the report (epoch s)."""
    return (os.path.getmtime(os.path.join(directory, 'experiment.yaml')),
            os.path.getmtime(os.path.join(directory, 'summary.json')))


def run_span(directory: str) -> float:
    """span_times' length, s."""
    start, end = span_times(directory)
    return end - start


class NodeUsage:
    """Polls the node processes under `namespace`: each one's peak resident memory (VmHWM, kB)
    and its CPU time (utime + stime, s) at each poll, every POLL s (`cpu_between`)."""

    POLL = 0.5

    def __init__(self, namespace: str) -> None:
        self.namespace, self.peak_kb = namespace, {}
        self._cpu: dict[tuple[str, str], list[tuple[float, float]]] = {}
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._poll, daemon=True)
        self._thread.start()

    def _poll(self) -> None:
        pattern = re.compile(r'lib/\w+/(\w+) --ros-args -r __ns:=\S*?(/worker_\d+)?(?: |$)')
        tick = os.sysconf('SC_CLK_TCK')
        while not self._stop.wait(self.POLL):
            for pid in os.listdir('/proc'):
                try:
                    cmd = open(f'/proc/{pid}/cmdline', 'rb').read().replace(b'\0', b' ').decode()
                    if f'__ns:={self.namespace}' not in cmd:
                        continue
                    status = open(f'/proc/{pid}/status').read()
                    # after the command's name in parentheses: utime and stime are the 12th
                    # and 13th fields (proc(5): 14 and 15 of the whole line)
                    stat = open(f'/proc/{pid}/stat').read().rsplit(')', 1)[1].split()
                except (OSError, ValueError):
                    continue
                m = pattern.search(cmd)
                hwm = re.search(r'VmHWM:\s+(\d+)', status)
                if m and hwm:
                    key = ((m.group(2) or '').strip('/'), m.group(1))
                    self.peak_kb[key] = max(self.peak_kb.get(key, 0), int(hwm.group(1)))
                    self._cpu.setdefault(key, []).append(
                        (time.time(), (int(stat[11]) + int(stat[12])) / tick))

    def stop(self) -> None:
        self._stop.set()
        self._thread.join()

    def cpu_between(self, start: float, end: float) -> dict[tuple[str, str], float]:
        """Each node's CPU time, s, from its last poll at or before `start` to its last at or
        before `end` (epoch s): within a poll of the span at either end."""
        def at(series: list, t: float) -> float:
            return max((cpu for when, cpu in series if when <= t), default=0.0)
        return {key: at(series, end) - at(series, start) for key, series in self._cpu.items()}


def graph(path: str, work: str, workers: int) -> tuple[str, float, dict, dict]:
    namespace = f'/bench_{os.getpid()}_{workers}'
    usage = NodeUsage(namespace)
    start = time.perf_counter()
    done = subprocess.run([executable('experiment_manager', 'run'), path, '--output',
                           os.path.join(work, f'graph_{workers}'), '--namespace', namespace,
                           '--workers', str(workers)], capture_output=True, text=True)
    wall = time.perf_counter() - start
    usage.stop()
    if done.returncode != 0:
        sys.exit(f'run --workers {workers} failed:\n{done.stderr}')
    results = re.search(r'^results:\s+(\S+)', done.stdout, re.M).group(1)
    return results, wall, usage.peak_kb, usage.cpu_between(*span_times(results))


def one_round(file, path: str, work: str, a: int, b: int) -> dict:
    """The file on the cores, then through the graph with `a` and with `b` workers: wall time
    per type, spans, peak memory and whether the result files are identical."""
    start, cpu = time.perf_counter(), time.process_time()
    local_dir = os.path.join(work, 'local')
    with LocalBackend() as backend, ResultsWriter(local_dir, file.text) as writer:
        Runner(file, [backend], writer).run()
    local_wall, local_cpu = time.perf_counter() - start, time.process_time() - cpu
    dir_a, wall_a, mem_a, cpu_a = graph(path, work, a)
    dir_b, wall_b, mem_b, cpu_b = graph(path, work, b)
    identical = all(rows(d, name, ('wall_time',)) == rows(local_dir, name, ('wall_time',))
                    for d in (dir_a, dir_b) for name in FILES)
    (g, count), (c, _) = per_type(dir_a), per_type(local_dir)
    return {'graph': g, 'cores': c, 'count': count, 'identical': identical,
            'span_a': run_span(dir_a), 'span_b': run_span(dir_b), 'local_wall': local_wall,
            'wall_a': wall_a, 'wall_b': wall_b, 'mem_a': mem_a, 'mem_b': mem_b,
            'local_cpu': local_cpu, 'cpu_a': cpu_a, 'cpu_b': cpu_b}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('file', nargs='?', default=None)
    parser.add_argument('--workers', type=int, nargs=2, default=[1, 2], metavar=('A', 'B'),
                        help='the two worker counts to compare (default 1 2)')
    parser.add_argument('--paper-case', nargs='+', default=[], metavar='RUN_DIR',
                        help="run directories of the paper's full test case, made before")
    parser.add_argument('--iterations', type=int, metavar='N',
                        help='cap every experiment of the file at N iterations')
    parser.add_argument('--rounds', type=int, default=1, metavar='R',
                        help='run cores, A and B workers R times in turn: runs of the same '
                             'code on this shared machine spread by 10 %% and more')
    args = parser.parse_args()
    if args.rounds < 1:
        parser.error(f'--rounds: {args.rounds} must be at least 1')
    path = os.path.abspath(args.file or default_file())
    try:
        file = experiment_file.load(path)
        text = None if args.iterations is None else experiment_file.reduced(file, args.iterations)
    except InvalidArgument as exc:
        parser.error(str(exc))
    os.environ.setdefault('ROS_DOMAIN_ID', str(150 + os.getpid() % 50))
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    work = tempfile.mkdtemp(prefix='bench_experiment_')
    if text is not None:
        path = os.path.join(work, os.path.basename(path))
        with open(path, 'w', encoding='utf-8') as f:
            f.write(text)
        file = experiment_file.load(path)

    a, b = args.workers
    rounds = []
    for r in range(args.rounds):
        rounds.append(one_round(file, path, os.path.join(work, f'round_{r}'), a, b))
    # wall time per type summed over the rounds; identical only if every round's files were
    g: dict[str, float] = collections.defaultdict(float)
    c: dict[str, float] = collections.defaultdict(float)
    for x in rounds:
        for kind, wall in x['graph'].items():
            g[kind] += wall
        for kind, wall in x['cores'].items():
            c[kind] += wall
    n = rounds[0]['count']
    identical = all(x['identical'] for x in rounds)
    print(f'{file.id}: {sum(n.values())} iterations' + (
        f', {len(rounds)} rounds (cores, {a} worker(s), {b} worker(s) in turn)'
        if len(rounds) > 1 else '') + '; wall time per iteration, s')
    print(f'{"experiment type":<18} {"n":>4} {f"graph, {a} worker(s)":>20} {"cores":>9} '
          f'{"ratio":>7}')
    for kind in experiment_file.TYPES:
        if kind in c:
            k = n[kind] * len(rounds)
            print(f'{kind:<18} {n[kind]:4d} {g[kind] / k:20.3f} {c[kind] / k:9.3f} '
                  f'{g[kind] / c[kind]:7.2f}')
    print(f'{"all iterations":<18} {sum(n.values()):4d} {sum(g.values()) / len(rounds):19.2f}s '
          f'{sum(c.values()) / len(rounds):8.2f}s {sum(g.values()) / sum(c.values()):7.2f}')
    if len(rounds) > 1:
        ratios = [sum(x['graph'].values()) / sum(x['cores'].values()) for x in rounds]
        gains = [x['span_a'] / x['span_b'] for x in rounds]
        print(f'by round: graph / cores {", ".join(f"{v:.2f}" for v in ratios)} (median '
              f'{statistics.median(ratios):.2f}); throughput of {b} against {a} '
              f'{", ".join(f"x{v:.2f}" for v in gains)} (median x{statistics.median(gains):.2f})')
    for x in rounds:
        print(f'\nthe run (first iteration to last summary): {a} worker(s) {x["span_a"]:.2f} s, '
              f'{b} worker(s) {x["span_b"]:.2f} s: throughput x{x["span_a"] / x["span_b"]:.2f}')
        print(f'the whole command: cores {x["local_wall"]:.2f} s; graph {a} worker(s) '
              f'{x["wall_a"]:.2f} s, {b} worker(s) {x["wall_b"]:.2f} s (starting processes and '
              'the report included)')
    for workers, key in ((a, 'mem_a'), (b, 'mem_b')):
        peaks: dict[tuple[str, str], int] = {}
        for x in rounds:
            for node, kb in x[key].items():
                peaks[node] = max(kb, peaks.get(node, 0))
        per_worker: dict[str, int] = collections.defaultdict(int)
        for (worker, _), kb in peaks.items():
            if worker:
                per_worker[worker] += kb
        nodes = ', '.join(f'{node} {kb / 1024:.0f}' for (worker, node), kb in sorted(
            peaks.items()) if worker in ('', 'worker_0'))
        print(f'peak memory, {workers} worker(s): per worker (3 processes) '
              + ', '.join(f'{w} {kb / 1024:.0f} MiB' for w, kb in sorted(per_worker.items()))
              + f'; worker_0 and manager by node (MiB): {nodes}')
    for workers, key in ((a, 'cpu_a'), (b, 'cpu_b')):
        by_node: dict[str, float] = collections.defaultdict(float)
        for x in rounds:
            for (_, node), seconds in x[key].items():
                by_node[node] += seconds
        cores = sum(x['local_cpu'] for x in rounds)
        total = sum(by_node.values())
        print(f'CPU of the nodes over the run, {workers} worker(s), s (all workers): '
              + ', '.join(f'{node} {s:.1f}' for node, s in sorted(by_node.items()))
              + f'; {total:.1f} in all, x{total / cores:.2f} the {cores:.1f} of the cores (this '
              'process, the same iterations)')
    print(f'result files identical (wall times aside): {identical}')
    if args.paper_case:
        print()
        print_full_case(args.paper_case)
    return 0 if identical else 1


if __name__ == '__main__':
    sys.exit(main())
