"""Where does a coarse step change a bin's answer? Drops 480 TO-220s (PTH1's part; `--parts`)
into the test case's biggest bin, 300 x 300 x 26 mm, at several time steps and the same seeds,
checks them with the container stage (the D 8, W 3 mm gripper of studies/convergence.py), and
prints per step, with 95 % intervals over the seeds: the container-free fraction, the parts
that lean past every grasp's tolerance (they stop at candidacy), the parts whose jaws hit the
container, the share of the leaning ones that lie on other parts (centre more than 8 mm above
the floor), and the parts tilted by more than 10 deg.

    tools/ws python -m studies.lean [--seeds 12] [--steps 240,480,960,1920] [--parts 480]

Runs are spread over a process per CPU.
"""

import argparse
from dataclasses import replace
import math
import multiprocessing
import os
import statistics
import time

import numpy as np
from pick_common.specs import SceneSpec
from pick_common.states import rotate
from pick_common.stats import interval
from pick_sim_world.config import PhysicsConfig
from pick_sim_world.world import World
from pick_validity.results import STAGE_CANDIDACY, STAGE_CONTAINER, STAGE_NEIGHBOUR, STAGE_VALID
from pick_validity.validity import Validator

from studies.cases import parse_args, variant
from studies.convergence import GRIPPER

BIN_MM = [300, 300, 26]
ON_PARTS = 0.008        # m: a centre this far above the floor lies on other parts


def drop(args: tuple[int, int, int]) -> tuple[int, int, dict]:
    per_second, seed, parts = args
    file = variant('pth1.yaml', [{'id': 'bins', 'type': 'bin_static', 'iterations': 1,
                                  'parts': parts, 'bins_mm': [BIN_MM]}], gripper=GRIPPER)
    container = file.experiments[0].bins[0]
    physics = replace(PhysicsConfig(), time_step=1.0 / per_second)
    start = time.perf_counter()
    with World(SceneSpec(container, file.part, 1, seed), physics) as world:
        world.drop(parts)
        states = world.snapshot()
        validator = Validator(file.setup, world.part)
        targets = states.ids[states.inside].tolist()
        report = validator.check(container, states.ids.tolist(), states.poses, targets, False)
        centre = world.part.center
    row = {int(i): k for k, i in enumerate(states.ids)}
    poses = states.poses[[row[r.part_id] for r in report.results]]
    stage = np.array([r.stage for r in report.results])
    angle = np.array([r.candidacy_angle for r in report.results])
    height = poses[:, 2] + rotate(poses[:, 3:], centre)[:, 2]
    leaning = stage == STAGE_CANDIDACY
    return per_second, seed, {
        'container-free': float(np.isin(stage, (STAGE_NEIGHBOUR, STAGE_VALID)).mean()),
        'leaning past tolerance': float(leaning.mean()),
        'jaws hit the container': float((stage == STAGE_CONTAINER).mean()),
        'leaning ones on parts': float((height[leaning] > ON_PARTS).mean()
                                       if leaning.any() else math.nan),
        'tilted > 10 deg': float((np.degrees(angle) > 10.0).mean()),
        'wall (s)': time.perf_counter() - start}


# the size of its smoke test (tests/test_studies.py): `--small`
SMALL = ['--seeds', '1', '--steps', '480', '--parts', '60']


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--seeds', type=int, default=12)
    parser.add_argument('--steps', default='240,480,960,1920', help='steps per second')
    parser.add_argument('--parts', type=int, default=480)
    args = parse_args(parser, SMALL)
    steps = [int(s) for s in args.steps.split(',')]
    start = time.perf_counter()
    with multiprocessing.Pool(os.cpu_count() or 1) as pool:
        results = pool.map(drop, [(s, k, args.parts) for s in steps for k in range(args.seeds)],
                           chunksize=1)
    print(f'{len(results)} drops, {(time.perf_counter() - start) / 60:.1f} min wall on '
          f'{os.cpu_count()} CPUs; {args.parts} TO-220s into {" x ".join(map(str, BIN_MM))} mm')
    columns = list(results[0][2])
    print('| step | ' + ' | '.join(columns) + ' |')
    print('| --- |' + ' --- |' * len(columns))
    for s in steps:
        cells = []
        for c in columns:
            values = [r[2][c] for r in results if r[0] == s and not math.isnan(r[2][c])]
            if not values:          # e.g. no part leaned, so none leaned on others
                cells.append('-')
                continue
            low, high = interval(values)
            half = 0.0 if low is None else (high - low) / 2
            cells.append(f'{statistics.fmean(values):.4g} +- {half:.2g}')
        print(f'| 1/{s} s | ' + ' | '.join(cells) + ' |')


if __name__ == '__main__':
    main()
