"""The physics collides what the checks collide, and applies the contact materials the file
gives, measured as a physicist would: where a resting part touches the floor, how fast a
sliding part slows, how high a dropped one rebounds, how a rolling and a spinning one slow."""

import os

import numpy as np
from pick_common import containers
from pick_common.containers import ContainerSpec
from pick_common.errors import InvalidArgument
from pick_common.parts import insets
from pick_common.parts.geometry import build_part
from pick_common.parts.materials import body_values, combined, Contact, TINY
from pick_common.parts.primitives import box
from pick_common.parts.spec import PartSpec
from pick_common.states import rotate
from pick_sim_world import bodies
from pick_sim_world.config import GRAVITY, PhysicsConfig
from pick_sim_world.engine import Engine
import pybullet as pb
import pytest
import trimesh

DT = PhysicsConfig().time_step
SURFACE = Contact(lateral_friction=0.35, rolling_friction=2e-4, spinning_friction=3e-4,
                  restitution=0.5)
PART = Contact(lateral_friction=0.5, rolling_friction=1e-4, spinning_friction=1e-4,
               restitution=0.3)


@pytest.fixture
def engine():
    e = Engine(PhysicsConfig().length_unit)
    bodies.configure(e, PhysicsConfig(), containers.BIN)
    yield e
    e.close()


def _mesh_part(tmp_path, name: str, mesh: trimesh.Trimesh):
    path = os.path.join(tmp_path, f'{name}.stl')
    mesh.export(path)
    return build_part(PartSpec(model='mesh', mesh_path=path, mass=0.002))


def _rest(engine, part, orientation, directory) -> np.ndarray:
    """The part dropped 20 mm onto a bin's floor (its top at z = 0) and left 2 s: the
    world-frame vertices of its visual mesh, m."""
    part_values, surface = body_values(part.spec.part_on_surface, part.spec.part_on_part)
    bodies.create_container(engine, ContainerSpec(), np.zeros(3), surface)
    shape = bodies.create_part_shape(engine, part, str(directory))
    pose = np.array([0.0, 0.0, 0.02 + part.radius, *orientation])
    body = bodies.create_part(engine, shape, part, pose, part_values)
    for _ in range(int(2.0 / DT)):
        engine.step()
    frame = bodies.part_frame_poses(engine.poses([body]), part)[0]
    return frame[:3] + rotate(np.repeat(frame[None, 3:], len(part.visual.vertices), 0),
                              part.visual.vertices)


@pytest.mark.parametrize('name, mesh, orientation', [
    ('cube', trimesh.creation.box((0.01, 0.01, 0.01)), (0.0, 0.0, 0.0, 1.0)),
    ('standing_cylinder', trimesh.creation.cylinder(0.003, 0.008, sections=48),
     (0.0, 0.0, 0.0, 1.0)),
    ('lying_cylinder', trimesh.creation.cylinder(0.003, 0.008, sections=48),
     (np.sqrt(0.5), 0.0, 0.0, np.sqrt(0.5))),
])
def test_a_mesh_part_rests_on_its_geometry_not_on_a_margin(engine, tmp_path, name, mesh,
                                                           orientation):
    part = _mesh_part(tmp_path, name, mesh)
    vertices = _rest(engine, part, orientation, tmp_path)
    # the lowest point of the geometry the checks collide lies on the floor, within 0.1 mm
    # (it lay 1 mm above it with pybullet's hull margin in metres, uninset)
    assert abs(vertices[:, 2].min()) < 1e-4
    assert insets.hull_swelling(part, engine.hull_margin) == 0.0
    # and where the physics touches the floor is on that geometry's surface
    touching = engine.contacts()
    assert touching
    for _, _, distance in touching:
        assert abs(distance) < 1e-4


def test_a_piece_thinner_than_two_margins_is_reported_swollen(tmp_path):
    part = _mesh_part(tmp_path, 'plate', trimesh.creation.box((0.01, 0.01, 0.0012)))
    # at the engine's 0.01 mm margin a 1.2 mm plate is inset by the whole margin
    assert insets.hull_swelling(part) == 0.0
    # with a 1 mm margin (a world in metres) only by 0.45 of its 1.2 mm: its faces lie 1 -
    # 0.54 mm outside the plate
    assert insets.hull_swelling(part, 1e-3) == pytest.approx(0.00046, abs=1e-9)


def _floor(engine, values) -> int:
    floor = engine.body(0.0, engine.shape([box((1.0, 1.0, 0.01))]), [0, 0, -0.01])
    engine.set_contact(floor, values)
    return floor


def _body(engine, shape: int, position, values, mass=0.002) -> int:
    body = engine.body(mass, shape, position)
    engine.set_contact(body, values, damping=0.0)
    return body


def _slope(samples) -> float:
    return float(np.polyfit(np.arange(len(samples)) * DT, samples, 1)[0])


def _steps(engine, n: int, read) -> list[float]:
    out = []
    for _ in range(n):
        engine.step()
        out.append(read())
    return out


@pytest.mark.parametrize('pair', ['part_on_surface', 'part_on_part'])
def test_the_physics_applies_each_pair_s_values_within_2_percent(engine, pair):
    part, surface = body_values(SURFACE, PART)
    want = SURFACE if pair == 'part_on_surface' else PART
    _floor(engine, surface if pair == 'part_on_surface' else part)
    mass, r = 0.002, 0.005

    def velocity(body, angular=False):
        return lambda: engine.velocity(body)[int(angular)]

    # slide: a box pushed to 0.5 m/s slows at mu g
    cube = _body(engine, engine.shape([box((r, r, 0.002))]), [0, 0, 0.002], part)
    _steps(engine, 100, lambda: 0)
    engine.set_velocity(cube, [0.5, 0, 0])
    slowing = -_slope([v[0] for v in _steps(engine, 40, velocity(cube))])
    assert slowing / GRAVITY == pytest.approx(want.lateral_friction, rel=0.02)
    engine.remove(cube)

    # rebound: a ball dropped 50 mm leaves the floor at e times the speed it arrived at (an
    # exact sphere: pybullet's own shape, in the engine's units)
    sphere = pb.createCollisionShape(pb.GEOM_SPHERE, radius=r / engine.unit,
                                     physicsClientId=engine.client)
    ball = _body(engine, sphere, [0, 0, r + 0.05], part)
    falls = [v[2] for v in _steps(engine, 240, velocity(ball))]
    up = next(i for i, v in enumerate(falls) if v > 0)
    # the step that turns it round adds a step of gravity before the contact is solved
    assert falls[up] / (GRAVITY * DT - falls[up - 1]) == pytest.approx(want.restitution,
                                                                      rel=0.02)
    engine.remove(ball)

    # rolling: a ball rolling without slipping slows at arm g r m / (I + m r^2)
    ball = _body(engine, sphere, [0, 0, r], part)
    _steps(engine, 50, lambda: 0)
    engine.set_velocity(ball, [0.2, 0, 0], [0, 0.2 / r, 0])
    inertia = engine.mass(ball).inertia[0] * engine.unit ** 2       # kg m^2
    slowing = -_slope([v[0] for v in _steps(engine, 60, velocity(ball))])
    arm = slowing * (inertia + mass * r * r) / (mass * GRAVITY * r)
    assert arm == pytest.approx(want.rolling_friction, rel=0.02)

    # spinning about the vertical: I dw/dt = -arm m g
    engine.set_velocity(ball, [0, 0, 0], [0, 0, 20.0])
    slowing = -_slope([w[2] for w in _steps(engine, 30, velocity(ball, angular=True))])
    assert slowing * inertia / (mass * GRAVITY) == pytest.approx(want.spinning_friction,
                                                                 rel=0.02)


def test_body_values_combine_to_the_pairs_and_a_pair_of_zero_stays_zero():
    for surface, part in [(SURFACE, PART),
                          (Contact(0.4, 1e-4, 1e-4, 0.0), Contact(0.0, 0.0, 0.0, 0.0)),
                          (Contact(0.0, 0.0, 0.0, 0.6), Contact(0.3, 2e-4, 1e-4, 0.2))]:
        p, s = body_values(surface, part)
        for got, want in ((combined(p, s), surface), (combined(p, p), part)):
            for name in ('lateral_friction', 'rolling_friction', 'spinning_friction',
                         'restitution'):
                assert getattr(got, name) == pytest.approx(getattr(want, name), rel=1e-9,
                                                           abs=TINY)


def test_a_pair_bullet_cannot_apply_is_refused_naming_both():
    # the part's own arm against a rough surface already gives more than 0.01 mm
    with pytest.raises(InvalidArgument) as err:
        body_values(Contact(0.8, 1e-5, 1e-4, 0.3), Contact(0.1, 1e-3, 1e-4, 0.3))
    assert err.value.field == 'materials.part_on_surface.rolling_friction'
    assert 'part_on_part' in str(err.value) and 'at least' in str(err.value)
    with pytest.raises(InvalidArgument, match='part_on_part.restitution'):
        body_values(SURFACE, Contact(0.5, 1e-4, 1e-4, 1.5))
