"""Recordings read back by an independent reader: mcap-ros2-support decodes every message from
the schema text in the file alone (it never imports our message classes)."""

import struct

from builtin_interfaces.msg import Time
from experiment_manager.commands.replay import replay_qos, STREAM
from experiment_manager.graph.recording import (
    msg_definition,
    OFFERED_QOS,
    qos_profiles,
    qos_yaml,
    Recorder,
    recover,
    SEPARATOR,
)
from geometry_msgs.msg import Vector3
from mcap.exceptions import EndOfFile, McapError
from mcap.reader import make_reader
from mcap.records import Message
from mcap.stream_reader import StreamReader
from mcap_ros2.decoder import DecoderFactory
from pick_common.containers import ContainerSpec
from pick_common.conversions import states_to_msg
from pick_common.node_runner import LATCHED
from pick_common.specs import SceneSpec
from pick_msgs.msg import FeederState, Part, PartArray, PartValidity, ValidityReport
from pick_sim_world.conversions import markers_msg, scene_to_msg
from pick_sim_world.world import World
import pytest
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.serialization import deserialize_message
import yaml

LATCHED_OFFER = lambda: qos_yaml([LATCHED])     # noqa: E731
STREAM_OFFER = lambda: qos_yaml([QoSProfile(depth=10)])     # noqa: E731


@pytest.fixture(scope='module')
def world_messages():
    with World(SceneSpec(ContainerSpec.tray(), seed=1)) as world:
        world.drop(12)
        states = world.snapshot()
        stamp = Time(sec=5, nanosec=7)
        return (scene_to_msg(world, stamp, 'world', 'w1/'),
                states_to_msg(states, stamp, 'world', 'w1/'),
                markers_msg(world, states, stamp, 'w1/'))


def test_schema_text_carries_every_dependency_once():
    text = msg_definition('pick_msgs/msg/Scene')
    names = [line for line in text.splitlines() if line.startswith('MSG: ')]
    assert len(names) == len(set(names))
    for needed in ('pick_msgs/PartModel', 'pick_msgs/Instance', 'pick_msgs/ContainerGeometry',
                   'shape_msgs/SolidPrimitive', 'shape_msgs/Mesh', 'geometry_msgs/Transform',
                   'builtin_interfaces/Time'):
        assert f'MSG: {needed}' in names
    assert text.count(SEPARATOR) == len(names)


def test_an_independent_reader_decodes_every_message(tmp_path, world_messages):
    scene, parts, markers = world_messages
    report = ValidityReport(checked=2, valid=1, results=[
        PartValidity(part_id=3, stage_reached=PartValidity.STAGE_VALID, valid=True,
                     valid_tilts=[-0.5, 0.25], reason='valid')])
    state = FeederState(state=FeederState.STATE_FEEDING, parts_in_feeder=40, vibrations=2)
    path = tmp_path / 'run.mcap'
    with Recorder(str(path)) as rec:
        rec.write('/w1/scene', scene, LATCHED_OFFER, 1)
        rec.write('/w1/parts', parts, STREAM_OFFER, 2)
        rec.write('/w1/markers', markers, LATCHED_OFFER, 3)
        rec.write('/w1/results', report, STREAM_OFFER, 4)
        rec.write('/feeder/state', state, STREAM_OFFER, 5)
        rec.write('/w1/parts', PartArray(parts=[Part(id=99)]), STREAM_OFFER, 6)
        rec.attach('experiment.yaml', b'experiment_id: demo\n', 'application/yaml')
        rec.metadata('run', {'seed': '7'})
    with open(path, 'rb') as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        decoded = [(channel.topic, schema.name, msg)
                   for schema, channel, _, msg in reader.iter_decoded_messages()]
    assert [(t, n) for t, n, _ in decoded] == [
        ('/w1/scene', 'pick_msgs/msg/Scene'), ('/w1/parts', 'pick_msgs/msg/PartArray'),
        ('/w1/markers', 'visualization_msgs/msg/MarkerArray'),
        ('/w1/results', 'pick_msgs/msg/ValidityReport'),
        ('/feeder/state', 'pick_msgs/msg/FeederState'), ('/w1/parts', 'pick_msgs/msg/PartArray')]
    got_scene, got_parts, got_markers, got_report, got_state, last = (d[2] for d in decoded)
    assert got_scene.part_model.name == 'radial_capacitor'
    assert got_scene.instances[0].frame_id == 'w1/instance_0'
    assert [p.dimensions for p in got_scene.part_model.primitives] == [
        list(p.dimensions) for p in scene.part_model.primitives]
    assert [(p.id, p.pose.pose.position.z) for p in got_parts.parts] == [
        (p.id, p.pose.pose.position.z) for p in parts.parts]
    assert len(got_markers.markers) == len(markers.markers)
    assert got_report.results[0].valid_tilts == [-0.5, 0.25]
    assert (got_state.state, got_state.parts_in_feeder) == (FeederState.STATE_FEEDING, 40)
    assert last.parts[0].id == 99
    with open(path, 'rb') as f:
        reader = make_reader(f)
        assert reader.get_header().profile == 'ros2'
        attachments = list(reader.iter_attachments())
        metadata = list(reader.iter_metadata())
        channels = reader.get_summary().channels.values()
    # Every channel says what its publishers offered, as the ros2 profile asks (read with a
    # plain YAML reader, not ours): the latched topics transient local, the rest volatile.
    offered = {c.topic: yaml.safe_load(c.metadata[OFFERED_QOS]) for c in channels}
    assert {t: [(p['reliability'], p['durability'], p['depth']) for p in o]
            for t, o in offered.items()} == {
        '/w1/scene': [('reliable', 'transient_local', 1)],
        '/w1/markers': [('reliable', 'transient_local', 1)],
        **{t: [('reliable', 'volatile', 10)]
           for t in ('/w1/parts', '/w1/results', '/feeder/state')}}
    assert [(a.name, a.data) for a in attachments] == [('experiment.yaml',
                                                         b'experiment_id: demo\n')]
    assert metadata[0].metadata == {'seed': '7'}


def test_a_recording_cut_off_before_close_keeps_its_complete_chunks(tmp_path):
    """What a killed run leaves: chunks written so far, no summary, a torn last write. A
    streaming reader reads every complete chunk, then mcap raises at the tear (EndOfFile, or
    struct.error when the tear is inside a length field)."""
    path = tmp_path / 'cut.mcap'
    rec = Recorder(str(path), chunk_size=16 * 1024)
    rec.attach('experiment.yaml', b'id: cut\n', 'application/yaml')
    rec.metadata('run', {'experiment_id': 'cut'})
    for k in range(3000):
        rec.write('/p', Vector3(x=float(k)), STREAM_OFFER, k)
    rec._file.flush()
    data = path.read_bytes()        # the bytes the OS holds when the process is killed
    rec.flush()                     # what the manager does after each iteration
    flushed = path.read_bytes()
    rec.close()
    cut = tmp_path / 'cut_copy.mcap'
    cut.write_bytes(data[:-7])
    xs = []
    with open(cut, 'rb') as f, pytest.raises((EndOfFile, struct.error)):
        for record in StreamReader(f, validate_crcs=True).records:
            if isinstance(record, Message):
                xs.append(deserialize_message(record.data, Vector3).x)
    assert 0 < len(xs) < 3000, 'complete chunks are readable, the open one is lost'
    assert xs == [float(k) for k in range(len(xs))]

    # recover() makes of it a closed file that a seeking reader opens, with every complete
    # message, the attachment and the metadata; a whole file comes out whole.
    counts = recover(str(cut), str(tmp_path / 'recovered.mcap'))
    assert counts == {'schemas': 1, 'channels': 1, 'messages': len(xs), 'attachments': 1,
                      'metadata': 1, 'torn': 1}
    with open(tmp_path / 'recovered.mcap', 'rb') as f:
        reader = make_reader(f)
        assert reader.get_summary().statistics.message_count == len(xs)
        assert [deserialize_message(m.data, Vector3).x for _, _, m in
                reader.iter_messages()] == xs
        assert [a.data for a in reader.iter_attachments()] == [b'id: cut\n']
        assert [m.metadata for m in reader.iter_metadata()] == [{'experiment_id': 'cut'}]
    (tmp_path / 'flushed.mcap').write_bytes(flushed)     # killed after a flush: nothing lost
    assert recover(str(tmp_path / 'flushed.mcap'), str(tmp_path / 'all.mcap'))['messages'] == 3000
    assert recover(str(path), str(tmp_path / 'whole.mcap'))['messages'] == 3000
    (tmp_path / 'not.mcap').write_bytes(b'id: not a recording\n')
    with pytest.raises(McapError, match='does not start as an MCAP file'):
        recover(str(tmp_path / 'not.mcap'), str(tmp_path / 'x.mcap'))


# What rosbag2 (Jazzy, bag version 9) writes for a latched publisher as the graph reports it.
ROSBAG2_LATCHED = """- history: keep_last
  depth: 1
  reliability: reliable
  durability: transient_local
  deadline:
    sec: 9223372036
    nsec: 854775807
  lifespan:
    sec: 9223372036
    nsec: 854775807
  liveliness: automatic
  liveliness_lease_duration:
    sec: 9223372036
    nsec: 854775807
  avoid_ros_namespace_conventions: false
"""


def test_offered_profiles_read_back_and_decide_how_replay_publishes():
    (profile,) = qos_profiles(ROSBAG2_LATCHED)
    assert (profile.durability, profile.depth) == (DurabilityPolicy.TRANSIENT_LOCAL, 1)
    assert profile.deadline.nanoseconds == 2**63 - 1
    assert yaml.safe_load(qos_yaml([profile])) == yaml.safe_load(ROSBAG2_LATCHED)  # same text
    # replayed latched, with STREAM's depth: a replay at 1000x must not overwrite what its
    # readers have not acknowledged
    latched = replay_qos('/w/scene', {OFFERED_QOS: ROSBAG2_LATCHED})
    assert (latched.durability, latched.reliability, latched.depth) == (
        DurabilityPolicy.TRANSIENT_LOCAL, ReliabilityPolicy.RELIABLE, STREAM.depth)
    # a best-effort stream keeps its reliability
    stream = replay_qos('/w/parts', {OFFERED_QOS: qos_yaml(
        [QoSProfile(depth=5, reliability=ReliabilityPolicy.BEST_EFFORT)])})
    assert (stream.reliability, stream.durability, stream.depth) == (
        ReliabilityPolicy.BEST_EFFORT, DurabilityPolicy.VOLATILE, STREAM.depth)
    # publishers that disagree: the default offer, as ros2 bag play falls back to
    mixed = qos_yaml([LATCHED, QoSProfile(depth=10)])
    assert replay_qos('/w/scene', {OFFERED_QOS: mixed}) is STREAM
    # a recording from before offered_qos_profiles: scene and markers latched by name
    assert replay_qos('/w/scene', {}) is LATCHED and replay_qos('/w/parts', {}) is STREAM
    with pytest.raises(ValueError, match='offered_qos_profiles is not a list of QoS profiles'):
        replay_qos('/w/scene', {OFFERED_QOS: '- {history: sometimes}'})
