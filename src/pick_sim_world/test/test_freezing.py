"""Freezing rested parts while a settle runs (freezing.py): what it must not change.

A frozen part is static until a moving part comes near; the settle after a pick from a resting
scene starts with only the parts the picked one touched awake. Wrong, either would leave parts
hovering where their support went, or a pile that moves on once its parts are dynamic again.
"""

import numpy as np
from pick_common.containers import ContainerSpec
from pick_common.errors import InvalidArgument
from pick_common.parts.materials import arms
from pick_common.parts.spec import PartSpec
from pick_common.specs import MOVES, SceneSpec
from pick_sim_world.config import PhysicsConfig
from pick_sim_world.world import World
import pytest

ARM = PartSpec().part_on_surface.rolling_friction
T = 0.0045                       # the TO-220's body thickness, m
FLAT = (np.sin(np.pi / 4), 0.0, 0.0, np.cos(np.pi / 4))    # its back (-Y) down


def _masses(world: World) -> set[float]:
    return {world.engine.mass(world.body(pid)).kg for pid in world.snapshot().ids.tolist()}


@pytest.mark.parametrize('freeze', [True, False], ids=['freeze', 'no-freeze'])
def test_a_column_falls_as_one_when_its_lowest_part_is_picked(freeze):
    """Twelve TO-220s stacked flat in a channel 12 mm wide, 54 mm tall: only the second
    touches the lowest, so the upper ones start frozen when it is picked (some farther from it
    than a part's length), and only waking part by part up the column brings them down. Every
    one must come down a part's thickness, and end dynamic again."""
    channel = ContainerSpec(inner_size=(0.012, 0.031, 0.1))
    scene = SceneSpec(channel, PartSpec(model='to220', **arms(ARM)), 1, 0)
    with World(scene, PhysicsConfig(settle_freeze=freeze)) as world:
        poses = np.array([[0.0, -0.00325, T / 2 + k * (T + 0.0001), *FLAT] for k in range(12)])
        ids = world._add_parts(world.instances[0], poses)
        assert world.settle().settled
        before = world.snapshot()
        assert np.ptp(np.diff(np.sort(before.poses[:, 2]))) < 0.0005, 'a stacked column'
        far = 2.0 * world.part.radius
        assert (before.poses[:, 2] - before.poses[0, 2] > far).sum() >= 3
        _, report = world.remove([ids[0]])
        after = world.snapshot()
        assert report.settled
        drop = before.poses[1:, 2] - after.poses[:, 2]
        assert np.all(np.abs(drop - T) < 0.001), f'came down {np.round(drop * 1000, 2)} mm'
        assert _masses(world) == {world.part.mass}


def test_a_pile_picked_from_stays_put_once_every_part_is_dynamic():
    """150 TO-220s in a 75 x 75 x 60 mm bin, ten parts picked from the top, each settle
    starting with only the parts the pick touched awake: a further second with every part
    dynamic moves at most as many parts as it does after the drop alone
    (test_world.test_a_settled_pile_stays_put: 7)."""
    part = PartSpec(model='to220', **arms(ARM))
    scene = SceneSpec(ContainerSpec(inner_size=(0.075, 0.075, 0.06)), part, 1, 0)
    with World(scene, PhysicsConfig()) as world:
        _, report = world.drop(150)
        assert report.settled
        for _ in range(10):
            state = world.snapshot()
            _, report = world.remove([int(state.ids[np.argmax(state.poses[:, 2])])])
            assert report.settled
        before = world.snapshot()
        world._run('settling', 1.0, None, stop_when_settled=False)    # no freezing here
        moved = np.linalg.norm(world.snapshot().poses[:, :3] - before.poses[:, :3], axis=1)
        assert _masses(world) == {world.part.mass}
    movers = int((moved > PhysicsConfig().settle_linear_tolerance).sum())
    assert movers <= 7, f'{movers} of 140 parts moved over 0.5 mm in a further second'


def test_the_tray_is_dynamic_again_after_a_settle_and_vibrates_as_commanded():
    with World(SceneSpec(ContainerSpec.tray(), PartSpec(), 1, 1), PhysicsConfig()) as world:
        world.drop(30)
        tray = world.instances[0].body
        for _ in range(2):
            report = world.vibrate(MOVES['spread'])
            assert world.engine.mass(tray).kg > 0
            assert report.tray.error < 0.05
        assert _masses(world) == {world.part.mass}


def test_an_empty_tray_settles_and_vibrates():
    with World(SceneSpec(ContainerSpec.tray(), PartSpec(), 1, 1), PhysicsConfig()) as world:
        assert world.settle().settled
        assert world.vibrate(MOVES['spread']).settled


def test_settle_freeze_must_be_a_boolean():
    with pytest.raises(InvalidArgument, match="settle.freeze: 'yes' must be true or false"):
        World(physics=PhysicsConfig(settle_freeze='yes'))
