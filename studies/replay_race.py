"""Replay the bins' race of finished adaptive runs with a given BIN_TIE, on their recorded drops:
the same batches (5 per bin, then 5 per bin still racing), each look deciding with
running/sampling.ended as a run does, until the race ends or the recorded drops run out.
--overlap replays the earlier rule (a bin left when its 99.9 % interval lay below the
leader's, and a tie was the leader's upper bound less the bin's lower bound); with --overlap
--tie 0 it gives back the race as runs made before the tie rule ran it.

    tools/ws python -m studies.replay_race [--tie 0.05] [--overlap] RUN_DIR...

RUN_DIR: an adaptive run's directory (its experiment.yaml and iterations.csv), with a
bin_static experiment `bins`.
"""

import argparse
import os

from experiment_manager import experiment_file
from experiment_manager.analysis.results import read_csv
from experiment_manager.experiment_file.plan import groups
from experiment_manager.running import sampling
import numpy as np
from pick_common.stats import interval

from . import replay_decisions


def overlap_race(exp, rows: list[dict]) -> tuple[list[int], list[int]]:
    """The earlier sampling.race: each bin's own interval at INTERIM_CONFIDENCE against
    the leader's."""
    if len(groups(exp)) == 1:
        return [], []
    fractions = {g: [r['container_free'] / r['checked'] for r in rows
                     if r['group'] == g and r['checked']] for g in groups(exp)}
    intervals = {g: interval(v, sampling.INTERIM_CONFIDENCE)
                 for g, v in fractions.items()}
    if any(low is None for low, _ in intervals.values()):
        return groups(exp), []
    leader = max(groups(exp), key=lambda g: (np.mean(fractions[g]), -g))
    floor, top = intervals[leader]
    racing = [g for g in groups(exp) if intervals[g][1] >= floor]
    if len(racing) == 1:
        return [], []
    if all(top - intervals[g][0] <= sampling.BIN_TIE * floor for g in racing):
        return [], [leader] + [g for g in racing if g != leader]
    return racing, []


def replay(run_dir: str, batch: int) -> str:
    file = experiment_file.load(os.path.join(run_dir, 'experiment.yaml'))
    exp = file.experiment('bins')
    rows = [r for r in read_csv(os.path.join(run_dir, 'iterations.csv'))
            if r['experiment'] == 'bins']
    used, looks, end = replay_decisions.replay(file, exp, rows, batch)
    racing, tie = sampling.ended(file, exp, used)
    if tie:
        end = 'a tie'
    elif racing:
        end = f'{end} with bins {racing} racing'
    elif end == 'settled':
        end = 'one bin left'
    return (f'{os.path.basename(os.path.normpath(run_dir))}: '
            f'{replay_decisions.decision(file, exp, used)}, {len(used)} of {len(rows)} drops, '
            f'{sum(r["wall_time"] for r in used) / 60:.1f} of '
            f'{sum(r["wall_time"] for r in rows) / 60:.1f} '
            f'worker-min, {looks} looks, ended by {end}')


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('run_dirs', nargs='+')
    parser.add_argument('--tie', type=float, default=sampling.BIN_TIE,
                        help=f'BIN_TIE to replay with (default {sampling.BIN_TIE})')
    parser.add_argument('--batch', type=int, default=5, help="the runs' sampling.batch")
    parser.add_argument('--overlap', action='store_true',
                        help='the earlier rule: intervals that do not overlap')
    args = parser.parse_args()
    sampling.BIN_TIE = args.tie
    if args.overlap:
        sampling.race = overlap_race
    print(f'BIN_TIE {args.tie}, {"intervals that do not overlap" if args.overlap else "Welch"}')
    for d in args.run_dirs:
        print(replay(d, args.batch))


if __name__ == '__main__':
    main()
