"""Do feeds tunnel? Seeded feeds of each test-case part onto its tray's feeder zone, each of
the largest load of the part's optimal range (the feeder's first feed, onto an empty tray, is
its biggest), at the world's default physics; counts the parts that ended in or under the
floor or a wall (tunnelled), over a wall (spilled), the deepest penetration and the lowest
part origin above the floor's top.

    tools/ws python -m studies.feeds [--feeds 50] [--loads pth0=90,pth1=55,pth2=54]

The default loads are the upper ends of the optimal ranges the reduced test case found with
the earlier physics (n* 85, 50, 49, margin 5: docs/paper-test-case.md). Feeds are
spread over a process per CPU; seed k of a part is the same feed at every call.
"""

import argparse
import multiprocessing
import os
import time

from experiment_manager.experiment_file import load
from pick_common.specs import SceneSpec
from pick_sim_world.config import PhysicsConfig
from pick_sim_world.world import World

from studies.cases import parse_args, TEST_CASE


def feed(args: tuple[str, int, int]) -> tuple[str, int, int, int, float, float, float]:
    name, load_, seed = args
    file = load(os.path.join(TEST_CASE, f'{name}.yaml'))
    start = time.perf_counter()
    with World(SceneSpec(file.tray, file.part, 1, seed), PhysicsConfig()) as world:
        _, report = world.drop(load_, zone='feeder')
        lowest = float(world.snapshot().poses[:, 2].min())
    return (name, seed, len(report.tunnelled_ids), len(report.spilled_ids),
            1000.0 * report.max_penetration, 1000.0 * lowest, time.perf_counter() - start)


# the size of its smoke test (tests/test_studies.py): `--small`
SMALL = ['--feeds', '1', '--loads', 'pth0=10']


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--feeds', type=int, default=50, help='seeded feeds per part')
    parser.add_argument('--loads', default='pth0=90,pth1=55,pth2=54',
                        help='part file = parts per feed, comma-separated')
    args = parse_args(parser, SMALL)
    loads = {k: int(v) for k, v in (item.split('=') for item in args.loads.split(','))}
    jobs = [(name, n, seed) for name, n in loads.items() for seed in range(args.feeds)]
    start = time.perf_counter()
    with multiprocessing.Pool(os.cpu_count() or 1) as pool:
        results = pool.map(feed, jobs, chunksize=1)
    print(f'{len(jobs)} feeds, {(time.perf_counter() - start) / 60:.1f} min wall on '
          f'{os.cpu_count()} CPUs')
    print('| part | parts per feed | feeds | tunnelled | feeds with a spill | spilled | '
          'deepest penetration (mm) | lowest origin above the floor (mm) | wall per feed (s) |')
    print('| --- | --- | --- | --- | --- | --- | --- | --- | --- |')
    for name, n in loads.items():
        rows = [r for r in results if r[0] == name]
        print(f'| {name} | {n} | {len(rows)} | {sum(r[2] for r in rows)} | '
              f'{sum(r[3] > 0 for r in rows)} | {sum(r[3] for r in rows)} | '
              f'{max(r[4] for r in rows):.2f} | {min(r[5] for r in rows):.2f} | '
              f'{sum(r[6] for r in rows) / len(rows):.1f} |')


if __name__ == '__main__':
    main()
