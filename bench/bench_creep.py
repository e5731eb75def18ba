"""Does a settled pile stay put? Drop TO-220s (PTH1's part) into a bin, settle (a cap, 5 s), then
step one more second and count the parts that move more than the settle tolerance (0.5 mm),
under engine settings that could be the cause of the creep.

    tools/ws python bench/bench_creep.py [--parts 150] [--bin 75x75x60] [--seed 0] [--cap 5]
        [--settings default,100-it,...]

Prints per setting: settled or not (and when), wall time, parts still moving at the end, the
deepest penetration, and over the further second the parts that moved > 0.5 mm, the median
and the largest displacement. One process; one seed per call.
"""

import argparse
from dataclasses import replace
import os
import time

from experiment_manager.config import load
import numpy as np
from pick_common.containers import ContainerSpec
from pick_common.parts import BUILTIN_MODELS
from pick_common.specs import SceneSpec
from pick_sim_world import bodies, spawning, tray
from pick_sim_world.bodies import CONTAINER_FRICTION
from pick_sim_world.config import GRAVITY, PhysicsConfig
from pick_sim_world.world import World
import pybullet as pb

PTH1 = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'src',
                    'experiment_manager', 'config', 'test_case', 'pth1.yaml')
# name: (PhysicsConfig fields, extra setPhysicsEngineParameter arguments)
SETTINGS = {
    'default': ({}, {}),
    '60-it': ({'solver_iterations': 60}, {}),
    '100-it': ({'solver_iterations': 100}, {}),
    '200-it': ({'solver_iterations': 200}, {}),
    '400-it': ({'solver_iterations': 400}, {}),
    'dt/2': ({'time_step': 1 / 480}, {}),
    '100-it-dt/2': ({'solver_iterations': 100, 'time_step': 1 / 480}, {}),
    'erp-0.8': ({}, {'erp': 0.8, 'contactERP': 0.8}),
    'no-split-impulse': ({}, {'useSplitImpulse': 0}),
    'cfm-slop': ({}, {'globalCFM': 1e-5, 'contactSlop': 1e-4}),
    'residual-1e-9': ({}, {'solverResidualThreshold': 1e-9}),
    'friction-0.5': ({}, {}),   # coefficients sqrt(0.5): Bullet's product is then 0.5
    'scaled-x10': ({}, {}),     # lengths and gravity x 10, masses x 1000: same dynamics
}


def creep(name: str, parts: int, size: tuple[float, float, float], seed: int, cap: float,
          physics: dict, engine: dict) -> str:
    part = load(PTH1).part
    spec = ContainerSpec(inner_size=size, wall_thickness=0.003)
    scale = 1.0
    if name == 'friction-0.5':
        bodies.CONTAINER_FRICTION = 0.5 ** 0.5
        part = replace(part, lateral_friction=0.5 ** 0.5)
    if name == 'scaled-x10':
        scale = 10.0
        bodies.GRAVITY = spawning.GRAVITY = tray.GRAVITY = GRAVITY * scale
        dims, mass, _ = BUILTIN_MODELS[part.model]
        part = replace(part, dimensions={k: v * scale for k, v in dims.items()},
                       mass=mass * scale ** 3, rolling_friction=part.rolling_friction * scale,
                       spinning_friction=part.spinning_friction * scale)
        spec = ContainerSpec(inner_size=tuple(x * scale for x in size), wall_thickness=0.03,
                             floor_thickness=spec.floor_thickness * scale)
        physics = {**physics, 'contact_breaking_threshold': 0.01,
                   'settle_linear_tolerance': 0.005}
    with World(SceneSpec(spec, part, 1, seed), PhysicsConfig(**physics)) as world:
        if engine:
            pb.setPhysicsEngineParameter(physicsClientId=world._client, **engine)
        start = time.perf_counter()
        _, report = world.drop(parts, max_settle_time=cap)
        wall = time.perf_counter() - start
        before = world.snapshot()
        world._run('settling', 1.0, None, stop_when_settled=False)   # a full second
        moved = np.linalg.norm(world.snapshot().poses[:, :3] - before.poses[:, :3],
                               axis=1) / scale
    bodies.CONTAINER_FRICTION = CONTAINER_FRICTION
    bodies.GRAVITY = spawning.GRAVITY = tray.GRAVITY = GRAVITY
    return (f'settled {report.settled!s:5} at {report.sim_time:5.2f} s, wall {wall:5.1f} s, '
            f'moving {len(report.unsettled_ids):3d}, penetration '
            f'{1000 * report.max_penetration / scale:.2f} mm | one more second: '
            f'{int((moved > 0.0005).sum()):3d} moved > 0.5 mm, median '
            f'{1000 * np.median(moved):.3f} mm, max {1000 * moved.max():.2f} mm')


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--parts', type=int, default=150)
    parser.add_argument('--bin', default='75x75x60', help='inner size, mm')
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--cap', type=float, default=5.0, help='settle cap, s')
    parser.add_argument('--settings', default=','.join(SETTINGS))
    args = parser.parse_args()
    size = tuple(float(x) / 1000 for x in args.bin.split('x'))
    print(f'{args.parts} TO-220s into a {args.bin} mm bin, seed {args.seed}', flush=True)
    for name in args.settings.split(','):
        physics, engine = SETTINGS[name]
        line = creep(name, args.parts, size, args.seed, args.cap, physics, engine)
        print(f'{name:18s} {line}', flush=True)


if __name__ == '__main__':
    main()
