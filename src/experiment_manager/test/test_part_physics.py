"""The physics collides each part's own surface, on every face it can rest on: the built-in
models, the tutorial's TO-220 and KiCad's 5 mm capacitor and DIP-8, each from its STEP file.
Measured as a physicist would, with the engine's own distance query and by letting the part
come to rest: never more than 0.05 mm outside its geometry (pybullet's hull margin was 1 mm
in a world in metres; the world now simulates in centimetres, pick_sim_world's engine.py)."""

import os

import numpy as np
from pick_common.containers import ContainerSpec
from pick_common.parts.aspects import part_aspects
from pick_common.parts.geometry import build_part, PartGeometry, primitive_mesh
from pick_common.parts.materials import body_values
from pick_common.parts.models import BUILTIN_MODELS
from pick_common.parts.spec import PartSpec
from pick_common.states import rotate
from pick_sim_world import bodies
from pick_sim_world.config import PhysicsConfig
from pick_sim_world.engine import Engine
import pytest
import trimesh

PARTS = os.path.join(os.path.dirname(__file__), '..', 'config', 'parts')
STEP = {'to220_kicad': 'TO-220-3_Vertical.step', 'capacitor_kicad': 'CP_Radial_D5.0mm_P2.00mm.step',
        'dip8_kicad': 'DIP-8_W7.62mm.step'}
TOLERANCE = 5e-5        # m: the most the physics' surface may lie outside the part's
GAP = 0.001             # m: how high over the floor each part is first held


def _spec(name: str) -> PartSpec:
    if name in STEP:
        return PartSpec(model='mesh', mesh_path=os.path.join(PARTS, STEP[name]), mass=0.001)
    return PartSpec(model=name)


def _surface(part: PartGeometry) -> np.ndarray:
    """The vertices (K, 3) of the surface the checks collide, in the part frame, m: a mesh's
    own, a built-in's primitives'."""
    if part.mass_frame is not None:
        return np.asarray(part.visual.vertices)
    return np.vstack([primitive_mesh(p).vertices for p in part.primitives])


def _onto(normal: np.ndarray) -> np.ndarray:
    """The xyzw quaternion that turns `normal` (part frame) to world -z."""
    down = np.array([0.0, 0.0, -1.0])
    axis = np.cross(normal, down)
    angle = np.arctan2(np.linalg.norm(axis), float(normal @ down))
    if np.linalg.norm(axis) < 1e-12:
        axis = np.array([1.0, 0.0, 0.0])
    axis /= np.linalg.norm(axis)
    return np.array([*(axis * np.sin(angle / 2)), np.cos(angle / 2)])


@pytest.mark.parametrize('name', [*sorted(BUILTIN_MODELS), *STEP])
def test_every_face_collides_within_0_05_mm_of_the_part_and_rests_on_it(name, tmp_path):
    """Each aspect held face down 1 mm over a bin's floor: the engine's distance from the
    part to the floor is the geometry's within 0.05 mm; let go, it comes to rest with its
    lowest point within 0.05 mm of the floor."""
    part = build_part(_spec(name))
    aspects = part_aspects(part)
    surface = _surface(part)
    engine = Engine(PhysicsConfig().length_unit)
    try:
        bodies.configure(engine, PhysicsConfig(), 'bin')
        values, floor_values = body_values(part.spec.part_on_surface, part.spec.part_on_part)
        pitch = 3 * part.radius + 0.01
        width = pitch * (len(aspects) + 1)
        floor = bodies.create_container(engine, ContainerSpec(inner_size=(width, pitch, 0.02)),
                                        np.zeros(3), floor_values)
        shape = bodies.create_part_shape(engine, part, str(tmp_path))
        placed = []
        for k, aspect in enumerate(aspects):
            q = _onto(np.asarray(aspect.normal))
            low = rotate(np.repeat(q[None], len(surface), 0), surface)[:, 2].min()
            pose = np.array([(k + 1) * pitch - width / 2, 0.0, GAP - low, *q])
            body = bodies.create_part(engine, shape, part, pose, values)
            held = min(engine.closest(body, floor, 0.01))
            assert abs(held - GAP) < TOLERANCE, (aspect.name, held)
            placed.append(body)
        for _ in range(int(1.0 / PhysicsConfig().time_step)):
            engine.step()
        frames = bodies.part_frame_poses(engine.poses(placed), part)
    finally:
        engine.close()
    for aspect, frame in zip(aspects, frames, strict=True):
        lowest = (frame[:3] + rotate(np.repeat(frame[None, 3:], len(surface), 0), surface))[:, 2]
        assert abs(lowest.min()) < TOLERANCE, (aspect.name, lowest.min())


def test_a_piece_of_a_thin_part_swells_no_further_than_the_margin(tmp_path):
    """A 0.3 mm lead-like rod of a mesh: inset by the engine's 0.01 mm margin whole, so its
    physics' surface is its own (in metres the 1 mm margin swelled it by 0.87 mm)."""
    path = os.path.join(tmp_path, 'rod.stl')
    trimesh.creation.box((0.0003, 0.0003, 0.01)).export(path)
    part = build_part(PartSpec(model='mesh', mesh_path=path, mass=0.0001))
    from pick_common.parts.insets import hull_swelling
    assert hull_swelling(part) == 0.0
    assert hull_swelling(part, 1e-3) == pytest.approx(0.001 - 0.45 * 0.0003, abs=1e-9)
