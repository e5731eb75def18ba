"""Property tests: any value in a scene, drop or vibration either works or is refused with
InvalidArgument naming the field; nothing else escapes, and the world stays usable."""

import re

from hypothesis import given, HealthCheck, settings
from hypothesis import strategies as st
import numpy as np
from pick_common.containers import ContainerSpec
from pick_common.errors import check_inside, InvalidArgument, UnknownInstance
from pick_common.parts.materials import Contact
from pick_common.parts.spec import PartSpec
from pick_common.specs import SceneSpec, Vibration
from pick_sim_world.world import World
import pytest

ANY_FLOAT = st.one_of(st.floats(allow_nan=True, allow_infinity=True),
                      st.floats(min_value=-0.5, max_value=0.5))
SIZE = st.one_of(ANY_FLOAT, st.floats(min_value=0.004, max_value=0.4))
# One world per module (building one per example would dominate the run); deterministic.
SETTINGS = dict(deadline=None, derandomize=True,
                suppress_health_check=[HealthCheck.function_scoped_fixture])


@pytest.fixture(scope='module')
def world():
    with World(SceneSpec(ContainerSpec.tray())) as w:
        yield w


def _still_works(world: World) -> None:
    world.reset(SceneSpec(ContainerSpec.tray()))
    _, report = world.drop(3)
    assert report.settled and np.isfinite(world.snapshot().poses).all()


@settings(max_examples=60, **SETTINGS)
@given(size=st.tuples(SIZE, SIZE, SIZE), wall=SIZE, floor=SIZE, diameter=SIZE, mass=ANY_FLOAT,
       friction=ANY_FLOAT, count=st.integers(min_value=-5, max_value=6000))
def test_any_scene_and_count_works_or_names_the_field(world, size, wall, floor, diameter, mass,
                                                      friction, count):
    scene = SceneSpec(ContainerSpec(inner_size=size, wall_thickness=wall, floor_thickness=floor),
                      PartSpec(dimensions={'body_diameter': diameter}, mass=mass,
                               part_on_surface=Contact(friction, 1e-4, 1e-4, 0.3)))
    try:
        world.reset(scene)
        world.drop(count, max_settle_time=0.3)
    except InvalidArgument as exc:
        assert exc.field.split('[')[0] in (
            'container.inner_size', 'container.wall_thickness', 'container.floor_thickness',
            'part.dimensions.body_diameter', 'part.dimensions.lead_pitch', 'part.mass',
            'materials.part_on_surface.lateral_friction', 'count'), exc
    else:
        assert np.isfinite(world.snapshot().poses).all()
    _still_works(world)


@settings(max_examples=40, **SETTINGS)
@given(amplitude=st.tuples(ANY_FLOAT, ANY_FLOAT, ANY_FLOAT), frequency=ANY_FLOAT,
       duration=st.one_of(ANY_FLOAT, st.floats(min_value=0.01, max_value=0.2)),
       instances=st.lists(st.integers(min_value=-2, max_value=3), max_size=3))
def test_any_vibration_works_or_names_the_field(world, amplitude, frequency, duration,
                                                instances):
    world.reset(SceneSpec(ContainerSpec.tray()))
    world.drop(5)
    try:
        world.vibrate(Vibration(amplitude, frequency, duration), instances or None,
                      max_settle_time=0.3)
    except InvalidArgument as exc:
        assert exc.field.split('[')[0] in ('vibration.amplitude', 'vibration.frequency',
                                           'vibration.duration', 'instances'), exc
    except UnknownInstance as exc:
        assert 'instances:' in str(exc)
    _still_works(world)


def test_a_path_outside_the_given_directories_is_refused_before_anything_is_read(tmp_path):
    allowed, outside = tmp_path / 'meshes', tmp_path / 'other'
    allowed.mkdir()
    outside.mkdir()
    (allowed / 'part.stl').write_text('solid x\nendsolid x\n')
    (allowed / 'link.stl').symlink_to(outside / 'secret.stl')
    (allowed / 'sub').symlink_to(outside, target_is_directory=True)
    roots = [str(allowed)]
    assert check_inside('f', str(allowed / 'part.stl'), roots, 'p') == str(allowed / 'part.stl')
    assert check_inside('f', str(allowed / 'new' / 'x'), roots, 'p')   # need not exist
    for path in (outside / 'secret.stl', allowed / '..' / 'other' / 'secret.stl',
                 allowed / 'link.stl', allowed / 'sub' / 'secret.stl', '/etc/passwd',
                 str(allowed) + '_twin/part.stl', 'relative/part.stl'):
        with pytest.raises(InvalidArgument, match=re.escape(
                f"f: '{path}' is outside the directories this node may use (p: '{allowed}')")):
            check_inside('f', str(path), roots, 'p')
    with pytest.raises(InvalidArgument, match=r'\(p: none\)'):
        check_inside('f', str(allowed / 'part.stl'), [], 'p')
