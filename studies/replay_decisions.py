"""How long each decision of a finished adaptive run takes with today's rules, replayed on its
recorded iterations: per part (run directory) and experiment, the iterations and worker-minutes
the looks of running/sampling.py would take, against what the run recorded, in the same
replay. Each look releases a batch per group still unsettled (a sweep's groups as
sampling.unsettled places them) and decides on the recorded rows released so far, as a run
does, until the decision is settled, the experiment's iterations are spent, or the record
runs out (said: the replay then stops short of what a run would take).

    tools/ws python -m studies.replay_decisions [--batch B] RUN_DIR...

--batch: replay as if the file's sampling.batch were B (a smaller batch replays exactly as
long as its looks stay inside the record).

The record holds what the run's own rules took, so a rule that needs fewer iterations replays
exactly (an adaptive run's iterations are the first ones of the fixed counts, seed for seed:
plan.py). Where a replayed decision differs from the recorded one (a race that ends on another
leader), the experiments that take from it (the bin emptying) replay on the recorded bin's
rows: said per experiment. Worker-minutes are the recorded iterations' wall_time; on W
workers a file takes about its worker-minutes / W.
"""

import argparse
import collections
import os

from experiment_manager import experiment_file
from experiment_manager.analysis import decisions, metrics
from experiment_manager.analysis.results import read_csv
from experiment_manager.analysis.wording import dims
from experiment_manager.experiment_file import (
    BIN_EMPTYING,
    BIN_STATIC,
    FEEDER_EMPTYING,
    TABLE_SWEEP,
)
from experiment_manager.experiment_file.plan import groups
from experiment_manager.running import sampling


def replay(file, exp, rows: list[dict], batch: int) -> tuple[list[dict], int, str]:
    """(the rows the looks take with batches of `batch`, the looks, how the replay ended)."""
    recorded = collections.Counter(r['group'] for r in rows)
    given = dict.fromkeys(groups(exp), batch)
    looks = 1
    while True:
        taken = [r for r in rows if r['iteration'] < given[r['group']]]
        wanted = collections.Counter(sampling.unsettled(file, exp, taken))
        wanted = {g: k for g, k in wanted.items() if given[g] < exp.iterations}
        if not wanted:
            return taken, looks, 'settled' if not sampling.unsettled(file, exp, taken) \
                else 'iterations spent'
        if any(min(given[g] + k * batch, exp.iterations) > recorded[g]
               for g, k in wanted.items()):
            return taken, looks, 'the record ran out'
        for g, k in wanted.items():
            given[g] = min(given[g] + k * batch, exp.iterations)
        looks += 1


def decision(file, exp, taken: list[dict]) -> str:
    if exp.type == BIN_STATIC:
        racing, tie = sampling.ended(file, exp, taken)
        best = metrics.bin_static(exp, taken).best_bin_mm
        return f'best bin {dims(best)} mm' + (f', a tie of bins {tie}' if tie else '') + \
            (f', bins {racing} not told apart' if racing else '')
    if exp.type == TABLE_SWEEP:
        fitted = metrics.fit_optimum([r['group'] for r in taken], [r['valid'] for r in taken],
                                     exp.counts[0], exp.counts[-1], exp.margin)
        return f'n* {fitted.n_star}'
    if exp.type in (FEEDER_EMPTYING, BIN_EMPTYING) and metrics.left_out(taken):
        return 'NOT FEASIBLE: an iteration left out of the figures (a physics fault)'
    if exp.type == FEEDER_EMPTYING:
        grounds = metrics.table_grounds(file, taken)
        return 'table ' + decisions.combined([g.verdict for g in grounds.values()])
    if exp.type == BIN_EMPTYING:
        emptied = sum(bool(r['emptied']) for r in taken)
        return 'bin ' + decisions.rate(emptied, len(taken), file.requirements.success_rate,
                                       'bins emptied').verdict
    return exp.type


def part(run_dir: str, batch: int | None) -> None:
    file = experiment_file.load(os.path.join(run_dir, 'experiment.yaml'))
    rows = read_csv(os.path.join(run_dir, 'iterations.csv'))
    batch = batch or file.sampling.batch
    print(f'{os.path.basename(os.path.normpath(run_dir))} (recorded with batch '
          f'{file.sampling.batch}, replayed with {batch}):')
    total = {'recorded': 0.0, 'replayed': 0.0}
    for exp in file.experiments:
        mine = [r for r in rows if r['experiment'] == exp.id]
        if not mine:
            continue
        taken, looks, end = replay(file, exp, mine, batch)
        minutes = [sum(r['wall_time'] for r in x) / 60.0 for x in (mine, taken)]
        total['recorded'] += minutes[0]
        total['replayed'] += minutes[1]
        print(f'  {exp.id}: {len(taken)} of {len(mine)} iterations, {minutes[1]:.1f} of '
              f'{minutes[0]:.1f} worker-min, {looks} looks, {end}; replayed: '
              f'{decision(file, exp, taken)}; on all recorded rows: {decision(file, exp, mine)}')
    print(f'  in all: {total["replayed"]:.1f} worker-min replayed against '
          f'{total["recorded"]:.1f} recorded (ratio {total["replayed"] / total["recorded"]:.2f})')


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('run_dirs', nargs='+')
    parser.add_argument('--batch', type=int, help="replay with this batch (default: the file's)")
    args = parser.parse_args()
    for run_dir in args.run_dirs:
        part(run_dir, args.batch)


if __name__ == '__main__':
    main()
