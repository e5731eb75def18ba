"""The node processes of `run`: the workers' nodes and the manager, started with the paths each
may use, watched while a run goes on, and a worker node that dies reported and started again
(a few times per run; the manager runs the iteration it lost again)."""

import collections
import json
import os
import sys
import time

import rclpy
from rclpy.node import Node

from . import claim, interrupt
from .launcher import MANAGER, NodeProcess, READS_MESHES, WORKER_NODES


def _dirs(name: str, paths) -> list[str]:
    """`-p name:=[...]` for a string array parameter (JSON is YAML), or nothing when empty
    (rcl refuses an empty list)."""
    paths = sorted(set(paths))
    return ['-p', f'{name}:={json.dumps(paths)}'] if paths else []


def start_graph(namespace: str, log_dir: str, workers: int, files: list[str],
                meshes: list[str], outputs: list[str], respawns: int) -> list[NodeProcess]:
    """The workers' nodes, then the manager (last). Each may read and write only where the
    goals need: the experiment files' and meshes' paths (their directories), and the output
    directories."""
    ns = claim.ns(namespace)
    names = [f'worker_{k}' for k in range(workers)]
    meshes = [os.path.dirname(mesh) for mesh in meshes if mesh]
    procs = []
    for worker in names:
        procs += [NodeProcess(pkg, exe, ['-r', f'__ns:={ns}/{worker}', *(
                                  _dirs('mesh_dirs', meshes) if exe in READS_MESHES else [])],
                              os.path.join(log_dir, f'{worker}.{exe}.log'), f'{worker}/{exe}')
                  for pkg, exe in WORKER_NODES]
    pkg, exe = MANAGER
    files = [os.path.dirname(f) for f in files]
    procs.append(NodeProcess(pkg, exe, [
        '-r', f'__ns:={ns or "/"}', '-p', f'workers:=[{", ".join(names)}]',
        *([] if respawns else ['-p', 'rejoin_timeout:=0.0']),
        *_dirs('experiment_dirs', files + meshes),
        *_dirs('output_dirs', outputs)],
        os.path.join(log_dir, f'{exe}.log')))
    return procs


def dead(procs: list[NodeProcess]) -> NodeProcess | None:
    return next((p for p in procs if not p.running()), None)


def spin_until(node: Node, done, procs: list[NodeProcess], timeout: float) -> NodeProcess | None:
    """Spin until done() or timeout; returns a process that died meanwhile, if any."""
    deadline = time.monotonic() + timeout
    while not done() and time.monotonic() < deadline:
        interrupt.check()       # a second signal stops the wait for the cancel as well
        rclpy.spin_once(node, timeout_sec=0.1)
        gone = dead(procs)
        if gone is not None:
            return gone
    return None


class Graph:
    """The node processes of `run`: the workers' nodes, then the manager (last); those not
    given up as dead (`watched`), and how often each was started again."""

    def __init__(self, procs: list[NodeProcess], limit: int) -> None:
        self.procs, self.watched, self.limit = procs, list(procs), limit
        self.respawns: collections.Counter = collections.Counter()

    @property
    def manager(self) -> NodeProcess:
        return self.procs[-1]

    def replace(self, dead: NodeProcess) -> NodeProcess | None:
        """Start a dead worker node again (`limit` times per run and node); None when it
        may not be, and then it is no longer watched."""
        if self.respawns[dead.name] >= self.limit:
            self.watched.remove(dead)
            return None
        self.respawns[dead.name] += 1
        new = dead.respawn()
        self.procs[self.procs.index(dead)] = self.watched[self.watched.index(dead)] = new
        return new


def report_dead(node: Node, done, graph: Graph, timeout: float, bar) -> bool:
    """Spin until done() or timeout, reporting each watched process that dies. A worker
    node is started again (the manager runs the iteration it lost again and takes the worker
    back). False when the manager died."""
    while (gone := spin_until(node, done, graph.watched, timeout)):
        bar.close()
        print(f'run: {gone.describe_exit()}:\n{gone.output(20)}', file=sys.stderr)
        if gone is graph.manager:
            return False
        if graph.replace(gone):
            print(f'run: {gone.name} started again ({graph.respawns[gone.name]} of '
                  f'{graph.limit}); its iteration runs again, on it or another worker',
                  file=sys.stderr)
        else:
            print('run: its worker is lost; the manager runs its iterations on the others',
                  file=sys.stderr)
    return True
