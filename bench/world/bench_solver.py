"""What the solver's iterations buy in the test case's slowest drop.

480 TO-220s (PTH1) into its 200 x 75 x 158 mm bin never settle within the 10 s cap: every one
of the full test case's 40 drops there hit it (57.7 s at the median). For a few solver
iteration counts, drops the same parts (same seed) with the default settle criterion and
prints the wall time, the time per step and the parts still moving at the end: whether fewer
iterations would make the full case cheaper, or more would let the pile settle.

    tools/ws python -m bench.world.bench_solver [--iterations 10 30 80] [--seed 0]
"""

import argparse
import os
import time

from experiment_manager.experiment_file import load
from pick_common.specs import SceneSpec
from pick_sim_world.config import PhysicsConfig
from pick_sim_world.world import World

from bench.paper_case import TEST_CASE


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--iterations', type=int, nargs='+', default=[10, 30, 80])
    parser.add_argument('--seed', type=int, default=0)
    args = parser.parse_args()
    file = load(os.path.join(TEST_CASE, 'pth1.yaml'))
    exp = next(e for e in file.experiments if e.type == 'bin_static')
    container = exp.bins[0]
    size = ' x '.join(f'{v * 1000:g}' for v in container.inner_size)
    print(f'{exp.parts} TO-220s into the {size} mm bin, seed {args.seed}, settle cap '
          f'{PhysicsConfig().max_settle_time:g} s')
    for iterations in args.iterations:
        physics = PhysicsConfig(solver_iterations=iterations)
        with World(SceneSpec(container, file.part, 1, args.seed), physics) as world:
            start = time.perf_counter()
            _, report = world.drop(exp.parts)
            wall = time.perf_counter() - start
        print(f'  solver iterations {iterations:3d}: wall {wall:6.1f} s, '
              f'{1000 * wall / report.steps:5.1f} ms/step, settled {report.settled}, '
              f'simulated {report.sim_time:5.2f} s, {len(report.unsettled_ids)} parts moving '
              f'at the end, {len(report.escaped_ids)} escaped', flush=True)


if __name__ == '__main__':
    main()
