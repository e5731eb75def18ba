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


class TopicRecorder:
    """Subscribes to the RECORDED topics of each worker added (a namespace relative to
    `namespace`) and to /tf_static and /tf, and writes what arrives to the recorder given to
    start(), until stop()."""

    def __init__(self, name: str, namespace: str, context=None) -> None:
        # Not the process's global arguments: launch names a node with `-r __node:=NAME`,
        # which renames every node of the process, and this one then took the manager's name
        # ('Publisher already registered for node name'). Its namespace is given.
        self.node = Node(name, namespace=namespace, context=context,
                         use_global_arguments=False)
        self._lock = threading.Lock()
        self._recorder: Recorder | None = None
        self._last = 0.0
        self._since = 0           # ns, system time: when the recording started
        # The instance and part frames of every worker (each world publishes its own): one
        # topic each.
        for topic in (TF_STATIC, TF):
            self.node.create_subscription(TFMessage, topic,
                                          self._callback(topic, type_name(TFMessage)), QOS,
                                          raw=True)
        self._executor = SingleThreadedExecutor(context=context)
        self._executor.add_node(self.node)
        self._thread = threading.Thread(target=self._spin, name=name, daemon=True)
        self._thread.start()

    def add(self, prefix: str) -> None:
        """Record the topics of the worker under `prefix` ('' for `namespace` itself)."""
        for topic, msg_type in RECORDED:
            relative = f'{prefix}/{topic}' if prefix else topic
            resolved = self.node.resolve_topic_name(relative)
            self.node.create_subscription(msg_type, relative,
                                          self._callback(resolved, type_name(msg_type)), QOS,
                                          raw=True)

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

    def _callback(self, topic: str, name: str):
        offered = self._offered(topic)

        def record(data: bytes, info: dict) -> None:
            # Not what was published before the recording started: a latched topic's history,
            # which Fast DDS sends even to this volatile subscription when it first matches.
            if info['source_timestamp'] < self._since:
                return
            with self._lock:
                if self._recorder is not None:
                    self._recorder.write_serialized(topic, name, data, offered)
                    self._last = time.monotonic()
        return record

    def write(self, publisher, msg) -> None:
        """Record a message this process publishes itself with `publisher` (no subscription
        needed; its own profile is the offer)."""
        with self._lock:
            if self._recorder is not None:
                self._recorder.write(publisher.topic_name, msg,
                                     lambda: qos_yaml([publisher.qos_profile]))

    def flush(self) -> None:
        """Hand what was recorded so far to the OS (Recorder.flush)."""
        with self._lock:
            if self._recorder is not None:
                self._recorder.flush()

    def start(self, recorder: Recorder) -> None:
        with self._lock:
            self._since = time.time_ns()
            self._recorder = recorder
            self._last = time.monotonic()

    def stop(self) -> None:
        """Wait until the topics have been quiet for DRAIN_QUIET (at most DRAIN_LIMIT), so the
        last messages of the run are in, then stop writing."""
        start = time.monotonic()
        while time.monotonic() - start < DRAIN_LIMIT:
            with self._lock:
                quiet = time.monotonic() - self._last > DRAIN_QUIET
            if quiet:
                break
            time.sleep(0.05)
        with self._lock:
            self._recorder = None

    def destroy(self) -> None:
        """Stop spinning, and destroy the node only once the spinning thread has left the
        executor: a node destroyed under a thread still waiting on it can crash the process."""
        self._executor.shutdown(timeout_sec=1.0)
        self._thread.join(timeout=5.0)
        self.node.destroy_node()
