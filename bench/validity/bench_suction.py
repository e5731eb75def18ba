"""Suction benchmark: a suction cup's staged check against the jaws' on the same settled scene.

    tools/ws python -m bench.validity.bench_suction [--parts 200] [--repeats 20]

A bin of DIP-8s (the built-in `dip`, 100 x 100 x 30 mm) settles in the real world core; then
the four-stage check runs `--repeats` times with parallel jaws (the DIP's top and bottom
across its width, its ends across its length: 19 wrist tilts each) and with a 4 mm suction
cup (its top, bottom and end: one approach each), on the same poses, alternating, one core.
Prints the median time per part of each, their ratio (target: the cup's no more than the
jaws'), the build times (the cup's seals and holding computed once per grasp), and how many
parts each found valid and at which stage the rest stopped. Each check is also compared with
the naive all-FCL loop once: the per-part results must be identical.
"""

import argparse
import collections
import os
import statistics
import time

from pick_common.containers import ContainerSpec
from pick_common.parts.spec import PartSpec
from pick_common.specs import SceneSpec
from pick_sim_world.world import World
from pick_validity.config import PlaceSpec, Setup
from pick_validity.grasps import GraspPose, SuctionGrasp
from pick_validity.grippers import SuctionCup
from pick_validity.naive import naive_check
from pick_validity.results import (
    STAGE_CANDIDACY,
    STAGE_CONTAINER,
    STAGE_NEIGHBOUR,
    STAGE_OUTSIDE,
    STAGE_PLACEABILITY,
    STAGE_VALID,
)
from pick_validity.validity import Validator

BIN = ContainerSpec(inner_size=(0.1, 0.1, 0.03))
SPEC = PartSpec(model='dip')
PLACE = PlaceSpec(seat_offset=0.0015)
JAWS = (GraspPose('top', (0, 0, 1), (0, 1, 0), 0.0135),
        GraspPose('bottom', (0, 0, -1), (0, 1, 0), 0.0135),
        GraspPose('end', (1, 0, 0), (0, 1, 0), 0.0135))
CUP = (SuctionGrasp('top', (0, 0, 1), (0, 0, 0.00165)),
       SuctionGrasp('bottom', (0, 0, -1), (0, 0, -0.00165)),
       SuctionGrasp('end', (1, 0, 0), (0.0047, 0, 0)))
STAGES = {STAGE_OUTSIDE: 'outside', STAGE_CANDIDACY: 'candidacy',
          STAGE_PLACEABILITY: 'placeability', STAGE_CONTAINER: 'container',
          STAGE_NEIGHBOUR: 'neighbour', STAGE_VALID: 'valid'}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--parts', type=int, default=200)
    parser.add_argument('--repeats', type=int, default=20)
    parser.add_argument('--seed', type=int, default=7)
    args = parser.parse_args()
    os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})
    with World(SceneSpec(BIN, SPEC, seed=args.seed)) as world:
        world.drop(args.parts)
        state = world.snapshot()
        part = world.part
    print(f'pinned to one core; {args.parts} DIP-8s settled in a 100 x 100 x 30 mm bin '
          f'(seed {args.seed}), {args.repeats} checks each')
    validators = {}
    for name, setup in (('jaws', Setup(SPEC, grasps=JAWS, place=PLACE)),
                        ('suction', Setup(SPEC, gripper=SuctionCup(), grasps=CUP,
                                          place=PLACE))):
        start = time.perf_counter()
        validators[name] = Validator(setup, part)
        print(f'{name:<8} validator built in {(time.perf_counter() - start) * 1e3:.1f} ms')
    walls = {name: [] for name in validators}
    reports = {}
    for _ in range(args.repeats):              # alternating: the same load on both
        for name, v in validators.items():
            reports[name] = v.check(BIN, state.ids, state.poses)
            walls[name].append(reports[name].wall_time)
    per_part = {}
    for name, v in validators.items():
        naive = naive_check(v.geometry, BIN, state.ids, state.poses)
        same = [a.key() for a in reports[name].results] == [b.key() for b in naive.results]
        per_part[name] = statistics.median(walls[name]) / len(state.ids)
        stages = collections.Counter(STAGES[r.stage] for r in reports[name].results)
        print(f'{name:<8} {per_part[name] * 1e6:8.1f} us per part (median of {args.repeats}; '
              f'min {min(walls[name]) * 1e3:.1f} ms, max {max(walls[name]) * 1e3:.1f} ms a '
              f'check), {reports[name].queries} FCL queries; identical to the naive loop: '
              f'{same}; stages {dict(stages)}')
        assert same, "the fast check must give the naive loop's results"
    print(f'suction / jaws, time per part: {per_part["suction"] / per_part["jaws"]:.2f} '
          '(target at most 1)')


if __name__ == '__main__':
    main()
