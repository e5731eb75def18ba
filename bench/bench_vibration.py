"""Does a vibration scatter the parts a feed dropped in the tray's feeder zone?

For each profile: feed 55 capacitors into the feeder zone of the 195 x 150 x 27 mm tray, then
vibrate 10 times; after each vibration, check every part (all four stages, the default gripper)
and measure how far the parts spread along the tray (standard deviation of x). Prints the
median valid parts per check and the spread after the last vibration, per profile, over seeds.

    tools/ws python bench/bench_vibration.py [--seeds 4]
"""

import argparse
import statistics
import time

from pick_sim_world.config import SceneSpec, Vibration
from pick_sim_world.containers import ContainerSpec
from pick_sim_world.world import World
from pick_validity.config import CAPACITOR_GRASPS, CheckConfig, Gripper, PlaceSpec
from pick_validity.validity import Validator

PROFILES = {
    'x + z in phase, 1 x 0.5 x 1 mm, 30 Hz, 1 s (the former default)':
        Vibration((0.001, 0.0005, 0.001), 30.0, 1.0),
    'vertical 3 mm, 30 Hz, 0.5 s (the default)': Vibration(),
    'vertical 1 mm, 30 Hz, 1 s': Vibration((0.0, 0.0, 0.001), 30.0, 1.0),
}


def run(vibration: Vibration, seed: int, count: int = 55, shakes: int = 10) -> dict:
    with World(SceneSpec(ContainerSpec.tray(), seed=seed)) as world:
        validator = Validator(world.part, Gripper(), CAPACITOR_GRASPS, PlaceSpec(),
                              CheckConfig())
        world.drop(count, zone='feeder')
        start = world.snapshot().poses[:, 0].std()
        valid, wall = [], 0.0
        for _ in range(shakes):
            t = time.perf_counter()
            world.vibrate(vibration)
            wall += time.perf_counter() - t
            s = world.snapshot()
            report = validator.check(world.scene.container, s.ids.tolist(), s.poses, None, True)
            valid.append(report.counts['valid'])
        s = world.snapshot()
        return {'valid': valid, 'spread0': start, 'spread': s.poses[:, 0].std(),
                'escaped': int((~s.inside).sum()), 'wall': wall / shakes}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--seeds', type=int, default=4)
    args = parser.parse_args()
    print(f'55 capacitors fed into the feeder zone, 10 vibrations, seeds 1..{args.seeds}')
    for name, vibration in PROFILES.items():
        runs = [run(vibration, seed) for seed in range(1, args.seeds + 1)]
        valid = [v for r in runs for v in r['valid']]
        print(f'{name:<66} valid per check: median {statistics.median(valid):4.1f}, '
              f'zero in {sum(v == 0 for v in valid)}/{len(valid)}; x spread '
              f'{statistics.median(r["spread0"] for r in runs) * 1000:4.1f} -> '
              f'{statistics.median(r["spread"] for r in runs) * 1000:4.1f} mm; escaped '
              f'{sum(r["escaped"] for r in runs)}; {statistics.median(r["wall"] for r in runs):.2f}'
              ' s per vibration')


if __name__ == '__main__':
    main()
