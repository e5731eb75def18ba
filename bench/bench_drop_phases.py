"""Where a bin's drop spends its time: the stream of spawn layers against the settle that ends
it, and how many parts the freezer holds while the parts stream in.

One drop per bin on the cores (World.drop, the world's defaults), one process: per phase the
steps, the wall time and the wall time per step; and at every fourth rest check of the stream
the parts in the bin, those frozen and those that moved more than the settle tolerance since
the last check (the parts a landing layer keeps awake).

    tools/ws python bench/bench_drop_phases.py [--file pth1.yaml] [--parts 480] [--seed 0]
        [--bins 200x75x158,300x150x53,300x300x26]
"""

import argparse
import time

from paper_case import variant
from pick_common.containers import ContainerSpec
from pick_common.specs import SceneSpec
from pick_sim_world import freezing
from pick_sim_world import world as world_module

# The world's own methods, before main wraps them.
RUN, CHECK = world_module.World._run, freezing.Freezer.check
SWEEP = [{'id': 'sweep', 'type': 'table_sweep', 'iterations': 1,
          'counts': {'first': 1, 'last': 1, 'step': 1}}]     # the file's part is what is used


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--file', default='pth1.yaml', help='a test-case file: its part')
    parser.add_argument('--parts', type=int, default=480)
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--bins', default='200x75x158,300x150x53,300x300x26',
                        help='inner sizes in mm, comma-separated')
    args = parser.parse_args()
    part = variant(args.file, SWEEP).part
    phases: dict[str, list[float]] = {}
    checks: list[tuple[int, int, int]] = []
    streaming = [False]

    def run(self, phase, duration, progress, stop_when_settled=True, **kwargs):
        streaming[0] = not stop_when_settled
        start = time.perf_counter()
        out = RUN(self, phase, duration, progress, stop_when_settled, **kwargs)
        totals = phases.setdefault('stream' if streaming[0] else 'settle', [0, 0.0])
        totals[0] += out.steps
        totals[1] += time.perf_counter() - start
        return out

    def check(self, bodies, poses, elapsed):
        if streaming[0] and elapsed > 0.0:
            moved, _ = self.movers(bodies, poses)
            checks.append((len(bodies), len(self.frozen), int(moved.sum())))
        CHECK(self, bodies, poses, elapsed)

    world_module.World._run, freezing.Freezer.check = run, check
    print(f'{args.parts} parts of {args.file}, seed {args.seed}, one process')
    for size in args.bins.split(','):
        inner = tuple(float(v) / 1000.0 for v in size.split('x'))
        phases.clear()
        checks.clear()
        scene = SceneSpec(ContainerSpec(inner_size=inner), part, 1, args.seed)
        with world_module.World(scene) as world:
            start = time.perf_counter()
            _, report = world.drop(args.parts)
            wall = time.perf_counter() - start
        print(f'\n{size} mm: {wall:.2f} s wall, {report.sim_time:.2f} s simulated, settled '
              f'{report.settled}, {len(report.unsettled_ids)} parts moving at the end')
        for name, (steps, seconds) in phases.items():
            print(f'  {name:<6} {steps:5d} steps {seconds:6.2f} s  '
                  f'{1000.0 * seconds / max(1, steps):5.2f} ms a step')
        print('  stream, every fourth check: parts / frozen / moved more than the tolerance')
        print('  ' + ', '.join(f'{n}/{f}/{m}' for n, f, m in checks[::4]))


if __name__ == '__main__':
    main()
