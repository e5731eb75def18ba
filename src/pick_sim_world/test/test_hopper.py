"""The hopper that feeds a tray (hopper.py), measured as a physicist would: the dose against the
shortfall, the outlet's height and the parts' speed as they leave it, no part let out above
the outlet, and the feed held back where the pile stands at the outlet."""

from dataclasses import replace
import math

import numpy as np
from pick_common import containers
from pick_common.containers import ContainerSpec
from pick_common.errors import InvalidArgument
from pick_common.parts.spec import PartSpec
from pick_common.specs import SceneSpec
from pick_common.states import rotate
from pick_sim_world import hopper
from pick_sim_world.config import GRAVITY
from pick_sim_world.world import World
import pytest

TRAY = ContainerSpec.tray()


def _world(container=TRAY, model='to220', seed=3):
    return World(SceneSpec(container, PartSpec(model=model), 1, seed))


def _lowest(world, poses):
    """Each part's lowest point (N,) over the floor, m, from its hull and pose."""
    hull = world.part.visual.convex_hull.vertices
    return np.array([p[2] + rotate(p[None, 3:], hull)[:, 2].min() for p in poses])


def test_the_outlet_is_the_zones_outer_edge_and_parts_leave_toward_the_centre():
    out = hopper.outlet(TRAY)
    (cx, cy), (sx, sy) = TRAY.feeder_zone_center, TRAY.feeder_zone_size
    assert out.lip == pytest.approx(cx - sx / 2) and out.inward == 1.0
    assert out.half_width == pytest.approx(sy / 2) and out.centre_y == cy
    assert out.height == containers.DROP_HEIGHT[containers.TRAY]
    assert out.velocity == (containers.HOPPER_SPEED, 0.0, 0.0)
    other = hopper.outlet(replace(TRAY, feeder_zone_center=(-cx, 0.01), hopper_speed=0.3,
                                  hopper_rate=4.0))
    assert other.lip == pytest.approx(-cx + sx / 2) and other.velocity == (-0.3, 0.0, 0.0)
    assert (other.rate, other.centre_y) == (4.0, 0.01)
    with pytest.raises(InvalidArgument, match='needs a tray; instance 0 has a bin'):
        hopper.outlet(ContainerSpec())


def test_a_part_leaves_at_the_outlets_height_never_above_and_across_it():
    with _world() as world:
        out = hopper.outlet(TRAY)
        rng = np.random.default_rng(5)
        poses = np.array([hopper.release(rng, world.part, world.part.visual.convex_hull.vertices,
                                         out, np.empty((0, 7))) for _ in range(50)])
        lowest = _lowest(world, poses)
        centres = poses[:, :3] + rotate(poses[:, 3:], world.part.center)
    assert np.allclose(lowest, out.height, atol=1e-12)
    r = world.part.radius + 0.0005
    assert np.allclose(centres[:, 0], out.lip + r)
    assert (np.abs(centres[:, 1] - out.centre_y) <= out.half_width - r + 1e-12).all()
    assert np.ptp(centres[:, 1]) > out.half_width     # spread across, not one spot


def test_the_outlet_is_taken_only_by_a_part_reaching_above_its_lip():
    with _world() as world:
        part, hull = world.part, world.part.visual.convex_hull.vertices
        out = replace(hopper.outlet(TRAY), half_width=part.radius + 0.0005)   # one place
        rng = np.random.default_rng(1)
        first = hopper.release(rng, part, hull, out, np.empty((0, 7)))
        # a part just let out takes the place; lowered wholly under the lip it does not
        assert hopper.release(rng, part, hull, out, first[None]) is None
        below = first.copy()
        below[2] -= _lowest(world, first[None])[0] - out.height + 2.0 * part.radius + 1e-4
        assert hopper.release(rng, part, hull, out, below[None]) is not None


def test_a_dose_runs_for_its_time_and_brings_the_shortfall_onto_an_empty_tray():
    with _world(replace(TRAY, hopper_rate=20.0), model='radial_capacitor') as world:
        ids, report = world.drop(12, zone='feeder')
        state = world.snapshot()
    assert len(ids) == 12 and state.inside.all() and report.landed_ids == []
    # twelve ticks of 1/20 s, then the settle
    assert report.sim_time >= 12 / 20.0 - 1e-9


def test_a_part_leaves_moving_at_the_hoppers_speed_and_falls_from_the_outlet():
    speed, height = 0.25, 0.1        # a 0.14 s fall: the first checks see it in the air
    spec = replace(TRAY, hopper_speed=speed, drop_height=height)
    seen = []
    with _world(spec) as world:
        def watch(progress):
            body = world.body(0)
            seen.append((progress.sim_time, world.engine.velocity(body)[0],
                         _lowest(world, world.snapshot().poses)[0]))
            return True
        ids, _ = world.drop(1, zone='feeder', progress=watch)
        start, dt = hopper.outlet(spec).lip, world.physics.time_step
        rest = world.snapshot().poses[0]
    assert ids == [0]
    t, velocity, lowest = seen[0]     # the first check, 0.05 s out
    assert t < math.sqrt(2 * (height - 0.01) / GRAVITY)
    assert velocity[0] == pytest.approx(speed, rel=0.01) and abs(velocity[1]) < 1e-6
    assert velocity[2] == pytest.approx(-GRAVITY * t, rel=0.05)
    # the engine's semi-implicit Euler steps fall g t (t + dt) / 2, dt its step
    assert lowest == pytest.approx(height - GRAVITY * t * (t + dt) / 2, abs=1e-5)
    assert max(s[2] for s in seen) <= height + 1e-9
    # it flew on at that speed over the fall from the lip, onto the tray toward its centre
    assert rest[0] - start > 0.9 * speed * math.sqrt(2 * (height - 0.02) / GRAVITY)


def test_a_pile_at_the_outlet_holds_the_feed_back():
    # a lip 5 mm over the floor, one place wide: the first parts cover it, the rest wait
    spec = replace(TRAY, drop_height=0.005, hopper_speed=0.01,
                   feeder_zone_size=(TRAY.feeder_zone_size[0], 0.035))
    with _world(spec) as world:
        ids, report = world.drop(20, zone='feeder')
    assert 0 < len(ids) < 20 and report.settled
