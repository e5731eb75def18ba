"""What does settling only what a pick disturbs save, and what does it change?

`World.remove` settles the scene after removing parts, unless the scene was at rest and no
removed part touched another part (by the last step's contacts, within the contact-breaking
threshold): lifting such a part out of a resting scene moves nothing. From a scene at rest, the
settle starts with only the parts the removed ones touched awake, the rest frozen until a
moving part comes near (freezing.py). This script runs the test case's feeder runs (100
parts, the optimal ranges the reduced test case found) and bin emptyings (the test case's
counts and best bins) on the cores in three modes, with the same seeds: a settle after every
removal with every part awake (the behaviour before 2026-11-23), the parts within a part's
length of a removed one awake (2026-11-23 to 2026-11-26), and the world's own (the parts
touched). It prints wall time, steps, removals that skipped the settle, and the outcomes
(vibrations, picks, parts spilled). The runs are spread over a process per CPU.

    tools/ws python bench/bench_pick_settle.py [--runs 4]
"""

import argparse
import collections
import multiprocessing
import os

from paper_case import run_on_cores
from pick_sim_world import bodies
from pick_sim_world import world as world_module

# Per part: its file, the reduced test case's optimal range (2026-11-22) and best bin, mm.
PARTS = {'PTH0': ('pth0.yaml', (72, 82), (100, 175, 15)),
         'PTH1': ('pth1.yaml', (39, 49), (300, 300, 26)),
         'PTH2': ('pth2.yaml', (53, 63), (300, 225, 29))}
MODES = ('every removal, every part', 'touched, parts within a length', 'touched, parts touched')
# The world's own methods, before `measure` wraps them (a pool process runs one case only).
TOUCHING, RUN = world_module.World._parts_touching, world_module.World._run


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

    def touching(self, ids):
        found = TOUCHING(self, ids)
        if mode == 0:
            found = set(self._bodies) - set(ids)
        elif mode == 1 and found:
            part_of = {body: pid for pid, body in self._bodies.items()}
            for pid in ids:
                found.update(part_of[b] for b in bodies.bodies_near(
                    self._client, self._bodies[pid], 2.0 * self._part.radius) if b in part_of)
            found -= set(ids)
        counts['removals'] += 1
        counts['skipped'] += not found and self._at_rest
        return found

    world_module.World._parts_touching = touching
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
            results = [by_case[(kind, part, mode)] for mode in range(len(MODES))]
            for mode, r in zip(MODES, results, strict=True):
                outcome = '; '.join(
                    f'{x["vibrations"]} vib, {x["picks"]} picks, {x["spilled"]} spilled'
                    for x in r['rows'])
                print(f'{kind:<8} {part} {mode:<30} wall {r["wall"]:6.1f} s, steps '
                      f'{r["steps"]:6d}, removals {r["removals"]:4d} (settle skipped '
                      f'{r["skipped"]:4d}): {outcome}', flush=True)
            now = results[-1]
            print(f'{kind:<8} {part} wall now / each mode: ' + ', '.join(
                f'{now["wall"] / r["wall"]:.2f}' for r in results) + '; steps: ' + ', '.join(
                f'{now["steps"] / r["steps"]:.2f}' for r in results))


if __name__ == '__main__':
    main()
