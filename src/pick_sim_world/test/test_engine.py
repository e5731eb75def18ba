"""The engine: the one module that speaks to PyBullet, in SI units, while the world simulates
in centimetres."""

import ast
import pathlib

import numpy as np
from pick_common.parts.primitives import box
import pick_sim_world
from pick_sim_world.engine import Engine
import pytest


def test_in_the_world_only_its_engine_speaks_to_pybullet():
    """engine.py converts every length, velocity and force: no other module of the package
    may call PyBullet (it would hand it metres)."""
    def imports(path: pathlib.Path) -> set[str]:
        tree = ast.parse(path.read_text())
        return ({a.name.split('.')[0] for n in ast.walk(tree) if isinstance(n, ast.Import)
                 for a in n.names}
                | {(n.module or '').split('.')[0] for n in ast.walk(tree)
                   if isinstance(n, ast.ImportFrom)})

    root = pathlib.Path(pick_sim_world.__file__).parent
    assert sorted(p.name for p in root.glob('*.py') if 'pybullet' in imports(p)) == [
        'engine.py']


@pytest.mark.parametrize('unit', [0.01, 1.0])
def test_what_goes_in_in_si_comes_out_in_si_and_falls_at_g(unit):
    """A body placed, pushed and let fall in SI reads back in SI at any length unit: after
    0.1 s of free fall it has fallen g t^2 / 2 and moves at g t (semi-implicit Euler: one
    step's worth more), whatever the engine's unit."""
    engine = Engine(unit)
    try:
        engine.reset(9.81, 1 / 480, 10, 0.85, 0.02)
        body = engine.body(0.01, engine.shape([box((0.002, 0.002, 0.002))]), [0.1, -0.2, 0.5])
        assert engine.position(body) == pytest.approx([0.1, -0.2, 0.5])
        engine.set_velocity(body, [0.3, 0.0, 0.0])
        for _ in range(48):
            engine.step()
        linear, _ = engine.velocity(body)
        t = 48 / 480
        assert linear == pytest.approx([0.3, 0.0, -9.81 * t], rel=1e-6)
        assert engine.position(body) == pytest.approx(
            [0.1 + 0.3 * t, -0.2, 0.5 - 9.81 * t * (t + 1 / 480) / 2], rel=1e-6)
        assert engine.speed(body) == pytest.approx(np.hypot(0.3, 9.81 * t), rel=1e-6)
    finally:
        engine.close()


def test_the_parameter_file_states_the_physics_defaults():
    """config/world.yaml says it states the defaults: its physics and settle settings are the
    code's (it kept the contact-breaking factor of the world in metres, 0.001, after the
    default became 0.02)."""
    from dataclasses import fields
    import os

    from pick_sim_world.config import PhysicsConfig
    import yaml

    path = os.path.join(os.path.dirname(__file__), '..', 'config', 'world.yaml')
    with open(path, encoding='utf-8') as f:
        stated = yaml.safe_load(f)['/**']['ros__parameters']
    names = {'max_settle_time': 'settle.max_time', 'settle_freeze': 'settle.freeze'}
    default = PhysicsConfig()
    for field in fields(PhysicsConfig):
        name = names.get(field.name) or (
            f'settle.{field.name[len("settle_"):]}' if field.name.startswith('settle_')
            else f'physics.{field.name}')
        if name in stated or name.startswith('physics.'):
            assert stated.get(name) == pytest.approx(getattr(default, field.name)), name
