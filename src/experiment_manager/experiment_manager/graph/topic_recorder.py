"""Recording workers' topics into a `Recorder`, from raw (still serialized) messages.

The subscriptions live on their own node, spun by their own single-threaded executor in a
thread: on the manager's multi-threaded executor they slowed the calls it waits on about 9x
(bench/graph/bench_recorder_executor.py: a feeder_emptying iteration took 184 s instead of 31 s).
"""

import threading
import time

from pick_msgs.msg import FeederState, PartArray, Scene, SettleReport, ValidityReport
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import MarkerArray

from .recording import qos_yaml, Recorder, type_name

RECORDED = (('parts', PartArray), ('scene', Scene), ('markers', MarkerArray),
            ('settle_reports', SettleReport), ('results', ValidityReport),
            ('feeder/state', FeederState))
TF_STATIC = '/tf_static'
TF = '/tf'              # the parts' frames, in which the worlds draw their markers
QOS = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE)
DRAIN_QUIET = 0.3       # s without a message before a recording is handed back
DRAIN_LIMIT = 3.0       # s at most spent waiting for the last messages
ROUTES_KEPT = 4         # a worker's last routes: a message later than that many is dropped


class TopicRecorder:
    """Subscribes to the RECORDED topics of each worker added (a namespace relative to
    `namespace`) and to /tf_static and /tf, and writes what arrives to the recordings started
    (start()) until each is stopped (stop()). With runs side by side (running/workers.py), a
    worker's topics go to the recording of the run that last took the worker (route()), and so
    do the /tf and /tf_static messages of its frames (a world names them under its namespace);
    those of a worker no run took yet, and of any other publisher, go to every recording
    open."""

    def __init__(self, name: str, namespace: str, context=None) -> None:
        # Not the process's global arguments: launch names a node with `-r __node:=NAME`,
        # which renames every node of the process, and this one then took the manager's name
        # ('Publisher already registered for node name'). Its namespace is given.
        self.node = Node(name, namespace=namespace, context=context,
                         use_global_arguments=False)
        self._lock = threading.Lock()
        # each open recording -> [ns, system time, when it started; s, monotonic, its last
        # message]
        self._open: dict[Recorder, list] = {}
        # worker prefix -> (ns, system time, recording): since when its messages go where
        self._route: dict[str, list[tuple[int, Recorder]]] = {}
        self._frames: dict[str, str] = {}         # worker prefix -> its frames' prefix
        # The instance and part frames of every worker (each world publishes its own): one
        # topic each.
        for topic in (TF_STATIC, TF):
            self.node.create_subscription(TFMessage, topic,
                                          self._callback(topic, type_name(TFMessage), None),
                                          QOS, raw=True)
        self._executor = SingleThreadedExecutor(context=context)
        self._executor.add_node(self.node)
        self._thread = threading.Thread(target=self._spin, name=name, daemon=True)
        self._thread.start()

    def add(self, prefix: str) -> None:
        """Record the topics of the worker under `prefix` ('' for `namespace` itself)."""
        # 'ns/worker_0/': the world's frames are its namespace's, without the leading slash
        self._frames[prefix] = self.node.resolve_topic_name(f'{prefix}/x' if prefix
                                                            else 'x')[1:-1]
        for topic, msg_type in RECORDED:
            relative = f'{prefix}/{topic}' if prefix else topic
            resolved = self.node.resolve_topic_name(relative)
            self.node.create_subscription(msg_type, relative,
                                          self._callback(resolved, type_name(msg_type), prefix),
                                          QOS, raw=True)

    def route(self, prefix: str, recorder: Recorder) -> None:
        """The topics of the worker under `prefix` published from now on go to `recorder`.
        By when they were published (their source timestamp), not when they arrive: the last
        messages of the run before, taken after this call, still go to its recording."""
        with self._lock:
            routes = self._route.setdefault(prefix, [])
            routes.append((time.time_ns(), recorder))
            del routes[:-ROUTES_KEPT]

    def _spin(self) -> None:
        try:
            self._executor.spin()
        except Exception:  # the context was shut down under it
            pass

    def _offered(self, topic: str):
        """offered_qos_profiles of `topic`: the profiles its publishers offer, as the graph
        reports them (ros2 bag record asks the same). Asked for when a recording registers
        the topic, so after its first message: a publisher that sent one has been discovered."""
        return lambda: qos_yaml(i.qos_profile for i in
                                self.node.get_publishers_info_by_topic(topic))

    def _callback(self, topic: str, name: str, prefix: str | None):
        """What records a message of `topic`, a worker's (under `prefix`) or every world's
        (None)."""
        offered = self._offered(topic)

        def record(data: bytes, info: dict) -> None:
            # a frame's worker is read only when runs side by side have recordings open
            worker = prefix if prefix is not None or len(self._open) < 2 else self._worker(data)
            with self._lock:
                routes = self._route.get(worker)
                # a worker's message goes where its run was when it was published; one a run
                # took no worker of, to every recording open
                to = list(self._open) if not routes else [
                    r for since, r in reversed(routes) if since <= info['source_timestamp']][:1]
                for recorder in to:
                    opened = self._open.get(recorder)
                    # Not what was published before the recording started: a latched topic's
                    # history, which Fast DDS sends even to this volatile subscription when it
                    # first matches.
                    if opened is None or info['source_timestamp'] < opened[0]:
                        continue
                    recorder.write_serialized(topic, name, data, offered)
                    opened[1] = time.monotonic()
        return record

    def _worker(self, data: bytes) -> str | None:
        """The worker whose frames a serialized TFMessage moves, None when none's: the
        longest frame prefix its bytes hold ('' is the manager's own, 'ns/', in every
        worker's). The CDR strings are searched as they are: for a message of 30 transforms
        about 3 us, where deserializing it to read its frames took about 0.5 ms."""
        found = [w for w, f in list(self._frames.items()) if f.encode() in data]
        return max(found, key=lambda w: len(self._frames[w]), default=None)

    def write(self, publisher, msg, recorder: Recorder) -> None:
        """Record a message this process publishes itself with `publisher` (no subscription
        needed; its own profile is the offer) into `recorder`, while it is open."""
        with self._lock:
            if recorder in self._open:
                recorder.write(publisher.topic_name, msg,
                               lambda: qos_yaml([publisher.qos_profile]))

    def flush(self, recorder: Recorder) -> None:
        """Hand what `recorder` recorded so far to the OS (Recorder.flush)."""
        with self._lock:
            if recorder in self._open:
                recorder.flush()

    def start(self, recorder: Recorder) -> None:
        with self._lock:
            self._open[recorder] = [time.time_ns(), time.monotonic()]

    def stop(self, recorder: Recorder) -> None:
        """Wait until `recorder`'s topics have been quiet for DRAIN_QUIET (at most
        DRAIN_LIMIT), so the last messages of its run are in, then stop writing to it."""
        start = time.monotonic()
        while time.monotonic() - start < DRAIN_LIMIT:
            with self._lock:
                quiet = time.monotonic() - self._open[recorder][1] > DRAIN_QUIET
            if quiet:
                break
            time.sleep(0.05)
        with self._lock:
            del self._open[recorder]     # a route to it drops its worker's late messages

    def destroy(self) -> None:
        """Stop spinning, and destroy the node only once the spinning thread has left the
        executor: a node destroyed under a thread still waiting on it can crash the process."""
        self._executor.shutdown(timeout_sec=1.0)
        self._thread.join(timeout=5.0)
        self.node.destroy_node()
