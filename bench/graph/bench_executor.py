"""The least a call over the graph costs, by the server's rclpy executor.

A server process with a service and an action that do nothing (`get_parts`, `remove_parts`
types, empty messages) spins on rclpy's SingleThreadedExecutor, MultiThreadedExecutor (3
threads, as the world) or `rclpy.experimental.EventsExecutor`; a client in this process
(SingleThreadedExecutor spun in a thread, the caller waiting on the futures, as GraphBackend
does) prints the median round trip of 30 calls of each, or that the server did not answer.
What a call to a node of ours costs beyond this floor is its own work (bench_calls.py).

    tools/ws python -m bench.graph.bench_executor [--executors single multi events]
"""

import argparse
import os
import statistics
import subprocess
import sys
import threading
import time

from pick_common.rclpy_adapter import LockedActionClient
from pick_msgs.action import RemoveParts
from pick_msgs.srv import GetParts
import rclpy
from rclpy.action import ActionServer
from rclpy.executors import MultiThreadedExecutor, SingleThreadedExecutor
from rclpy.node import Node

ANSWER_WAIT = 5.0   # s for one answer before the server is reported as not answering
CALLS = 30


def serve(namespace: str, kind: str) -> None:
    rclpy.init()
    node = Node('server', namespace=namespace)
    node.create_service(GetParts, 'get_parts', lambda request, response: response)

    def execute(goal_handle):
        goal_handle.succeed()
        return RemoveParts.Result()

    ActionServer(node, RemoveParts, 'remove_parts', execute_callback=execute)
    if kind == 'events':
        from rclpy.experimental import EventsExecutor
        executor = EventsExecutor()
    elif kind == 'multi':
        executor = MultiThreadedExecutor(num_threads=3)
    else:
        executor = SingleThreadedExecutor()
    executor.add_node(node)
    executor.spin()


def wait(future):
    done = threading.Event()
    future.add_done_callback(lambda _: done.set())
    if not done.wait(ANSWER_WAIT):
        raise TimeoutError
    return future.result()


def measure(node: Node, kind: str) -> str:
    server = subprocess.Popen([sys.executable, '-m', __spec__.name, '--serve',
                               node.get_namespace(), kind])
    try:
        service = node.create_client(GetParts, 'get_parts')
        action = LockedActionClient(node, RemoveParts, 'remove_parts')
        deadline = time.monotonic() + 30.0
        while not (service.service_is_ready() and action.server_is_ready()):
            if time.monotonic() > deadline:
                return f'{kind}: the server did not appear in 30 s'
            time.sleep(0.05)
        time.sleep(1.0)     # discovery settles

        def call_service():
            wait(service.call_async(GetParts.Request()))

        def call_action():
            wait(wait(action.send_goal_async(RemoveParts.Goal())).get_result_async())

        out = []
        for what, call in (('service', call_service), ('action', call_action)):
            times = []
            try:
                for _ in range(CALLS):
                    start = time.perf_counter()
                    call()
                    times.append(time.perf_counter() - start)
            except TimeoutError:
                out.append(f'{what}: no answer in {ANSWER_WAIT:g} s')
                break
            out.append(f'{what} {1000 * statistics.median(times):.2f} ms')
        node.destroy_client(service)
        action.destroy()
        return f'{kind:<7} ' + ', '.join(out)
    finally:
        server.kill()
        server.wait()


def main() -> int:
    if sys.argv[1:2] == ['--serve']:
        serve(sys.argv[2], sys.argv[3])
        return 0
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--executors', nargs='+', default=['single', 'multi', 'events'],
                        choices=['single', 'multi', 'events'])
    args = parser.parse_args()
    os.environ.setdefault('ROS_DOMAIN_ID', str(150 + os.getpid() % 50))
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    rclpy.init()
    print(f'median round trip of {CALLS} calls, client on SingleThreadedExecutor; '
          'server executor:')
    for kind in args.executors:
        node = Node('client', namespace=f'/bench_executor_{os.getpid()}_{kind}')
        executor = SingleThreadedExecutor()
        executor.add_node(node)
        threading.Thread(target=executor.spin, daemon=True).start()
        print(measure(node, kind), flush=True)
    os._exit(0)     # the executor threads are daemons; nothing to close cleanly


if __name__ == '__main__':
    sys.exit(main())
