"""An experiment file through the graph (the `run` command: four node processes over DDS)
against the same file on the cores in this process (LocalBackend), in one run: wall times per
experiment type, the ratio, and whether the result files are identical (they must be).

    tools/ws python bench/bench_experiment.py [FILE]   (default: the built-in experiment file)
"""

import argparse
import collections
import os
import re
import subprocess
import sys
import tempfile
import time

from experiment_manager import config
from experiment_manager.cli import default_file
from experiment_manager.experiments import Runner
from experiment_manager.launcher import executable
from experiment_manager.local_backend import LocalBackend
from experiment_manager.results import FILES, read_text_rows, ResultsWriter


def rows(directory: str, name: str, drop: tuple[str, ...] = ()) -> list[dict]:
    return read_text_rows(os.path.join(directory, f'{name}.csv'), drop)


def per_type(directory: str) -> dict[str, float]:
    out: dict[str, float] = collections.defaultdict(float)
    for r in rows(directory, 'iterations'):
        out[r['type']] += float(r['wall_time'])
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('file', nargs='?', default=None)
    path = os.path.abspath(parser.parse_args().file or default_file())
    file = config.load(path)
    os.environ.setdefault('ROS_DOMAIN_ID', str(150 + os.getpid() % 50))
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    work = tempfile.mkdtemp(prefix='bench_experiment_')

    start = time.perf_counter()
    local_dir = os.path.join(work, 'local')
    with LocalBackend() as backend, ResultsWriter(local_dir, file.text) as writer:
        Runner(file, [backend], writer).run()
    local_wall = time.perf_counter() - start

    start = time.perf_counter()
    done = subprocess.run([executable('experiment_manager', 'run'), path, '--output',
                           os.path.join(work, 'graph'), '--namespace',
                           f'/bench_{os.getpid()}'], capture_output=True, text=True)
    graph_wall = time.perf_counter() - start
    if done.returncode != 0:
        print(done.stderr, file=sys.stderr)
        return 1
    graph_dir = re.search(r'^results:\s+(\S+)', done.stdout, re.M).group(1)

    identical = all(rows(graph_dir, name, ('wall_time',)) == rows(local_dir, name, ('wall_time',))
                    for name in FILES)
    g, c = per_type(graph_dir), per_type(local_dir)
    print(f'{file.id}: {sum(1 for _ in rows(local_dir, "iterations"))} iterations')
    print(f'{"experiment type":<18} {"graph s":>9} {"core s":>9} {"ratio":>7}')
    for kind in config.TYPES:
        if kind in c:
            print(f'{kind:<18} {g[kind]:9.2f} {c[kind]:9.2f} {g[kind] / c[kind]:7.2f}')
    print(f'{"iterations, all":<18} {sum(g.values()):9.2f} {sum(c.values()):9.2f} '
          f'{sum(g.values()) / sum(c.values()):7.2f}')
    print(f'{"whole command":<18} {graph_wall:9.2f} {local_wall:9.2f} '
          f'{graph_wall / local_wall:7.2f}   (graph: starting 4 processes included)')
    print(f'result files identical (wall times aside): {identical}')
    return 0 if identical else 1


if __name__ == '__main__':
    sys.exit(main())
