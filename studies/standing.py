"""Do feeder moves stand capacitors on their heads? A capacitor of a test-case file dropped on
the tray, then spread by the default move again and again; after each block of moves, how the
parts lie: on their side, standing on the body's top with the leads up (no grasp can place it,
so candidacy rejects it), standing on the leads, or leaning. Per solver setting on the same
seeds, to tell the physics from the step.

    tools/ws python -m studies.standing [--file pth2] [--parts 100] [--moves 50]
        [--every 10] [--seeds 0,1] [--settings default,dt/2]

In an earlier reduced test case PTH2's feeder run (8 mm capacitors, 95-105 on the tray)
picked 101 of 480 parts in 500 moves: 58 % of its capacitors stood on their heads at the
checks, against 7 % of a dropped pile (the sweep's), and PTH0's (5 mm) 2 %. One process per
setting, at most one per CPU.
"""

import argparse
from dataclasses import replace
import multiprocessing
import os
import time

from experiment_manager.experiment_file import load
import numpy as np
from pick_common.containers import ContainerSpec
from pick_common.specs import MOVES, SceneSpec
from pick_common.states import rotate
from pick_sim_world.config import PhysicsConfig
from pick_sim_world.world import World

from studies.cases import parse_args, TEST_CASE

SETTINGS = {
    'default': {},                                      # 1/480 s
    'dt/2': {'time_step': PhysicsConfig().time_step / 2},
    '1/240': {'time_step': 1 / 240},
    '200-it': {'solver_iterations': 200},
}


def poses(quaternions: np.ndarray) -> dict[str, float]:
    """Fractions of parts by the angle of their axis (local z: body top; leads at -z) from
    the world's up: head down (> 150 deg), upright on the leads (< 30), on the side (60-120),
    leaning (the rest)."""
    up = rotate(quaternions, np.array([0.0, 0.0, 1.0]))[:, 2]   # the local z axis's world z
    angle = np.degrees(np.arccos(np.clip(up, -1, 1)))
    n = len(angle)
    return {'head down': (angle > 150).sum() / n, 'on leads': (angle < 30).sum() / n,
            'side': ((angle >= 60) & (angle <= 120)).sum() / n,
            'leaning': (((angle >= 30) & (angle < 60)) | ((angle > 120) & (angle <= 150))).sum()
            / n}


def run(job: tuple[str, str, list[int], int, int, int]) -> list[str]:
    name, file, seeds, parts, moves, every = job
    physics = replace(PhysicsConfig(), **SETTINGS[name])
    part = load(os.path.join(TEST_CASE, f'{file}.yaml')).part
    lines = []
    for seed in seeds:
        start = time.perf_counter()
        with World(SceneSpec(ContainerSpec.tray(), part, 1, seed), physics) as world:
            world.drop(parts)
            line = []
            for done in range(moves + 1):
                if done % every == 0:
                    f = poses(world.snapshot().poses[:, 3:])
                    line.append(f'{done}: {100 * f["head down"]:3.0f}/{100 * f["side"]:3.0f}'
                                f'/{100 * f["leaning"]:2.0f}/{100 * f["on leads"]:2.0f}')
                if done < moves:
                    world.vibrate(MOVES['spread'])
        wall = time.perf_counter() - start
        lines.append(f'{name:8s} seed {seed}: % head down/side/leaning/on leads after moves '
                     + ', '.join(line) + f'  (wall {wall:.0f} s)')
    return lines


# the size of its smoke test (tests/test_studies.py): `--small`
SMALL = ['--file', 'pth0', '--parts', '10', '--moves', '2', '--every', '1', '--seeds', '0',
         '--settings', 'default']


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--file', default='pth2', help='a test-case file: pth0 or pth2')
    parser.add_argument('--parts', type=int, default=100)
    parser.add_argument('--moves', type=int, default=50)
    parser.add_argument('--every', type=int, default=10)
    parser.add_argument('--seeds', default='0,1')
    parser.add_argument('--settings', default='default,dt/2')
    args = parse_args(parser, SMALL)
    seeds = [int(s) for s in args.seeds.split(',')]
    jobs = [(name, args.file, seeds, args.parts, args.moves, args.every)
            for name in args.settings.split(',')]
    print(f'{args.parts} parts of {args.file}.yaml dropped on the tray, then {args.moves} '
          f'default moves, seeds {seeds}', flush=True)
    with multiprocessing.Pool(min(len(jobs), os.cpu_count() or 1)) as pool:
        for lines in pool.imap(run, jobs):
            print('\n'.join(lines), flush=True)


if __name__ == '__main__':
    main()
