"""How honest the progress line's ETA is, replayed on a finished run.

  tools/ws python -m bench.experiment.bench_eta RUN_DIR [--workers 2]

The run's iterations (iterations.csv, in plan order, with the wall time each took) are handed
to `--workers` workers in turn, each to the first free one, as the scheduler does (waits for an
experiment's inputs are not replayed). After each iteration finishes, the time left is
estimated from the iterations finished so far, by today's estimate (running/estimate.py:
measured seconds per part per type, scaled by the run's own) and by the one before it (a
feeder run's part weighed as 200 of any other type's, nothing said before an iteration had
finished), beside the time that was truly left. Printed at the iterations nearest 5, 10, 25,
50, 75 and 90 % of the run.
"""

import argparse
import heapq
import os
import sys

from experiment_manager import experiment_file
from experiment_manager.analysis.results import read_csv
from experiment_manager.experiment_file import FEEDER_EMPTYING
from experiment_manager.running.estimate import Costs, mean_units, units


def before(done: dict, left: list, workers: int) -> float:
    """The earlier estimate: seconds per weighed part of the experiment, its type or
    all (a feeder run's part weighing 200), 0 (unknown) before anything finished."""
    weight = {FEEDER_EMPTYING: 200.0}
    total = 0.0
    for exp, n in left:
        if not n:
            continue
        rate = None
        for chosen in ([v for k, v in done.items() if k == exp.id],
                       [v for v in done.values() if v[0].type == exp.type],
                       list(done.values())):
            u = sum(v[2] * weight.get(v[0].type, 1.0) for v in chosen)
            if u > 0:
                rate = sum(v[1] for v in chosen) / u
                break
        if rate is None:
            return 0.0
        total += n * rate * mean_units(exp) * weight.get(exp.type, 1.0)
    return total / workers


def replay(run_dir: str, workers: int) -> None:
    file = experiment_file.load(os.path.join(run_dir, 'experiment.yaml'))
    exps = {e.id: e for e in file.experiments}
    rows = read_csv(os.path.join(run_dir, 'iterations.csv'))
    free = [(0.0, k) for k in range(workers)]
    finished = []
    for r in rows:
        start, k = heapq.heappop(free)
        end = start + r['wall_time']
        heapq.heappush(free, (end, k))
        finished.append((end, r))
    finished.sort(key=lambda f: f[0])
    makespan = finished[-1][0]
    costs, done = Costs(), {}
    left = {e.id: sum(r['experiment'] == e.id for r in rows) for e in file.experiments}
    marks = [0.05, 0.10, 0.25, 0.50, 0.75, 0.90]
    print(f'{os.path.basename(run_dir.rstrip("/"))}: {len(rows)} iterations, '
          f'{makespan / 60:.1f} min on {workers} workers (replayed)')
    print('  at     | truly left | estimate today | before')
    said = {'start': Costs().left([(exps[k], n) for k, n in left.items()], workers)}
    print(f'  start  | {makespan / 60:7.1f} min | {said["start"] / 60:9.1f} min | unknown')
    for end, r in finished:
        exp = exps[r['experiment']]
        costs.add(exp, r['parts'], r['wall_time'])
        _, s, u = done.get(exp.id, (exp, 0.0, 0.0))
        done[exp.id] = (exp, s + r['wall_time'], u + units(exp, r['parts']))
        left[exp.id] -= 1
        while marks and end >= marks[0] * makespan:
            todo = [(exps[k], n) for k, n in left.items()]
            today, old = costs.left(todo, workers), before(done, todo, workers)
            print(f'  {end / 60:4.1f} m | {(makespan - end) / 60:7.1f} min | '
                  f'{today / 60:9.1f} min | {old / 60:.1f} min' if old else
                  f'  {end / 60:4.1f} m | {(makespan - end) / 60:7.1f} min | '
                  f'{today / 60:9.1f} min | unknown')
            marks.pop(0)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('run_dirs', nargs='+')
    parser.add_argument('--workers', type=int, default=2)
    args = parser.parse_args(argv)
    for run_dir in args.run_dirs:
        replay(run_dir, args.workers)
    return 0


if __name__ == '__main__':
    sys.exit(main())
