"""Helpers for graph tests: node processes, a client node, a node spun by another thread, a
steady-clock wait, a wrapper of an action client's rcl handle.

Nodes run as real processes started from their installed executables (the path `ros2 run`
uses) and talk to the test's client node over DDS on loopback.
"""

from collections.abc import Callable, Iterator
import contextlib
import os
import tempfile
import threading
import time

from experiment_manager.commands import launcher
from pick_common.node_runner import handshake
from pick_common.rclpy_adapter import LockedActionClient
import rclpy
from rclpy.context import Context
from rclpy.executors import MultiThreadedExecutor, SingleThreadedExecutor
from rclpy.node import Node

# The small file of every experiment type that the graph tests run.
SMALL = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), 'src',
                     'experiment_manager', 'test', 'small_experiment.yaml')


def wait_for(predicate: Callable[[], bool], timeout: float, spin: Callable[[], None]) -> bool:
    """Spin until predicate() holds or timeout (s, steady clock) passes; no fixed sleeps."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        spin()
    return predicate()


def unique_namespace(base: str) -> str:
    """A namespace of this process only: two test runs on one ROS domain (their domain ids can
    collide) then never drive each other's nodes."""
    return f'/{base}_{os.getpid()}'


class NodeProcess(launcher.NodeProcess):
    """A node started as a process, its output in a temporary log file (a pipe nobody reads
    can fill and stall the node)."""

    def __init__(self, package: str, name: str, args: list[str],
                 prefix: tuple[str, ...] = ()) -> None:
        fd, log = tempfile.mkstemp(prefix=f'{name}_', suffix='.log')
        os.close(fd)
        super().__init__(package, name, args, log, prefix=prefix)


def stop_all(procs) -> None:
    """Stop every node process (SIGINT), then fail if any did not exit with 0: stopping all
    before judging any leaves no node running after a failure."""
    codes = [proc.stop() for proc in procs]
    for proc, code in zip(procs, codes, strict=True):
        assert code == 0, f'{proc.name} exited with {code} on SIGINT:\n{proc.output()}'


@contextlib.contextmanager
def spun_node(name: str, make: Callable[[Node], tuple]) -> Iterator[tuple]:
    """A node in a context of its own with what `make(node)` makes on it (action servers and
    clients), its MultiThreadedExecutor spun by a daemon thread once they exist (as the
    manager's node, whose other threads call and wait while it spins). Yields make's
    entities; after the block, stops the executor, then destroys them, the node and the
    context."""
    context = Context()
    rclpy.init(context=context)
    node = Node(name, context=context)
    executor = MultiThreadedExecutor(context=context)
    executor.add_node(node)
    made = make(node)
    threading.Thread(target=executor.spin, daemon=True).start()
    try:
        yield made
    finally:
        executor.shutdown(timeout_sec=2.0)
        for entity in made:
            entity.destroy()
        node.destroy_node()
        rclpy.try_shutdown(context=context)


class WrappedHandle:
    """An action client's rcl handle (`client._client_handle`) passed through, for a test to
    change one of its requests; `unwrap` puts the handle back."""

    def __init__(self, handle) -> None:
        self._handle = handle

    def __getattr__(self, name):
        return getattr(self._handle, name)

    def __enter__(self):
        return self._handle.__enter__()

    def __exit__(self, *exc):
        return self._handle.__exit__(*exc)

    @staticmethod
    def unwrap(client) -> None:
        handle = client._client_handle
        client._client_handle = handle._handle if isinstance(handle, WrappedHandle) else handle


class Client:
    """A client node in its own context with a single-threaded executor."""

    def __init__(self) -> None:
        self.context = Context()
        rclpy.init(context=self.context)
        self.node = Node('test_client', context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)

    def spin_once(self) -> None:
        self.executor.spin_once(timeout_sec=0.05)

    def wait(self, predicate: Callable[[], bool], timeout: float = 30.0,
             nodes: tuple[NodeProcess, ...] = ()) -> bool:
        """Spin until predicate() holds; fail at once, with its output, if a node process
        in `nodes` has exited (instead of waiting out the timeout on a dead node)."""
        def done() -> bool:
            for proc in nodes:
                if not proc.running():
                    raise AssertionError(f'{proc.command[0]} exited with '
                                         f'{proc.process.returncode}:\n{proc.output()}')
            return predicate()
        return wait_for(done, timeout, self.spin_once)

    def wait_for_servers(self, *clients, timeout: float = 60.0,
                         nodes: tuple[NodeProcess, ...] = ()) -> bool:
        """Wait until every client (service or action) sees its server and the server answers
        a probe (node_runner.handshake), as the experiment manager does."""
        def ready() -> bool:
            return all(c.server_is_ready() if isinstance(c, LockedActionClient)
                       else c.service_is_ready() for c in clients)
        if not self.wait(ready, timeout, nodes):
            return False
        return handshake(self.node, clients,
                         lambda future, wait: self.wait(future.done, wait, nodes),
                         time.monotonic() + timeout)

    def result(self, future, timeout: float = 60.0):
        assert self.wait(future.done, timeout), f'no answer within {timeout} s'
        return future.result()

    def close(self) -> None:
        self.executor.shutdown()
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)
