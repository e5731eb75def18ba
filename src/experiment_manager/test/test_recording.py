"""Recordings read back by an independent reader: mcap-ros2-support decodes every message from
the schema text in the file alone (it never imports our message classes)."""

import struct

from builtin_interfaces.msg import Time
from experiment_manager.recording import msg_definition, Recorder, recover, SEPARATOR
from geometry_msgs.msg import Vector3
from mcap.exceptions import EndOfFile, McapError
from mcap.reader import make_reader
from mcap.records import Message
from mcap.stream_reader import StreamReader
from mcap_ros2.decoder import DecoderFactory
from pick_common.containers import ContainerSpec
from pick_common.conversions import states_to_msg
from pick_common.specs import SceneSpec
from pick_msgs.msg import FeederState, Part, PartArray, PartValidity, ValidityReport
from pick_sim_world.conversions import markers_msg, scene_to_msg
from pick_sim_world.world import World
import pytest
from rclpy.serialization import deserialize_message


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
        rec.write('/w1/scene', scene, 1)
        rec.write('/w1/parts', parts, 2)
        rec.write('/w1/markers', markers, 3)
        rec.write('/w1/results', report, 4)
        rec.write('/feeder/state', state, 5)
        rec.write('/w1/parts', PartArray(parts=[Part(id=99)]), 6)
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
        rec.write('/p', Vector3(x=float(k)), k)
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
