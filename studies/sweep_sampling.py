"""Where should an adaptive sweep drop its parts? Replays the rows of a table_sweep run with
fixed counts through adaptive sampling's looks, two ways, on the same orderings of each
count's iterations: a batch at every count at each look (the baseline), and the batches
sampling.unsettled places where they narrow n* most. Prints, per way, how many orderings
settled, the looks, the iterations and the worker-minutes they took (the rows' own wall
times), and the n* each reached, against the fixed counts' n* and 95 % interval.

    tools/ws python -m studies.sweep_sampling RUN_DIR [--orders 20] [--batch 5]

RUN_DIR: a run directory whose file has a table_sweep run with its full counts (every count's
`iterations` written). Each ordering shuffles the iterations within each count (they are
exchangeable: each has its own seed), so the looks see other first draws of the same sweep.
"""

import argparse
import collections
from dataclasses import replace
import os

from experiment_manager import experiment_file
from experiment_manager.analysis import metrics
from experiment_manager.analysis.results import read_csv
from experiment_manager.running import sampling
import numpy as np
from pick_common.errors import InvalidArgument


def replay(file, exp, by_count: dict, everywhere: bool) -> tuple:
    """The looks of an adaptive sweep over the recorded rows (`by_count`: count -> its rows
    in the order they are released); (settled, looks, rows taken)."""
    batch = file.sampling.batch
    taken = {n: min(batch, len(v)) for n, v in by_count.items()}
    looks = 1
    while True:
        rows = [r for n, v in by_count.items() for r in v[:taken[n]]]
        asked = sampling.unsettled(file, exp, rows)
        wanted = [n for n in asked if taken[n] < len(by_count[n])]
        if not wanted:
            return not asked, looks, rows
        if everywhere:
            wanted = [n for n in by_count if taken[n] < len(by_count[n])]
        for n, k in collections.Counter(wanted).items():
            taken[n] = min(len(by_count[n]), taken[n] + k * batch)
        looks += 1


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('run_dir')
    parser.add_argument('--orders', type=int, default=20)
    parser.add_argument('--batch', type=int, default=5)
    args = parser.parse_args()
    try:
        file = experiment_file.load(os.path.join(args.run_dir, 'experiment.yaml'))
    except InvalidArgument as exc:
        raise SystemExit(f'{args.run_dir}: not a run directory ({exc})') from None
    file = replace(file, sampling=replace(file.sampling, mode=experiment_file.ADAPTIVE,
                                          batch=args.batch))
    exp = next((e for e in file.experiments if e.type == experiment_file.TABLE_SWEEP), None)
    if exp is None:
        raise SystemExit(f'{args.run_dir}: its file has no table_sweep experiment')
    rows = [r for r in read_csv(os.path.join(args.run_dir, 'iterations.csv'))
            if r['experiment'] == exp.id]
    recorded = {n: sorted((r for r in rows if r['group'] == n), key=lambda r: r['iteration'])
                for n in exp.counts}
    if any(len(v) != exp.iterations for v in recorded.values()):
        raise SystemExit(f'{args.run_dir}: {exp.id} does not have {exp.iterations} iterations '
                         'at every count (run it with its full counts)')
    fixed = metrics.table_sweep(file, exp, rows)
    minutes = sum(r['wall_time'] for r in rows) / 60.0
    print(f'{file.id} {exp.id}: {len(exp.counts)} counts x {exp.iterations}, {minutes:.1f} '
          f'worker-min; fixed counts n* {fixed.n_star}, 95 % interval '
          f'{fixed.n_star_ci95}; batch {args.batch}, {args.orders} orderings')
    results = {'a batch at every count': [], 'placed where n* narrows most': []}
    for k in range(args.orders):
        rng = np.random.default_rng([file.seed, k])
        by_count = {n: [v[i] for i in rng.permutation(len(v))] for n, v in recorded.items()}
        for way, everywhere in zip(results, (True, False), strict=True):
            settled, looks, taken = replay(file, exp, by_count, everywhere)
            star = metrics.table_sweep(file, exp, taken).n_star
            results[way].append((settled, looks, len(taken),
                                 sum(r['wall_time'] for r in taken) / 60.0, star))
    baseline = np.median([r[3] for r in results['a batch at every count']])
    for way, got in results.items():
        settled, looks, taken, spent, stars = (np.array(c) for c in zip(*got, strict=True))
        low, high = fixed.n_star_ci95 or (None, None)
        inside = int(np.sum((stars >= low) & (stars <= high))) if low is not None else '-'
        print(f'  {way}: settled {settled.sum()} of {len(got)}, looks median '
              f'{np.median(looks):g} (max {looks.max()}), iterations median '
              f'{np.median(taken):g}, worker-min median {np.median(spent):.2f} '
              f'({spent.min():.2f}-{spent.max():.2f}; x{baseline / np.median(spent):.2f} '
              f'against a batch at every count), n* median {np.median(stars):g} '
              f"({stars.min()}-{stars.max()}; {inside} of {len(got)} inside the fixed counts' "
              f'interval)', flush=True)


if __name__ == '__main__':
    main()
