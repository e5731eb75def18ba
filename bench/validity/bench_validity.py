"""Validity benchmark: the staged check of a settled 480-part bin against the naive loop.

    tools/ws python -m bench.validity.bench_validity [--seeds 2] [--repeats 20]

For each seed, 480 radial capacitors settle in a 300 x 300 x 26 mm bin (the real world core);
then the full four-stage check (and the three-stage static analysis) runs `--repeats` times and
the naive loop (every part, every tilt, every other part, FCL for everything, no broadphase, no
caching) once, on the same scene. Per-part results must be identical. Pinned to one core.
"""

import argparse
import os
import statistics
import time

from pick_common.containers import ContainerSpec
from pick_common.specs import SceneSpec
from pick_sim_world.world import World
from pick_validity.config import CAPACITOR_GRASPS, Setup
from pick_validity.grippers import Jaws
from pick_validity.naive import naive_check
from pick_validity.validity import Validator

BIN = ContainerSpec(inner_size=(0.3, 0.3, 0.026))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--seeds', type=int, default=2)
    parser.add_argument('--repeats', type=int, default=20)
    args = parser.parse_args()
    os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})
    print(f'pinned to core {sorted(os.sched_getaffinity(0))}; grasps '
          f'{[g.name for g in CAPACITOR_GRASPS]}, {Jaws()}, tilts -45..45 deg by 5')
    for seed in range(args.seeds):
        with World(SceneSpec(BIN, seed=seed)) as world:
            world.drop(480)
            state = world.snapshot()
            part = world.part
        start = time.perf_counter()
        validator = Validator(Setup(), part)
        build = time.perf_counter() - start
        print(f'\n== seed {seed}: 480 settled capacitors; validator built in {build * 1e3:.1f} ms '
              "(part and gripper geometry, each grasp's finger depth)")
        for neighbours in (True, False):
            label = 'four stages' if neighbours else 'stages 1-3 (static bin analysis)'
            walls = []
            for _ in range(args.repeats):
                fast = validator.check(BIN, state.ids, state.poses, neighbour_check=neighbours)
                walls.append(fast.wall_time)
            naive = naive_check(validator.geometry, BIN, state.ids, state.poses,
                                neighbour_check=neighbours)
            same = [a.key() for a in fast.results] == [b.key() for b in naive.results]
            median = statistics.median(walls)
            print(f'{label:<34} fast {median * 1e3:7.1f} ms (min {min(walls) * 1e3:.1f}, max '
                  f'{max(walls) * 1e3:.1f}) {fast.queries:>7} FCL queries | naive '
                  f'{naive.wall_time * 1e3:8.0f} ms {naive.queries:>8} queries | '
                  f'x{naive.wall_time / median:.0f} faster | identical: {same}')
            print(f'{"":<34} {fast.counts}')
            assert same, "the fast check must give the naive loop's results"
            if neighbours:
                print(f'{"":<34} target <= 50 ms: '
                      f'{"met" if median <= 0.050 else "NOT met"}')


if __name__ == '__main__':
    main()
