"""The claim of a namespace for `run`'s graph: no other `run` on this host (a lock file per ROS
domain and namespace, certain) and no nodes of our names in the graph (best effort: another
host). Started beside a running graph, ours would answer to the same names, and its calls could
be answered by our nodes."""

import fcntl
import os
import tempfile
import time
from typing import IO

from rclpy.node import Node

from . import interrupt
from .launcher import MANAGER, WORKER_NODES

DISCOVERY_WAIT = 3.0    # s to discover a graph already running in the namespace (Fast DDS on
                        # this 2-core host under full load: 0.2-2.0 s, measured;
                        # over 3 s once, with CI beside it)


class NamespaceInUse(Exception):
    """Another graph runs the nodes `run` would start."""


def ns(namespace: str) -> str:
    """'/a/b' for 'a/b/', '' for the root namespace."""
    return '/' + namespace.strip('/') if namespace.strip('/') else ''


def claim(node: Node, namespace: str, workers: int) -> IO[str]:
    """The namespace for this run's graph, or NamespaceInUse naming who has it: another `run`
    on this host (_lock, certain) or nodes of our names in the graph (_already_running, best
    effort: another host). Returns the lock file, to keep open."""
    domain = node.context.get_domain_id()
    lock = _lock(domain, namespace)
    running = _already_running(node, namespace, workers)
    if running:
        lock.close()
        raise _in_use(domain, namespace, f'already has {", ".join(running)} (another `run`, or '
                      'one killed less than about 20 s ago)')
    return lock


def _in_use(domain: int, namespace: str, why: str) -> NamespaceInUse:
    return NamespaceInUse(f'namespace {ns(namespace) or "/"!r} of ROS domain {domain} {why}: '
                          'ours would answer to the same names. Pass --namespace with another '
                          'namespace, or set another ROS_DOMAIN_ID')


def _lock(domain: int, namespace: str) -> IO[str]:
    """Take (ROS domain, namespace) for this process's life, against other `run`s on this host:
    the open lock file, or NamespaceInUse naming the pid of the `run` that holds it. flock, so
    a `run` killed with SIGKILL leaves no stale lock (and, unlike the graph, nothing to wait
    out)."""
    name = f'pick_run.{os.getuid()}.domain_{domain}{ns(namespace).replace("/", ".")}.lock'
    f = open(os.path.join(tempfile.gettempdir(), name), 'a+')
    try:
        fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        f.seek(0)
        holder = f.read().strip() or '?'
        f.close()
        raise _in_use(domain, namespace,
                      f'is taken by `run` (pid {holder}) on this host') from None
    f.truncate(0)
    f.write(str(os.getpid()))
    f.flush()
    return f


def _already_running(node: Node, namespace: str, workers: int) -> list[str]:
    """The nodes of the graph `run` would start that the ROS domain already has (another
    `run` in the same namespace, on another host: _lock covers this one), found within
    DISCOVERY_WAIT, which is best effort (discovery took longer on a loaded host). Started
    beside them, ours would serve the same names, and the running graph's calls could be
    answered by our nodes."""
    prefix = ns(namespace)
    ours = {f'{prefix}/{MANAGER[1]}'} | {f'{prefix}/worker_{k}/{exe}' for k in range(workers)
                                         for _, exe in WORKER_NODES}
    deadline = time.monotonic() + DISCOVERY_WAIT
    while True:
        found = ours & {f'{space.rstrip("/")}/{name}'
                        for name, space in node.get_node_names_and_namespaces()}
        if found or time.monotonic() >= deadline:
            return sorted(found)
        interrupt.sleep(0.1)
