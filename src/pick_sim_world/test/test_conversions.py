"""Pure tests of message conversions that carry geometry (real PyBullet world, no ROS graph)."""

from builtin_interfaces.msg import Time
import numpy as np
from pick_common.containers import ContainerSpec
from pick_common.parts.primitives import Box, Cylinder, Hull
from pick_common.parts.spec import PartSpec
from pick_common.specs import SceneSpec, Vibration
from pick_sim_world import conversions as conv
from pick_sim_world.world import World
import pybullet as pb
import pytest
import trimesh
from visualization_msgs.msg import Marker


@pytest.mark.parametrize('model', ['radial_capacitor', 'to220'])
def test_each_part_marker_is_its_primitive_placed_by_the_part_frame_on_tf(model):
    with World(SceneSpec(ContainerSpec.tray(), PartSpec(model=model), 2, seed=4)) as world:
        world.drop(12)
        states = world.snapshot()
        # Parts in and out of their container in both instances: markers_msg copies one
        # marker per colour and primitive.
        states.inside[::3] = False
        assert set(zip(states.instances.tolist(), states.inside.tolist(),
                       strict=True)) == {
            (0, True), (0, False), (1, True), (1, False)}
        msg = conv.markers_msg(world, states, Time(sec=3), 'w/')
        tf = conv.parts_tf_msg(states, Time(sec=3), 'w/')
        primitives = world.part.primitives
    assert msg.markers[0].action == Marker.DELETEALL
    parts = [m for m in msg.markers[1:] if m.ns.startswith('part_')]
    walls = [m for m in msg.markers[1:] if m.ns == 'container']
    assert len(walls) == 2 * 5 and len(parts) == len(states.ids) * len(primitives)
    by_key = {(m.ns, m.id): m for m in parts}
    frames = {t.child_frame_id: t for t in tf.transforms}
    assert len(frames) == len(tf.transforms) == len(states.ids)
    for pid, instance, pose, inside in zip(states.ids, states.instances, states.poses,
                                           states.inside, strict=True):
        # the part's frame on /tf: its pose in its instance frame
        t = frames[f'w/part_{pid}']
        assert t.header.frame_id == f'w/instance_{instance}' and t.header.stamp.sec == 3
        r, q = t.transform.translation, t.transform.rotation
        assert [r.x, r.y, r.z, q.x, q.y, q.z, q.w] == pytest.approx(pose, abs=0.0)
        for k, p in enumerate(primitives):
            m = by_key[(f'part_{pid}', k)]
            assert m.header.frame_id == f'w/part_{pid}' and m.frame_locked
            # drawn through the part's frame, the primitive lands where the part pose puts it
            position, orientation = pb.multiplyTransforms(
                [r.x, r.y, r.z], [q.x, q.y, q.z, q.w],
                [m.pose.position.x, m.pose.position.y, m.pose.position.z],
                [m.pose.orientation.x, m.pose.orientation.y, m.pose.orientation.z,
                 m.pose.orientation.w])
            want, want_orientation = pb.multiplyTransforms(pose[:3], pose[3:], p.position,
                                                           p.orientation)
            assert position == pytest.approx(want, abs=1e-6)   # two single-precision steps
            assert abs(np.dot(orientation, want_orientation)) == pytest.approx(1.0, abs=1e-6)
            expected = {Box: Marker.CUBE, Cylinder: Marker.CYLINDER}.get(type(p),
                                                                          Marker.TRIANGLE_LIST)
            assert m.type == expected
            assert (m.color.r, m.color.g, m.color.b) == pytest.approx(
                (0.1, 0.3, 0.8) if inside else (0.9, 0.1, 0.1))
            if isinstance(p, Hull):
                assert len(m.points) == 3 * len(p.faces)


def test_markers_need_publishing_again_only_when_the_parts_or_their_colours_change():
    with World(SceneSpec(ContainerSpec.tray(), PartSpec(model='radial_capacitor'),
                         seed=4)) as world:
        ids = world.drop(6)[0]
        before = world.snapshot()
        world.vibrate(Vibration())
        moved = world.snapshot()
        world.remove(ids[:1])
        removed = world.snapshot()
    assert not np.allclose(moved.poses, before.poses)
    assert conv.drawn(moved) == conv.drawn(before)
    assert conv.drawn(removed) != conv.drawn(moved)
    moved.inside[0] = not moved.inside[0]
    assert conv.drawn(moved) != conv.drawn(before)


def test_a_part_s_marker_shapes_are_built_once_and_follow_the_world_s_part(tmp_path):
    """The points of a part's hulls are built once for its primitives (a CAD part's run
    rebuilt thousands after every operation), and a world of another part gets its own: each
    call's markers equal those built with nothing kept."""
    specs = []
    for name, mesh in (('ball', trimesh.creation.icosphere(subdivisions=1, radius=0.003)),
                       ('rod', trimesh.creation.cylinder(radius=0.002, height=0.008))):
        mesh.export(str(tmp_path / f'{name}.stl'))
        specs.append(PartSpec(model='mesh', mesh_path=str(tmp_path / f'{name}.stl'),
                              mass=0.001))
    built = []
    for spec in (specs[0], specs[1], specs[0]):
        with World(SceneSpec(ContainerSpec.tray(), spec, seed=4)) as world:
            world.drop(3)
            states = world.snapshot()
            kept = conv.markers_msg(world, states, Time(sec=3), 'w/')
            again = conv.markers_msg(world, states, Time(sec=3), 'w/')
            conv._shapes_of = ((), [])
            fresh = conv.markers_msg(world, states, Time(sec=3), 'w/')
        assert kept == fresh and again == fresh
        hulls = [m for m in kept.markers if m.type == Marker.TRIANGLE_LIST]
        assert len(hulls) == 3
        built.append(hulls[0].points)
    assert built[0] == built[2] and built[0] != built[1]
