"""Does a settled pile stay put? Drop a test-case part (TO-220s, PTH1's, by default) into a bin,
settle (a cap, 5 s), then step one more second and count the parts that move more than the
settle tolerance (0.5 mm), at the defaults and under settings that could be the cause of the
creep (most of them on the former defaults, where the creep was found; the 'former' settings
keep that day's 1 mm rolling and spinning friction arms, the others take today's, 0.1 mm,
unless they change them: ARMS).

    tools/ws python -m studies.creep [--parts 150] [--bin 75x75x60] [--seed 0] [--cap 5]
        [--part pth1] [--settings default,former,...] [--seconds 1]

Prints per setting: settled or not (and when), wall time, parts still moving at the end, the
deepest penetration, and over the further second the parts that moved > 0.5 mm, the median
and the largest displacement; with --seconds N, the movers in each of N further seconds (a pile
still settling moves less each second, a creeping one does not). One process; one seed per call.
"""

import argparse
from dataclasses import replace
import os
import time

from experiment_manager.experiment_file import load
import numpy as np
from pick_common.containers import ContainerSpec
from pick_common.specs import SceneSpec
from pick_sim_world.config import PhysicsConfig
from pick_sim_world.world import World

from studies.cases import parse_args, TEST_CASE

# The defaults before the convergence study: 30 iterations, pybullet's warm start 0.1
# and step of 1/240 s. The probes for the cause of the creep ran on them first (world README,
# "Piles that rest"); the probes that set Bullet's engine parameters, part dynamics or gravity
# directly (ERP, split impulse, CFM, cone friction, SAT, friction anchors, damping, a scene
# scaled x 10) needed the world's private client and were dropped from this script when
# benchmarks took to public names only; their figures in docs/studies.md were measured with it.
FORMER = {'solver_iterations': 30, 'warm_starting_factor': 0.1, 'time_step': 1 / 240}
# name: PhysicsConfig fields
SETTINGS = {
    'default': {},                  # 1/480 s, 100 iterations, warm start 0.85 (Bullet's)
    '1/240': {'time_step': 1 / 240},                # an earlier default step
    'warm-1': {'time_step': 1 / 240, 'warm_starting_factor': 1.0},   # an earlier default
    'dt/2': {'time_step': PhysicsConfig().time_step / 2},
    'dt/4': {'time_step': PhysicsConfig().time_step / 4},
    '200-it': {'solver_iterations': 200},
    '30-it': {'solver_iterations': 30},
    '50-it': {'solver_iterations': 50},
    'warm-0.1': {'warm_starting_factor': 0.1},
    'former': FORMER,
    'former-60-it': {**FORMER, 'solver_iterations': 60},
    'former-100-it': {**FORMER, 'solver_iterations': 100},
    'former-200-it': {**FORMER, 'solver_iterations': 200},
    'former-400-it': {**FORMER, 'solver_iterations': 400},
    'former-dt/2': {**FORMER, 'time_step': 1 / 480},
    'former-100-it-dt/2': {**FORMER, 'solver_iterations': 100, 'time_step': 1 / 480},
    'former-warm-0.85': {**FORMER, 'warm_starting_factor': 0.85},     # Bullet's own
    'former-warm-1': {**FORMER, 'warm_starting_factor': 1.0},
    'former-breaking-5mm': {**FORMER, 'contact_breaking_threshold': 0.005},
    'former-breaking-20mm': {**FORMER, 'contact_breaking_threshold': 0.02},   # Bullet's
    # the parts' rolling and spinning friction arms (the cause of the creep): the
    # earlier defaults (1 mm each), one of them at a time, and other arms
    'former-arms-1mm': {},
    'rolling-1mm': {}, 'spinning-1mm': {},
    'rolling-0': {}, 'rolling-0.2mm': {}, 'rolling-0.3mm': {}, 'rolling-0.5mm': {},
    'arms-0.01mm': {},
}
# The parts' rolling and spinning friction arms, m, where a setting changes them. The 'former'
# settings keep the arms of their day (1 mm each), so that their figures stand.
FORMER_ARMS = (1e-3, 1e-3)
ARMS = {'former-arms-1mm': FORMER_ARMS, 'rolling-1mm': (1e-3, None),
        'spinning-1mm': (None, 1e-3), 'rolling-0': (0.0, None), 'rolling-0.2mm': (2e-4, None),
        'rolling-0.3mm': (3e-4, None), 'rolling-0.5mm': (5e-4, None),
        'arms-0.01mm': (1e-5, 1e-5)}

def creep(name: str, parts: int, size: tuple[float, float, float], seed: int, cap: float,
          physics: dict, seconds: int = 1, case: str = 'pth1') -> str:
    part = load(os.path.join(TEST_CASE, f'{case}.yaml')).part
    rolling, spinning = ARMS.get(name, FORMER_ARMS if name.startswith('former') else
                                 (None, None))
    pairs = {}
    for pair in ('part_on_surface', 'part_on_part'):
        contact = getattr(part, pair)
        pairs[pair] = replace(contact, rolling_friction=contact.rolling_friction
                              if rolling is None else rolling,
                              spinning_friction=contact.spinning_friction
                              if spinning is None else spinning)
    part = replace(part, **pairs)
    spec = ContainerSpec(inner_size=size, wall_thickness=0.003)
    with World(SceneSpec(spec, part, 1, seed), PhysicsConfig(**physics)) as world:
        start = time.perf_counter()
        _, report = world.drop(parts, max_settle_time=cap)
        wall = time.perf_counter() - start
        before = world.snapshot()
        # every further second apart: a pile still settling moves less each second, a creeping
        # one keeps moving
        per_second = []
        for _ in range(seconds):
            start_of_second = world.snapshot()
            world.advance(1.0)   # a full second, at rest or not
            step = np.linalg.norm(world.snapshot().poses[:, :3] - start_of_second.poses[:, :3],
                                  axis=1)
            per_second.append(int((step > 0.0005).sum()))
        moved = np.linalg.norm(world.snapshot().poses[:, :3] - before.poses[:, :3], axis=1)
    return (f'settled {report.settled!s:5} at {report.sim_time:5.2f} s, wall {wall:5.1f} s, '
            f'moving {len(report.unsettled_ids):3d}, penetration '
            f'{1000 * report.max_penetration:.2f} mm | one more second: '
            f'{per_second[0]:3d} moved > 0.5 mm, median '
            f'{1000 * np.median(moved):.3f} mm, max {1000 * moved.max():.2f} mm'
            + (f' | moved > 0.5 mm in each of {seconds} seconds: '
               f'{", ".join(map(str, per_second))}' if seconds > 1 else ''))

# the size of its smoke test (tests/test_studies.py): `--small`
SMALL = ['--parts', '20', '--settings', 'default', '--cap', '1', '--seconds', '1']


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--parts', type=int, default=150)
    parser.add_argument('--bin', default='75x75x60', help='inner size, mm')
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--part', default='pth1', choices=('pth0', 'pth1', 'pth2'),
                        help='the test-case file whose part is dropped (pth1: TO-220s)')
    parser.add_argument('--cap', type=float, default=5.0, help='settle cap, s')
    parser.add_argument('--settings', default=','.join(SETTINGS))
    parser.add_argument('--seconds', type=int, default=1,
                        help='further seconds, each counted apart (median and max: over all)')
    args = parse_args(parser, SMALL)
    size = tuple(float(x) / 1000 for x in args.bin.split('x'))
    print(f'{args.parts} parts of {args.part} into a {args.bin} mm bin, seed {args.seed}',
          flush=True)
    for name in args.settings.split(','):
        line = creep(name, args.parts, size, args.seed, args.cap, SETTINGS[name], args.seconds,
                     args.part)
        print(f'{name:18s} {line}', flush=True)


if __name__ == '__main__':
    main()
