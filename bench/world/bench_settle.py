"""What does waiting for every part to rest cost, and what would stopping earlier change?

For each part of the paper's test case, drop its bin_static parts into three of its bins (the
first, middle and last) with the strict settle criterion (every part at rest, or the 10 s cap),
and note the moments at which other criteria would have ended the drop: at most 1 % or 2 % of
the parts still moving (`settle.moving_fraction`), or a cap of 3 s or 5 s of simulated time.
At each such moment the pile is checked (candidacy + placeability + container, as bin_static
does, and all four stages): a criterion is as good as the strict one when its checks give the
same counts. One simulation per bin and seed (the same seed gives the same trajectory, so the
moments are those of separate runs), the checks' own time taken out of the wall times.

    tools/ws python -m bench.world.bench_settle [--seeds 2]
"""

import argparse
import os
import statistics
import time

from experiment_manager.experiment_file import load
from pick_common.specs import SceneSpec
from pick_sim_world.config import PhysicsConfig
from pick_sim_world.world import World
from pick_validity.validity import Validator

from bench.paper_case import TEST_CASE

FRACTIONS = (0.01, 0.02)
CAPS = (3.0, 5.0)


def drop(file, container, count: int, seed: int) -> dict:
    """{criterion: (wall s, sim s, valid without neighbours, valid with)} for one drop."""
    with World(SceneSpec(container, file.part, 1, seed), PhysicsConfig()) as world:
        validator = Validator(file.setup, world.part)
        spent = 0.0
        out: dict[str, tuple] = {}
        start = time.perf_counter()

        def check(name: str, sim: float) -> None:
            nonlocal spent
            t = time.perf_counter()
            physics_wall = t - start - spent
            s = world.snapshot()
            alone = validator.check(container, s.ids.tolist(), s.poses, None, False).counts
            full = validator.check(container, s.ids.tolist(), s.poses, None, True).counts
            spent += time.perf_counter() - t
            out[name] = (physics_wall, sim, alone['valid'], full['valid'])

        def progress(p) -> bool:
            window_full = p.sim_time >= world.physics.settle_window + 1e-9
            for f in FRACTIONS:
                name = f'moving <= {f:.0%}'
                if name not in out and window_full and p.parts_moving <= int(f * count):
                    check(name, p.sim_time)
            for cap in CAPS:
                name = f'cap {cap:g} s'
                if name not in out and p.sim_time >= cap - 1e-9:
                    check(name, p.sim_time)
            return True

        _, report = world.drop(count, progress=progress)
        wall = time.perf_counter() - start - spent
        s = world.snapshot()
        alone = validator.check(container, s.ids.tolist(), s.poses, None, False).counts
        full = validator.check(container, s.ids.tolist(), s.poses, None, True).counts
        out['strict'] = (wall, report.sim_time, alone['valid'], full['valid'])
        criteria = [f'moving <= {f:.0%}' for f in FRACTIONS] + [f'cap {c:g} s' for c in CAPS]
        return {name: out.get(name, out['strict']) for name in ['strict', *criteria]}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--seeds', type=int, default=2)
    args = parser.parse_args()
    print(f'seeds 1..{args.seeds}. Per criterion: median wall s (and its ratio to strict), '
          'median simulated s, then per seed: parts valid without neighbours / with neighbours')
    totals: dict[str, float] = {}
    changes: dict[str, list[float]] = {}
    for name in ('pth0', 'pth1', 'pth2'):
        file = load(os.path.join(TEST_CASE, f'{name}.yaml'))
        exp = next(e for e in file.experiments if e.type == 'bin_static')
        for container in (exp.bins[0], exp.bins[len(exp.bins) // 2], exp.bins[-1]):
            size = ' x '.join(f'{v * 1000:g}' for v in container.inner_size)
            print(f'{name}: {exp.parts} parts in {size} mm', flush=True)
            runs = [drop(file, container, exp.parts, seed) for seed in range(1, args.seeds + 1)]
            strict = statistics.median(r['strict'][0] for r in runs)
            for criterion in runs[0]:
                wall = statistics.median(r[criterion][0] for r in runs)
                totals[criterion] = totals.get(criterion, 0.0) + sum(r[criterion][0]
                                                                     for r in runs)
                for r in runs:
                    base = r['strict'][2]
                    changes.setdefault(criterion, []).append(
                        abs(r[criterion][2] - base) / max(base, 1))
                print(f'  {criterion:<14} wall {wall:6.1f} s ({wall / strict:4.2f})  sim '
                      f'{statistics.median(r[criterion][1] for r in runs):5.2f} s  valid '
                      + '  '.join(f'{r[criterion][2]}/{r[criterion][3]}' for r in runs),
                      flush=True)
    print('all drops: wall time against strict, and the median / largest relative change of '
          'the parts valid without neighbours')
    for criterion, total in totals.items():
        c = changes[criterion]
        print(f'  {criterion:<14} {total:7.1f} s ({total / totals["strict"]:4.2f})  change '
              f'{statistics.median(c):.1%} / {max(c):.1%}')


if __name__ == '__main__':
    main()
