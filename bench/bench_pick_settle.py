"""What does skipping the settle after a pick of a part that touches no other part save, and
what does it change?

`World.remove` settles the scene after removing parts, unless the scene was at rest and no
removed part touched another part (by the last step's contacts, within the contact-breaking
threshold): lifting such a part out of a resting scene moves nothing. This script runs the
test case's feeder runs (100 parts, the optimal ranges the reduced test case found) and bin
emptyings (the test case's counts and best bins) on the cores, once as the world does now and
once with a settle after every removal (the behaviour before 2026-11-23), with the same seeds:
wall time, steps, removals that skipped the settle, and the outcomes (vibrations, picks, parts
spilled). The runs are spread over a process per CPU.

    tools/ws python bench/bench_pick_settle.py [--runs 4]
"""

import argparse
import collections
import multiprocessing
import os

from paper_case import run_on_cores
from pick_sim_world import world as world_module

# Per part: its file, the reduced test case's optimal range (2026-11-22) and best bin, mm.
PARTS = {'PTH0': ('pth0.yaml', (72, 82), (100, 175, 15)),
         'PTH1': ('pth1.yaml', (39, 49), (300, 300, 26)),
         'PTH2': ('pth2.yaml', (53, 63), (300, 225, 29))}
MODES = ('settle after every removal (before)', 'skip when nothing touched (now)')
# The world's own methods, before `measure` wraps them (a pool process runs one case only).
TOUCH, RUN = world_module.World._touch_other_parts, world_module.World._run


def experiments(kind: str, part: str, runs: int) -> list[dict]:
    _, optimal_range, best_bin = PARTS[part]
    if kind == 'feeder':
        return [{'id': 'feeder', 'type': 'feeder_emptying', 'iterations': runs, 'parts': 100,
                 'optimal_range': list(optimal_range), 'max_vibrations': 300}]
    parts = 240 if part == 'PTH0' else 480
    return [{'id': 'bins', 'type': 'bin_static', 'iterations': 1, 'parts': parts,
             'bins_mm': [list(best_bin)]},
            {'id': 'emptying', 'type': 'bin_emptying', 'iterations': runs, 'parts': parts,
             'bin': 'bins'}]


def measure(kind: str, part: str, mode: int, runs: int) -> dict:
    """Run `kind` (feeder | emptying) for `part` in `mode` (an index of MODES)."""
    counts = collections.Counter()

    def touch(self, ids):
        touched = True if mode == 0 else TOUCH(self, ids)
        counts['removals'] += 1
        counts['skipped'] += not touched and self._at_rest
        return touched

    world_module.World._touch_other_parts = touch
    steps = [0]

    def counted(self, *args, **kwargs):
        report = RUN(self, *args, **kwargs)
        steps[0] += report.steps
        return report

    world_module.World._run = counted
    rows, wall = run_on_cores(PARTS[part][0], experiments(kind, part, runs))
    rows = [r for r in rows if r['type'] != 'bin_static']
    return dict(wall=wall, steps=steps[0], rows=rows, **counts)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--runs', type=int, default=4, help='runs per part and kind')
    args = parser.parse_args()
    cases = [(kind, part, mode) for kind in ('feeder', 'emptying') for part in PARTS
             for mode in range(len(MODES))]
    # One case per process (the wrapped methods must not leak into the next case); the two
    # modes of a case run side by side.
    with multiprocessing.Pool(os.cpu_count(), maxtasksperchild=1) as pool:
        results = pool.starmap(measure, [(*case, args.runs) for case in cases], chunksize=1)
    by_case = dict(zip(cases, results, strict=True))
    print(f'{args.runs} runs per part and kind, the same seeds in both modes; wall time of the '
          'whole experiment (an emptying includes one bin_static drop)')
    for kind in ('feeder', 'emptying'):
        for part in PARTS:
            before, now = by_case[(kind, part, 0)], by_case[(kind, part, 1)]
            for mode, r in zip(MODES, (before, now), strict=True):
                outcome = '; '.join(
                    f'{x["vibrations"]} vib, {x["picks"]} picks, {x["spilled"]} spilled'
                    for x in r['rows'])
                print(f'{kind:<8} {part} {mode:<36} wall {r["wall"]:6.1f} s, steps '
                      f'{r["steps"]:6d}, removals {r["removals"]:4d} (settle skipped '
                      f'{r["skipped"]:4d}): {outcome}', flush=True)
            print(f'{kind:<8} {part} wall now / before: {now["wall"] / before["wall"]:.2f}, '
                  f'steps {now["steps"] / before["steps"]:.2f}')


if __name__ == '__main__':
    main()
