"""Replay the bins' race of finished adaptive runs with a given BIN_TIE, on their recorded drops:
the same batches (5 per bin, then 5 per bin still racing), each look deciding with
running/sampling.ended as a run does, until the race ends or the recorded drops run out. With
--tie 0 it gives back the race the runs ran before the tie rule.

    tools/ws python -m bench.experiment.replay_race [--tie 0.05] RUN_DIR...

RUN_DIR: an adaptive run's directory (its experiment.yaml and iterations.csv), with a
bin_static experiment `bins`.
"""

import argparse
import os

from experiment_manager import experiment_file
from experiment_manager.analysis.results import read_csv
from experiment_manager.running import sampling


def replay(run_dir: str, batch: int) -> str:
    file = experiment_file.load(os.path.join(run_dir, 'experiment.yaml'))
    exp = file.experiment('bins')
    rows = [r for r in read_csv(os.path.join(run_dir, 'iterations.csv'))
            if r['experiment'] == 'bins']
    recorded = {}
    for r in rows:
        recorded[r['group']] = max(recorded.get(r['group'], 0), r['iteration'] + 1)
    given = dict.fromkeys(range(len(exp.bins)), batch)
    looks, end = 1, 'one bin left'
    while True:
        racing, tie = sampling.ended(file, exp, [r for r in rows
                                                 if r['iteration'] < given[r['group']]])
        if tie:
            end = f'a tie of bins {tie}'
        if not racing:
            break
        if any(given[g] + batch > recorded.get(g, 0) for g in racing):
            end = f'the recorded drops ran out with bins {racing} racing'
            break
        for g in racing:
            given[g] += batch
        looks += 1
    used = [r for r in rows if r['iteration'] < given[r['group']]]
    return (f'{os.path.basename(os.path.normpath(run_dir))}: {len(used)} of {len(rows)} drops, '
            f'{sum(r["wall_time"] for r in used) / 60:.1f} of '
            f'{sum(r["wall_time"] for r in rows) / 60:.1f} '
            f'worker-min, {looks} looks, ended by {end}')


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('run_dirs', nargs='+')
    parser.add_argument('--tie', type=float, default=sampling.BIN_TIE,
                        help=f'BIN_TIE to replay with (default {sampling.BIN_TIE})')
    parser.add_argument('--batch', type=int, default=5, help="the runs' sampling.batch")
    args = parser.parse_args()
    sampling.BIN_TIE = args.tie
    print(f'BIN_TIE {args.tie}')
    for d in args.run_dirs:
        print(replay(d, args.batch))


if __name__ == '__main__':
    main()
