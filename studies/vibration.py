"""Which vibration serves a feeder: does it scatter a fed pile, and does it empty the feeder?

Scatter: for each profile, feed 55 capacitors into the feeder zone of the 195 x 150 x 27 mm
tray, then vibrate 10 times; after each vibration, check every part (all four stages, the
default gripper) and measure how far the parts spread along the tray (standard deviation of x).
Prints the median valid parts per check and the spread after the last vibration, over seeds.

Feeder: for each part (the test case's capacitor PTH0 and TO-220 PTH1, with their grasps),
range and profile, `feeder_emptying` runs of 100 parts with a limit of 300 vibrations, through
the experiment runner on the cores: runs emptied, vibrations to the last pick, parts spilled over
the edge. The ranges are the policy's default [20, 30], a fuller table, [50, 60], and [70, 80],
the top of the ranges our sweeps give (PTH0's); none is a result of the paper. The runs are
spread over a process per CPU.

    tools/ws python -m studies.vibration [--seeds 4] [--feeder-seeds 3]
"""

import argparse
import itertools
import multiprocessing
import os
import statistics
import time

from pick_common.containers import ContainerSpec
from pick_common.specs import FIXED, MOVES, RANDOM, SceneSpec, Vibration
from pick_sim_world.world import World
from pick_validity.config import Setup
from pick_validity.validity import Validator

from studies.cases import parse_args, run_on_cores

PROFILES = {
    'x + z in phase, 1 x 0.5 x 1 mm, 30 Hz, 1 s (fixed)':
        Vibration((0.001, 0.0005, 0.001), 30.0, 1.0, FIXED),
    'vertical 3 mm, 30 Hz, 0.5 s (the former default)':
        Vibration((0.0, 0.0, 0.003), 30.0, 0.5, FIXED),
    'vertical 1 mm, 30 Hz, 1 s': Vibration((0.0, 0.0, 0.001), 30.0, 1.0, FIXED),
    'vertical 3 mm + 3 mm horizontal, 30 Hz, random direction (the former default)':
        Vibration((0.003, 0.0, 0.003), 30.0, 0.5, RANDOM),
    'vertical 1.4 mm + 1.4 mm horizontal, 26 Hz, random direction (spread, a former default)':
        MOVES['spread'],
}
FEEDER_PROFILES = {
    'vertical 3 mm (the former default)': Vibration((0.0, 0.0, 0.003), 30.0, 0.5, FIXED),
    'vertical 3 mm + 1 mm horizontal, random direction':
        Vibration((0.001, 0.0, 0.003), 30.0, 0.5, RANDOM),
    'vertical 3 mm + 3 mm horizontal, random direction (the former default)':
        Vibration((0.003, 0.0, 0.003), 30.0, 0.5, RANDOM),
    'vertical 1.4 mm + 1.4 mm horizontal, 26 Hz, random direction (spread, a former default)':
        MOVES['spread'],
    'vertical 1.5 mm + 3 mm horizontal, random direction':
        Vibration((0.003, 0.0, 0.0015), 30.0, 0.5, RANDOM),
}
FEEDER_PARTS = {'PTH0 (capacitor 5 x 11 mm)': 'pth0.yaml', 'PTH1 (TO-220)': 'pth1.yaml'}
FEEDER_RANGES = ((20, 30), (50, 60), (70, 80))


def run(vibration: Vibration, seed: int, count: int = 55, shakes: int = 10) -> dict:
    with World(SceneSpec(ContainerSpec.tray(), seed=seed)) as world:
        validator = Validator(Setup(), world.part)
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


def feeder_runs(part_file: str, vibration: Vibration, runs: int,
                optimal_range: tuple[int, int]) -> list[dict]:
    """`runs` feeder_emptying iterations of 100 parts in `optimal_range`, on the cores."""
    vibration_section = {'amplitude_mm': [a * 1000 for a in vibration.amplitude],
                         'frequency_hz': vibration.frequency,
                         'duration_s': vibration.duration, 'direction': vibration.direction}
    rows, _ = run_on_cores(part_file, [{'id': 'feeder', 'type': 'feeder_emptying',
                                        'iterations': runs, 'parts': 100,
                                        'optimal_range': list(optimal_range),
                                        'max_vibrations': 300}],
                           moves=[vibration_section])
    return rows

# the size of its smoke test (tests/test_studies.py): `--small`
SMALL = ['--seeds', '1', '--feeder-seeds', '1', '--cases', '1', '--profiles', '1']


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--seeds', type=int, default=4)
    parser.add_argument('--feeder-seeds', type=int, default=3)
    parser.add_argument('--cases', type=int, help='only the first N feeder cases (part, range, '
                        'profile); default: all')
    parser.add_argument('--profiles', type=int, help='only the first N scatter profiles; '
                        'default: all')
    args = parse_args(parser, SMALL)
    print(f'feeder_emptying: 100 parts, limit 300 vibrations, {args.feeder_seeds} runs each')
    cases = [(part, optimal_range, name) for part, optimal_range, name in itertools.product(
        FEEDER_PARTS, FEEDER_RANGES, FEEDER_PROFILES)][:args.cases]
    with multiprocessing.Pool(os.cpu_count()) as pool:
        results = pool.starmap(feeder_runs, [
            (FEEDER_PARTS[part], FEEDER_PROFILES[name], args.feeder_seeds, optimal_range)
            for part, optimal_range, name in cases])
    for (part, (low, high), name), rows in zip(cases, results, strict=True):
        emptied = sum(r['emptied'] for r in rows)
        vibrations = [r['vibrations'] for r in rows]
        wall = sum(r['wall_time'] for r in rows)
        print(f'{part:<27} [{low}, {high}] {name:<66} emptied {emptied}/{len(rows)}; '
              f'vibrations {"/".join(map(str, vibrations))}; picked '
              f'{"/".join(str(r["picks"]) for r in rows)}; spilled '
              f'{sum(r["spilled"] for r in rows)}; {wall / max(1, sum(vibrations)):.2f} s '
              'per vibration (picks included)', flush=True)
    print()
    print(f'55 capacitors fed into the feeder zone, 10 vibrations, seeds 1..{args.seeds}')
    for name, vibration in list(PROFILES.items())[:args.profiles]:
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
