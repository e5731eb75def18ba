"""`replay`: republish a run's MCAP recording on the graph, for review without `ros2 bag`.

    replay RECORDING.mcap [--rate R] [--topics T ...] [--prefix NS] [--loop] [--clock [HZ]]
    replay RECORDING.mcap --info
    replay RECORDING.mcap --recover OUT.mcap

Messages go out on their recorded topics (under --prefix, if given) with the recorded spacing
divided by the rate, each topic with the reliability and durability its recorded publishers
offered (the channel's offered_qos_profiles, as ros2 bag play does): `scene` and `markers` come
out latched (transient local) as the world publishes them. --info lists the topics, types,
message counts and attachments, and exits. Payloads are published as recorded (CDR, no decode),
so any type in the file replays if its package is installed. --recover copies every complete
record of a recording cut off before it was closed (its manager was killed) into a closed file
that every reader opens, and exits. SIGINT or SIGTERM stops a replay before its next message
(exit 130, "stopped after N messages"). --loop plays the recording again and again until
then; --clock publishes the recording's time on `clock` (under --prefix) at HZ (default 40, as
ros2 bag play), for nodes with use_sim_time. On a terminal a progress line counts the messages.
"""

import argparse
import importlib
import os
import struct
import sys
import time

from builtin_interfaces.msg import Time
from mcap.exceptions import McapError
from mcap.reader import make_reader
from pick_common.node_runner import LATCHED
import rclpy
from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions
from rosgraph_msgs.msg import Clock
from tqdm import tqdm

from ..graph.recording import channel_qos, recover
from . import interrupt

# Recordings whose channels carry no offered_qos_profiles (older ones): latched by name.
LATCHED_TOPICS = ('scene', 'markers')
STREAM = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE)
MATCH_WAIT = 2.0     # s a new topic waits by default for a subscriber to match (--match-wait)
ACK_WAIT = 5.0       # s at the end for subscribers to acknowledge the last messages
CLOCK_HZ = 40.0      # --clock's default rate, ros2 bag play's
# rclpy's and rclcpp's time sources subscribe to /clock best effort, keeping the last one
CLOCK_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.BEST_EFFORT)


def message_type(name: str) -> type:
    """The message class of 'pkg/msg/Type' (the schema name of a ROS 2 MCAP channel)."""
    parts = name.split('/')
    if len(parts) != 3 or parts[1] != 'msg':
        raise ValueError(f'schema {name!r} is not a ROS 2 message type name (pkg/msg/Type)')
    return getattr(importlib.import_module(f'{parts[0]}.msg'), parts[2])


def replay_qos(topic: str, metadata: dict[str, str]) -> QoSProfile:
    """The profile to publish a recorded topic with: the reliability and durability its
    recorded publishers offered where they all agree (ros2 bag play's rule), STREAM where they
    disagree. The depth is STREAM's whatever was offered: a reliable writer that keeps fewer
    samples than a fast replay sends ahead of its readers' acknowledgements replaces them (a
    late subscriber to a latched topic gets up to that many of its last messages). Raises
    ValueError for unreadable metadata."""
    offered = channel_qos(metadata)
    if not offered:
        return LATCHED if topic.rsplit('/', 1)[-1] in LATCHED_TOPICS else STREAM
    if len({(p.reliability, p.durability) for p in offered}) > 1:
        return STREAM
    return QoSProfile(depth=STREAM.depth, reliability=offered[0].reliability,
                      durability=offered[0].durability)


def _parse(argv: list[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog='replay', description=__doc__.split('\n\n')[0])
    parser.add_argument('recording', help='an MCAP file written by the experiment manager')
    parser.add_argument('--rate', type=float, default=1.0,
                        help='playback speed factor (default 1: as recorded)')
    parser.add_argument('--topics', nargs='*', default=None, help='only these topics')
    parser.add_argument('--prefix', default='',
                        help='namespace put in front of every topic (default: none)')
    parser.add_argument('--match-wait', type=float, default=MATCH_WAIT, metavar='S',
                        help='seconds each topic waits for a subscriber to match before its '
                        f'first message (default {MATCH_WAIT:g}; 0..600); then it publishes '
                        'anyway and says so')
    parser.add_argument('--loop', action='store_true',
                        help='play the recording again and again until SIGINT or SIGTERM')
    parser.add_argument('--clock', type=float, nargs='?', const=CLOCK_HZ, default=None,
                        metavar='HZ', help="publish the recording's time on clock (under "
                        f'--prefix) at HZ (default {CLOCK_HZ:g}; 1..1000)')
    parser.add_argument('--info', action='store_true', help='list the content and exit')
    parser.add_argument('--recover', metavar='OUT',
                        help='copy the complete records of a cut-off recording into OUT (a '
                        'closed MCAP file) and exit')
    args = parser.parse_args(argv)
    if args.recover and os.path.abspath(args.recover) == os.path.abspath(args.recording):
        parser.error('--recover writes a new file: OUT must differ from RECORDING')
    if not 0.001 <= args.rate <= 1000.0:
        parser.error(f'--rate: {args.rate:g} must be within [0.001, 1000]')
    if not 0.0 <= args.match_wait <= 600.0:
        parser.error(f'--match-wait: {args.match_wait:g} must be within [0, 600]')
    if args.clock is not None and not 1.0 <= args.clock <= 1000.0:
        parser.error(f'--clock: {args.clock:g} must be within [1, 1000]')
    return args


def info(path: str) -> str:
    """Topics, types and counts, attachments and metadata of a recording (like
    `ros2 bag info`)."""
    with open(path, 'rb') as f:
        try:
            summary = make_reader(f).get_summary()
        except (McapError, struct.error):   # no footer to find the summary from
            summary = None
    if summary is None:
        raise McapError(f'{path} has no summary section (cut off before it was closed? '
                        f'recover it: replay {path} --recover OUT.mcap)')
    counts = summary.statistics.channel_message_counts if summary.statistics else {}
    lines = [f'{path}: {summary.statistics.message_count if summary.statistics else "?"} '
             'messages']
    for cid, channel in sorted(summary.channels.items(), key=lambda c: c[1].topic):
        schema = summary.schemas.get(channel.schema_id)
        lines.append(f'  {channel.topic:<36} {schema.name if schema else "?":<36} '
                     f'{counts.get(cid, 0)}')
    for a in summary.attachment_indexes:
        lines.append(f'  attachment {a.name} ({a.data_size} bytes)')
    for m in summary.metadata_indexes:
        lines.append(f'  metadata {m.name}')
    return '\n'.join(lines)


def _count(reader, topics: list[str] | None) -> int | None:
    """Messages a pass plays (the progress line's total); None when the summary lacks them."""
    try:
        summary = reader.get_summary()
    except (McapError, struct.error):   # cut off: no footer (play then says so)
        return None
    if summary is None or summary.statistics is None:
        return None
    return sum(n for cid, n in summary.statistics.channel_message_counts.items()
               if not topics or summary.channels[cid].topic in topics)


class Player:
    """Publishes recorded messages at their recorded spacing divided by the rate: a publisher
    per channel (made at its first message, then waiting for a subscriber to match), and the
    recording's time on `clock` while it waits, with --clock."""

    def __init__(self, node: Node, args: argparse.Namespace) -> None:
        self.node, self.args = node, args
        self.publishers: dict[int, object] = {}
        self.sent = 0
        self._prefix = args.prefix.rstrip('/')    # put before every (absolute) topic
        self._clock = (node.create_publisher(Clock, f'{self._prefix}/clock', CLOCK_QOS)
                       if args.clock else None)
        self._ticked = float('-inf')

    def _open(self, schema, channel) -> None:
        """The channel's publisher, made and matched at its first message."""
        topic = self._prefix + channel.topic
        pub = self.publishers[channel.id] = self.node.create_publisher(
            message_type(schema.name), topic, replay_qos(channel.topic, channel.metadata))
        deadline = time.monotonic() + self.args.match_wait
        while pub.get_subscription_count() == 0 and time.monotonic() < deadline:
            interrupt.sleep(0.02)
        if pub.get_subscription_count() == 0:
            print(f'replay: {topic}: no subscriber matched within {self.args.match_wait:g} s '
                  '(--match-wait); publishing anyway', file=sys.stderr)

    def _wait(self, due: float, due_log: int, start_log: int, start_wall: float) -> None:
        """Sleep until `due` (monotonic s), when the message of log time `due_log` (ns) goes
        out, publishing on the way, at the --clock rate, the recording's time: `start_log`
        (ns) when the pass started at `start_wall` (monotonic s), advancing at the rate, and
        never past `due_log`. In integer ns: a float of some 1.8e18 ns is 256 ns coarse (the
        clock once read 127 ns before the first message), and a wake-up after `due` made it run
        1 ms past the last (the graph test caught both). A signal ends the wait
        (KeyboardInterrupt)."""
        while True:
            now = time.monotonic()
            if self._clock is not None and now - self._ticked >= 1.0 / self.args.clock:
                log = min(due_log, start_log + int((now - start_wall) * self.args.rate * 1e9))
                sec, nanosec = divmod(log, 10**9)
                self._clock.publish(Clock(clock=Time(sec=sec, nanosec=nanosec)))
                self._ticked = now
            if now >= due:
                interrupt.check()
                return
            period = 1.0 / self.args.clock if self._clock is not None else due - now
            interrupt.sleep(min(due - now, period))

    def play(self, messages, bar) -> None:
        """One pass over (schema, channel, message) in log-time order."""
        rate = self.args.rate
        start_log = start_wall = None
        for schema, channel, message in messages:
            if channel.id not in self.publishers:
                self._open(schema, channel)
                if start_log is not None:   # keep the recorded spacing after the wait
                    start_wall = time.monotonic() - (message.log_time - start_log) / 1e9 / rate
            if start_log is None:
                start_log, start_wall = message.log_time, time.monotonic()
            self._wait(start_wall + (message.log_time - start_log) / 1e9 / rate,
                       message.log_time, start_log, start_wall)
            # SIGINT, SIGTERM: stop in the wait, not between a publish and its count
            self.publishers[channel.id].publish(message.data)
            self.sent += 1
            bar.update()

    def finish(self) -> None:
        """Wait for the subscribers' acknowledgements: exiting at once would drop messages
        still in flight."""
        for pub in self.publishers.values():
            pub.wait_for_all_acked(Duration(seconds=ACK_WAIT))


def main(argv: list[str] | None = None) -> int:
    args = _parse(sys.argv[1:] if argv is None else argv)
    try:
        if args.info:
            print(info(args.recording))
            return 0
        if args.recover:
            counts = recover(args.recording, args.recover)
            print(f'replay: {args.recover}: ' + ', '.join(
                f'{n} {k}' for k, n in counts.items() if k != 'torn')
                + ('; the source ended inside a record (the rest is lost)' if counts['torn']
                   else '; the source was whole'), file=sys.stderr)
            return 0
        f = open(args.recording, 'rb')
    except (OSError, McapError) as exc:
        print(f'replay: {args.recording}: {exc}', file=sys.stderr)
        return 2
    interrupt.install()
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    node = Node('replay')
    player = Player(node, args)
    try:
        reader = make_reader(f)
        with tqdm(total=_count(reader, args.topics), unit='msg', file=sys.stderr,
                  dynamic_ncols=True, disable=not sys.stderr.isatty()) as bar:
            while True:
                before = player.sent
                player.play(reader.iter_messages(topics=args.topics or None,
                                                 log_time_order=True), bar)
                if not args.loop or player.sent == before:     # nothing to play again
                    break
                bar.reset()
        player.finish()
        print(f'replay: published {player.sent} messages on {len(player.publishers)} topics',
              file=sys.stderr)
        return 0
    except KeyboardInterrupt:
        print(f'\nreplay: stopped after {player.sent} messages', file=sys.stderr)
        return 130
    except (McapError, ValueError, AttributeError, ModuleNotFoundError) as exc:
        print(f'replay: {args.recording}: after {player.sent} messages: {type(exc).__name__}: '
              f'{exc}', file=sys.stderr)
        return 1
    finally:
        f.close()
        node.destroy_node()
        rclpy.try_shutdown()
