"""MCAP recording in the ROS 2 profile: `ros2msg` schemas with their full dependency text and
CDR payloads from rclpy.serialization, so that `ros2 bag play`, Foxglove and independent readers
(mcap-ros2-support, rosbags) open the file.

Messages are written to zstd-compressed chunks (no per-message flush; the manager flushes once
per iteration); `close()` writes the summary and index. A file cut off before `close()`
(SIGKILL) keeps every complete chunk, which a streaming reader reads; `recover` copies them into
a closed file (`replay CUT --recover OUT`).
"""

from collections.abc import Callable, Iterable, Iterator, Mapping
import os
import re
import struct
import time

from ament_index_python.packages import get_package_share_directory
from mcap.exceptions import McapError
from mcap.records import Attachment, Channel, Header, Message, Metadata, Schema
from mcap.stream_reader import StreamReader
from mcap.writer import CompressionType, Writer
from rclpy.duration import Duration
from rclpy.qos import (
    DurabilityPolicy,
    HistoryPolicy,
    LivelinessPolicy,
    QoSProfile,
    ReliabilityPolicy,
)
from rclpy.serialization import serialize_message
import yaml

PRIMITIVES = {'bool', 'byte', 'char', 'float32', 'float64', 'int8', 'uint8', 'int16', 'uint16',
              'int32', 'uint32', 'int64', 'uint64', 'string', 'wstring'}
CONSTANT = re.compile(r'^\S+\s+[A-Za-z0-9_]+\s*=')
SEPARATOR = '=' * 80
PROFILE = 'ros2'
CHUNK_SIZE = 1024 * 1024   # bytes per chunk before it is compressed and written


def type_name(msg_type: type) -> str:
    """'pkg/msg/Type' of a generated message class."""
    package = msg_type.__module__.split('.')[0]
    return f'{package}/msg/{msg_type.__name__}'


# The MCAP ros2 profile's channel metadata key, written as rosbag2 writes it for bag version 9
# (Jazzy; rosbag2_storage qos.cpp): a YAML list of the offering publishers' profiles, policies
# by their rmw names ('keep_last', 'reliable', 'transient_local', 'automatic'), durations as
# {sec, nsec}.
OFFERED_QOS = 'offered_qos_profiles'
# A profile's keys in rosbag2's order: policies by name, depth an int, durations {sec, nsec}.
_POLICIES = {'history': HistoryPolicy, 'reliability': ReliabilityPolicy,
             'durability': DurabilityPolicy, 'liveliness': LivelinessPolicy}
_DURATIONS = ('deadline', 'lifespan', 'liveliness_lease_duration')
_KEYS = ('history', 'depth', 'reliability', 'durability', 'deadline', 'lifespan', 'liveliness',
         'liveliness_lease_duration', 'avoid_ros_namespace_conventions')


def qos_yaml(profiles: Iterable[QoSProfile]) -> str:
    """The offered_qos_profiles text of a channel whose publishers offered `profiles`."""
    def encode(key: str, value):
        if key in _POLICIES:
            return value.short_key
        if key in _DURATIONS:
            sec, nsec = divmod(value.nanoseconds, 10**9)
            return {'sec': sec, 'nsec': nsec}
        return value
    return yaml.safe_dump([{k: encode(k, getattr(p, k)) for k in _KEYS} for p in profiles],
                          sort_keys=False)


def qos_profiles(text: str) -> list[QoSProfile]:
    """The profiles of an offered_qos_profiles text (qos_yaml's, or rosbag2's of version 9).
    Raises ValueError naming what it cannot read."""
    try:
        entries = yaml.safe_load(text) or []
        return [QoSProfile(
            depth=int(e['depth']),
            **{key: policy.get_from_short_key(e[key]) for key, policy in _POLICIES.items()},
            **{key: Duration(seconds=int(e[key]['sec']), nanoseconds=int(e[key]['nsec']))
               for key in _DURATIONS},
            avoid_ros_namespace_conventions=bool(e['avoid_ros_namespace_conventions']))
            for e in entries]
    except (yaml.YAMLError, KeyError, TypeError, ValueError, AttributeError) as exc:
        raise ValueError(f'{OFFERED_QOS} is not a list of QoS profiles: '
                         f'{type(exc).__name__}: {exc}') from None


def channel_qos(metadata: Mapping[str, str]) -> list[QoSProfile]:
    """The recorded publishers' profiles of a channel; empty for a recording without them."""
    return qos_profiles(metadata[OFFERED_QOS]) if metadata.get(OFFERED_QOS) else []


def _msg_file(package: str, name: str) -> str:
    return os.path.join(get_package_share_directory(package), 'msg', f'{name}.msg')


def _dependencies(package: str, text: str) -> Iterator[tuple[str, str]]:
    """(package, name) of every message type a .msg text uses, in order of appearance."""
    for line in text.splitlines():
        code = line.split('#', 1)[0].strip()
        if not code:
            continue
        if CONSTANT.match(code):
            continue   # constants have primitive types
        field_type = code.split()[0]
        base = re.sub(r'\[.*\]$', '', field_type)
        base = re.sub(r'<=\d+$', '', base)
        if base in PRIMITIVES:
            continue
        parts = base.split('/')
        if len(parts) == 1:
            yield package, parts[0]
        else:
            yield parts[0], parts[-1]


def msg_definition(full_name: str) -> str:
    """The ros2msg schema text of 'pkg/msg/Type': its .msg text, then each dependency once
    (depth first) under a separator line and 'MSG: pkg/Type'."""
    package, _, name = full_name.split('/')
    with open(_msg_file(package, name)) as f:
        root = f.read()
    seen: set[tuple[str, str]] = set()
    blocks: list[str] = []

    def visit(pkg: str, text: str) -> None:
        for dep in _dependencies(pkg, text):
            if dep in seen:
                continue
            seen.add(dep)
            with open(_msg_file(*dep)) as f:
                dep_text = f.read()
            blocks.append(f'{SEPARATOR}\nMSG: {dep[0]}/{dep[1]}\n{dep_text}')
            visit(dep[0], dep_text)

    visit(package, root)
    return '\n'.join([root.rstrip('\n'), *[b.rstrip('\n') for b in blocks]]) + '\n'


class Recorder:
    """Writes ROS 2 messages, attachments and metadata to one MCAP file."""

    def __init__(self, path: str, chunk_size: int = CHUNK_SIZE,
                 library: str = 'pick_sim experiment_manager') -> None:
        """chunk_size: bytes of messages gathered before a chunk is compressed and written;
        a run killed before close() loses at most the chunk being gathered."""
        self.path = path
        self._file = open(path, 'wb')   # closed by close()
        self._writer = Writer(self._file, chunk_size=chunk_size,
                              compression=CompressionType.ZSTD)
        self._writer.start(profile=PROFILE, library=library)
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, int] = {}
        self.messages = 0

    def _channel(self, topic: str, name: str, offered: Callable[[], str]) -> int:
        channel = self._channels.get(topic)
        if channel is None:
            schema = self._schemas.get(name)
            if schema is None:
                schema = self._schemas[name] = self._writer.register_schema(
                    name=name, encoding='ros2msg', data=msg_definition(name).encode())
            channel = self._channels[topic] = self._writer.register_channel(
                topic=topic, message_encoding='cdr', schema_id=schema,
                metadata={OFFERED_QOS: offered()})
        return channel

    def write(self, topic: str, msg, offered: Callable[[], str],
              log_time_ns: int | None = None) -> None:
        """Record one message on `topic` (an absolute name, as ros2 bag records them).
        offered(): the topic's offered_qos_profiles (qos_yaml), asked for once, when the
        topic's channel is registered."""
        self.write_serialized(topic, type_name(type(msg)), serialize_message(msg), offered,
                              log_time_ns)

    def write_serialized(self, topic: str, name: str, data: bytes, offered: Callable[[], str],
                         log_time_ns: int | None = None) -> None:
        """Record one CDR-serialized message of type `name` ('pkg/msg/Type'), as a raw
        subscription receives it (no decode and encode again); offered() as in write()."""
        now = time.time_ns() if log_time_ns is None else log_time_ns
        self._writer.add_message(channel_id=self._channel(topic, name, offered), log_time=now,
                                 publish_time=now, data=data, sequence=self.messages)
        self.messages += 1

    def attach(self, name: str, data: bytes, media_type: str) -> None:
        """Store a file (the experiment file, results) inside the recording."""
        now = time.time_ns()
        self._writer.add_attachment(create_time=now, log_time=now, name=name,
                                    media_type=media_type, data=data)

    def metadata(self, name: str, data: dict[str, str]) -> None:
        self._writer.add_metadata(name=name, data=data)

    def flush(self) -> None:
        """End the chunk being gathered and hand everything written so far to the OS: a
        process killed after this loses nothing recorded before it."""
        self._writer.flush()

    def close(self) -> None:
        """Write the summary and index and close the file. Idempotent."""
        if not self._file.closed:
            self._writer.finish()
            self._file.close()

    def __enter__(self) -> 'Recorder':
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class CompleteRecords:
    """The complete records of an MCAP stream in file order, up to its tear if it has one (a
    record cut off, or its CRC wrong: what a manager killed before close() leaves); `torn`
    says afterwards whether there was one."""

    def __init__(self, f) -> None:
        self._f, self.torn = f, False

    def __iter__(self) -> Iterator:
        try:
            yield from StreamReader(self._f, validate_crcs=True).records
        except (McapError, struct.error):
            self.torn = True


def recover(source: str, target: str) -> dict[str, int]:
    """Copy every complete record of a recording into a new file, closed with its summary and
    indexes: what a manager killed before close() leaves becomes a file every reader opens.
    Returns the counts copied, and `torn` 1 when the source ended inside a record (0 when it
    was whole). Raises McapError when the source does not start as an MCAP file."""
    counts = dict.fromkeys(('schemas', 'channels', 'messages', 'attachments', 'metadata',
                            'torn'), 0)
    schemas: dict[int, int] = {}
    channels: dict[int, int] = {}
    with open(source, 'rb') as f, open(target, 'wb') as out:
        writer = None
        records = CompleteRecords(f)
        for record in records:
            if isinstance(record, Header):
                writer = Writer(out, compression=CompressionType.ZSTD)
                writer.start(profile=record.profile, library=record.library)
            elif isinstance(record, Schema):
                schemas[record.id] = writer.register_schema(record.name, record.encoding,
                                                            record.data)
                counts['schemas'] += 1
            elif isinstance(record, Channel):
                channels[record.id] = writer.register_channel(
                    record.topic, record.message_encoding, schemas.get(record.schema_id, 0),
                    record.metadata)
                counts['channels'] += 1
            elif isinstance(record, Message):
                writer.add_message(channels[record.channel_id], record.log_time,
                                   record.data, record.publish_time, record.sequence)
                counts['messages'] += 1
            elif isinstance(record, Attachment):
                writer.add_attachment(record.create_time, record.log_time, record.name,
                                      record.media_type, record.data)
                counts['attachments'] += 1
            elif isinstance(record, Metadata):
                writer.add_metadata(record.name, record.metadata)
                counts['metadata'] += 1
        counts['torn'] = int(records.torn)
        if writer is None:
            raise McapError(f'{source} does not start as an MCAP file')
        writer.finish()
    return counts
