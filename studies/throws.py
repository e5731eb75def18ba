"""Does the solver throw parts? TO-220s (PTH1's part, the one thrown off the tray in the reduced
test case) fed onto the tray and spread many times, per solver setting on the same seeds; the
world reads every part's speed after every step and names the parts faster than gravity and
the tray can make them (world.speed_limit).

    tools/ws python -m studies.throws [--settings default,warm-1] [--seeds 10,11,12]
        [--parts 50] [--moves 200]

Prints per setting and seed: moves with a thrown part, parts thrown, parts that ended off the
tray (thrown or spilled), the fastest part (m/s) and the wall time; then the totals. A move
settles for at most 0.25 s, so the moves come fast, as a feeder's do. One process per setting,
at most one per CPU.
"""

import argparse
from dataclasses import replace
import multiprocessing
import os
import time

from pick_common.containers import ContainerSpec
from pick_common.parts.spec import PartSpec
from pick_common.specs import MOVES, SceneSpec
from pick_sim_world.config import PhysicsConfig
from pick_sim_world.world import World

from studies.cases import parse_args

SETTINGS = {
    'default': {},                          # 1/480 s, 50 iterations, warm start 0.85
    '1/240': {'time_step': 1 / 240},        # an earlier default step
    'warm-1': {'time_step': 1 / 240, 'warm_starting_factor': 1.0},   # an earlier default
    'warm-0.5': {'warm_starting_factor': 0.5},
    'warm-0.1': {'warm_starting_factor': 0.1},       # pybullet's
    'dt/2': {'time_step': PhysicsConfig().time_step / 2},
    'tray-100-it': {'tray_solver_iterations': 100},     # an earlier default
    '30-it': {'tray_solver_iterations': 30},
}


def run(job: tuple[str, list[int], int, int]) -> list[str]:
    name, seeds, parts, moves = job
    physics = replace(PhysicsConfig(), **SETTINGS[name])
    lines, totals = [], [0, 0, 0, 0.0, 0.0]
    for seed in seeds:
        start = time.perf_counter()
        with World(SceneSpec(ContainerSpec.tray(), PartSpec(model='to220'), 1, seed),
                   physics) as world:
            world.drop(parts, zone='feeder')
            reports = [world.vibrate(MOVES['spread'], max_settle_time=0.25) for _ in range(moves)]
            off = int((~world.snapshot().inside).sum())
        wall = time.perf_counter() - start
        thrown = {i for r in reports for i in r.thrown_ids}
        with_thrown = sum(bool(r.thrown_ids) for r in reports)
        fastest = max(r.max_speed for r in reports)
        lines.append(f'{name:9s} seed {seed:3d}: moves with a thrown part {with_thrown:3d} of '
                     f'{moves}, parts thrown {len(thrown):2d}, off the tray {off:2d}, fastest '
                     f'{fastest:5.2f} m/s, wall {wall:5.0f} s')
        totals = [totals[0] + with_thrown, totals[1] + len(thrown), totals[2] + off,
                  max(totals[3], fastest), totals[4] + wall]
    lines.append(f'{name:9s} total ({len(seeds)} seeds x {moves} moves): moves with a thrown '
                 f'part {totals[0]}, parts thrown {totals[1]}, off the tray {totals[2]}, '
                 f'fastest {totals[3]:.2f} m/s, wall {totals[4]:.0f} s')
    return lines


# the size of its smoke test (tests/test_studies.py): `--small`
SMALL = ['--settings', 'default', '--seeds', '10', '--parts', '10', '--moves', '2']


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--settings', default='default,warm-1')
    parser.add_argument('--seeds', default='10,11,12')
    parser.add_argument('--parts', type=int, default=50)
    parser.add_argument('--moves', type=int, default=200)
    args = parse_args(parser, SMALL)
    names = args.settings.split(',')
    unknown = [n for n in names if n not in SETTINGS]
    if unknown:
        parser.error(f'--settings: unknown {", ".join(unknown)} (known: {", ".join(SETTINGS)})')
    seeds = [int(s) for s in args.seeds.split(',')]
    print(f'{args.parts} TO-220s fed onto the tray, {args.moves} spread moves, seeds {seeds}',
          flush=True)
    with multiprocessing.Pool(min(len(names), os.cpu_count() or 1)) as pool:
        for lines in pool.imap(run, [(n, seeds, args.parts, args.moves) for n in names]):
            print('\n'.join(lines), flush=True)


if __name__ == '__main__':
    main()
