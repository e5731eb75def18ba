"""A mesh part's physics comes from its geometry, not from where its file puts the origin: the
mass centre and principal axes are the solid's (uniform density), and the world reports the
file's frame. That the answers do not move with the origin: experiment_manager's
test_part_frames.py (it needs the validity checks too)."""

import os

import numpy as np
from pick_common.containers import ContainerSpec
from pick_common.parts.geometry import build_part
from pick_common.parts.mass import mass_properties
from pick_common.parts.spec import PartSpec
from pick_common.specs import SceneSpec
from pick_common.states import rotate
from pick_sim_world.config import PhysicsConfig
from pick_sim_world.world import World
import pytest
import trimesh

BOX = (0.012, 0.004, 0.002)          # m
MASS = 0.001                          # kg
IDENTITY = np.eye(3)


def _mesh(tmp_path, name: str, offset, turn=IDENTITY) -> PartSpec:
    """The box, its centre at `offset` and its axes turned by `turn` in the file's frame."""
    mesh = trimesh.creation.box(BOX)
    mesh.apply_transform(np.vstack([np.column_stack([turn, offset]), [0, 0, 0, 1]]))
    path = os.path.join(tmp_path, f'{name}.stl')
    mesh.export(path)
    return PartSpec(model='mesh', mesh_path=path, mass=MASS)


def test_mass_centre_and_inertia_are_the_solid_s(tmp_path):
    spec = _mesh(tmp_path, 'corner', (0.006, 0.002, 0.001))
    part = build_part(spec)
    centre, axes, moments = mass_properties([part.visual], MASS)
    assert part.mass_frame[0] == pytest.approx((0.006, 0.002, 0.001), abs=1e-9)
    assert centre == pytest.approx(part.mass_frame[0]) and axes == pytest.approx(part.mass_frame[1])
    a, b, c = BOX
    assert sorted(moments) == pytest.approx(sorted([MASS / 12 * (b * b + c * c),
                                                    MASS / 12 * (a * a + c * c),
                                                    MASS / 12 * (a * a + b * b)]), rel=1e-6)
    assert build_part(PartSpec()).mass_frame is None    # a built-in: its frame, as before


def test_the_world_puts_the_mass_where_the_material_is(tmp_path):
    offset = np.array([0.03, -0.02, 0.01])
    spec = _mesh(tmp_path, 'far', offset)
    with World(SceneSpec(ContainerSpec.tray(), spec, 1, 0), PhysicsConfig()) as world:
        world.drop(1)
        state = world.snapshot()
        body = world.body(int(state.ids[0]))
        # PyBullet's base pose is the mass centre's (with maximal coordinates its
        # getDynamicsInfo reports no usable inertial frame: the base pose is the check)
        base = world.engine.position(body)
        origin = world.instances[0].origin
    # the snapshot is of the file's frame: the box's centre, where the pose puts it, is the
    # body's mass centre, resting in the tray
    centre = state.poses[0, :3] + rotate(state.poses[:1, 3:], offset)[0]
    assert centre == pytest.approx(np.array(base) - origin, abs=1e-9)
    assert state.inside.all() and 0.0 < centre[2] < 0.005
