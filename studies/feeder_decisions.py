"""The table's verdict on few feeder runs against the verdict on many.

Two steps:
  tools/ws python -m studies.feeder_decisions files DIR
writes DIR/feeder_pth0.yaml, feeder_pth1.yaml, feeder_pth2.yaml: the test case's parts,
grippers and requirements (config/test_case/pth*.yaml) with one experiment, 50 feeder runs at
the optimal range of the full-count sweeps (n* 72, 45 and 54, +-5: docs/paper-test-case.md),
to be run through the graph (`files DIR --moves centre,flip` writes feeder_pth0_centre_flip.yaml
and so on: the same runs with another feeder cycle, for compare_runs.py):
  tools/ws install/experiment_manager/lib/experiment_manager/run --output DIR/runs DIR/*.yaml
and then
  tools/ws python -m studies.feeder_decisions table RUN_DIR... [--draws 2000]
reads each run's iterations.csv and prints, per part, the verdict on all its runs, then, for
subsamples of 3, 5, 8 and 12 runs drawn without replacement `--draws` times, how often the
verdict on the subsample agrees with the full data's, how often it says FEASIBLE where the
full data does not (false FEASIBLE), and how often it is UNDECIDED; and the same for a
borderline refill interval (the full data's estimate of the 90 % quantile of the time to
empty), where the verdict should say UNDECIDED more than anything else; and the same at the
runs' own 90 % quantile, no model's (a tenth of the runs over it: a subsample drawn from them
that says FEASIBLE there is wrong). Last, the cost of the
table's decision per part in worker-minutes (the runs' wall_time, as they ran): all the
runs (fixed counts), the runs adaptive sampling took before this rule (batches of 5 until the
share of runs emptied was settled at 99.9 %, two-sided: 73 runs when all empty, so all 50),
and the runs it takes with this rule (sampling.unsettled after each batch of 5).

  tools/ws python -m studies.feeder_decisions noise RUN_DIR... [--populations 60]
asks how far the borderline's false-FEASIBLE rate would stray with a decision that is exact:
it draws populations of as many runs as each part has from the Gumbel fitted to them (the
model the decision assumes, so that its 95 % holds by construction), puts each population's
borderline where `table` puts it, and prints the spread of the same rate over the populations
(median, 90th percentile, the share above 5 %) beside the part's own. The borderline sits on
the quantile itself, where a one-sided 95 % bound says FEASIBLE 5 % of the time on average;
one population of 50 scatters about that.

  tools/ws python -m studies.feeder_decisions plot RUN_DIR... --out PNG
draws each part's probability plots: its runs' times to empty, ordered, against the Gumbel's
quantiles, and their logarithms less the picks' time against the normal's (the lognormal the
bound used before the Gumbel's; Gringorten's and Blom's plotting positions), each with the
fitted line; where the points bend off a line at the top, that
model's tail is too short for the runs.

Deciding finished runs again with today's rules is the `decide` command.
"""

import argparse
import os
import sys

from experiment_manager import experiment_file
from experiment_manager.analysis import decisions
from experiment_manager.analysis.results import read_csv
from experiment_manager.running import sampling
import numpy as np
from pick_common.stats import rate_interval
import yaml

from studies.cases import TEST_CASE

# the full-count sweeps' n* (docs/paper-test-case.md, "In short") and the files' margin
N_STAR = {'pth0': 72, 'pth1': 45, 'pth2': 54}
MARGIN = 5
RUNS = 50
SIZES = (3, 5, 8, 12)


def write_files(directory: str, moves: list[str] | None = None) -> list[str]:
    """The files (see the module's doc); with `moves`, that feeder cycle in place of the test
    case's, and the cycle's names in each file's id and name (the same seeds: a seed comes from
    the file's seed, the experiment's id and the iteration's key)."""
    os.makedirs(directory, exist_ok=True)
    paths = []
    for part, n_star in N_STAR.items():
        with open(os.path.join(TEST_CASE, f'{part}.yaml'), encoding='utf-8') as f:
            data = yaml.safe_load(f)
        feeder = next(e for e in data['experiments'] if e['type'] == 'feeder_emptying')
        feeder.update(iterations=RUNS, optimal_range=[n_star - MARGIN, n_star + MARGIN])
        data['experiments'] = [feeder]
        name = f'feeder_{part}' + ''.join(f'_{m}' for m in moves or ())
        data['id'] = name
        if moves:
            data['moves'] = list(moves)
        path = os.path.join(directory, f'{name}.yaml')
        with open(path, 'w', encoding='utf-8') as f:
            f.write(f'# {RUNS} feeder runs of {part} at n* {n_star} +- {MARGIN} '
                    '(studies/feeder_decisions.py)\n')
            yaml.safe_dump(data, f, sort_keys=False)
        paths.append(path)
    return paths


def _decide(runs: list[dict], file, refill: float) -> str:
    """The table's verdict on `runs` at a refill interval of `refill`, s, as a run's verdict
    reads it (its time and spill grounds)."""
    r = file.requirements
    return decisions.combined([decisions.table_time(runs, refill, r.success_rate).verdict,
                               decisions.spills(runs, r.max_spilled, r.success_rate).verdict])


def table(run_dirs: list[str], draws: int, seed: int) -> None:
    rng = np.random.default_rng(seed)
    print(f'{draws} subsamples drawn without replacement per size; false FEASIBLE: FEASIBLE '
          'where all runs do not say FEASIBLE')
    for run_dir in run_dirs:
        file = experiment_file.load(os.path.join(run_dir, 'experiment.yaml'))
        runs = decisions.feeder_runs(read_csv(os.path.join(run_dir, 'iterations.csv')),
                                     file.cell)
        refill = file.requirements.refill_interval
        full = decisions.table_time(runs, refill, file.requirements.success_rate)
        print(f'\n{file.id}: {len(runs)} runs, time to empty '
              f'{min(r["time"] for r in runs) / 60:.1f}-{max(r["time"] for r in runs) / 60:.1f}'
              f' min; all runs: {full.verdict} ({full.reason})')
        # borderline: the interval at the full data's estimate of the 90 % quantile (its
        # bound lies past it, its lower bound before it: UNDECIDED on all the runs); and at
        # the runs' own 90 % quantile, no model's: a tenth of them over it
        fit = full.detail.get('gumbel')
        ordered = sorted(r['time'] for r in runs)
        own = ordered[len(ordered) - 1 - len(ordered) // 10]
        border = fit['estimate'] if fit else own
        for label, interval in (('refill interval', refill), ('borderline', border),
                                ('borderline, a tenth of the runs over it', own)):
            truth = _decide(runs, file, interval)
            print(f'  {label} {interval / 60:.1f} min: all {len(runs)} runs say {truth}')
            print('    runs | agree | false FEASIBLE | UNDECIDED | NOT FEASIBLE')
            for size in (k for k in SIZES if k < len(runs)):
                said = [_decide([runs[i] for i in rng.choice(len(runs), size, replace=False)],
                                file, interval) for _ in range(draws)]
                agree = np.mean([s == truth for s in said])
                false = np.mean([s == decisions.FEASIBLE and truth != decisions.FEASIBLE
                                 for s in said])
                undecided = np.mean([s == decisions.UNDECIDED for s in said])
                infeasible = np.mean([s == decisions.NOT_FEASIBLE for s in said])
                print(f'    {size:4d} | {agree:5.1%} | {false:14.1%} | {undecided:9.1%} | '
                      f'{infeasible:.1%}')


def _rate_at_border(runs: list[dict], file, draws: int, rng, size: int) -> float:
    """The share of `draws` subsamples of `size` of `runs` that say FEASIBLE at the runs'
    borderline (the Gumbel estimate of their 90 % quantile, as `table` puts it)."""
    fit = decisions.table_time(runs, file.requirements.refill_interval,
                               file.requirements.success_rate).detail['gumbel']
    said = [_decide([runs[i] for i in rng.choice(len(runs), size, replace=False)], file,
                    fit['estimate']) for _ in range(draws)]
    return float(np.mean([s == decisions.FEASIBLE for s in said]))


def noise(run_dirs: list[str], populations: int, draws: int, seed: int) -> None:
    rng = np.random.default_rng(seed)
    print(f"borderline false FEASIBLE: the part's own runs against {populations} populations "
          f'drawn from their fitted Gumbel ({draws} subsamples each)')
    print('  part | runs | size | own | model: median | 90th percentile | share above 5 %')
    for run_dir in run_dirs:
        file = experiment_file.load(os.path.join(run_dir, 'experiment.yaml'))
        runs = decisions.feeder_runs(read_csv(os.path.join(run_dir, 'iterations.csv')),
                                     file.cell)
        fit = decisions.table_time(runs, file.requirements.refill_interval,
                                   file.requirements.success_rate).detail['gumbel']
        n = len(runs)
        for size in (k for k in SIZES if k < n):
            own = _rate_at_border(runs, file, draws, rng, size)
            model = np.array([_rate_at_border(
                [{'time': t, 'spilled': 0, 'emptied': True}
                 for t in rng.gumbel(fit['location_s'], fit['scale_s'], n)],
                file, draws, rng, size) for _ in range(populations)])
            print(f'  {file.id} | {n} | {size} | {own:.1%} | {np.median(model):.1%} | '
                  f'{np.quantile(model, 0.9):.1%} | {(model > 0.05).mean():.0%}')


def cost(run_dirs: list[str]) -> None:
    print("\ntime to the table's decision, worker-minutes of feeder runs (runs taken):")
    print('  part | all runs (fixed) | adaptive, share emptied | adaptive, time to empty')
    for run_dir in run_dirs:
        file = experiment_file.load(os.path.join(run_dir, 'experiment.yaml'))
        exp = file.experiments[0]
        rows = sorted(read_csv(os.path.join(run_dir, 'iterations.csv')),
                      key=lambda r: r['iteration'])
        minutes = np.cumsum([r['wall_time'] for r in rows]) / 60.0
        batch = file.sampling.batch
        before = next((k for k in range(batch, len(rows) + 1, batch)
                       if rate_interval(sum(r['emptied'] for r in rows[:k]), k,
                                                sampling.INTERIM_CONFIDENCE)[0] >= 0.9),
                      len(rows))
        now = next((k for k in range(batch, len(rows) + 1, batch)
                    if not sampling.unsettled(file, exp, rows[:k])), len(rows))
        print(f'  {file.id} | {minutes[-1]:.1f} ({len(rows)}) | {minutes[before - 1]:.1f} '
              f'({before}) | {minutes[now - 1]:.1f} ({now})')


def plot(run_dirs: list[str], out: str) -> None:
    import matplotlib
    matplotlib.use('Agg')
    from matplotlib import pyplot
    from scipy import stats
    figure, axes = pyplot.subplots(2, len(run_dirs), figsize=(4.2 * len(run_dirs), 7.5),
                                   squeeze=False)
    for column, run_dir in enumerate(run_dirs):
        file = experiment_file.load(os.path.join(run_dir, 'experiment.yaml'))
        rows = read_csv(os.path.join(run_dir, 'iterations.csv'))
        times = np.sort([r['time'] for r in decisions.feeder_runs(rows, file.cell)]) / 60.0
        n = len(times)
        location, scale = decisions.gumbel_fit(times)
        gumbel = decisions.gringorten(n)
        normal = stats.norm.ppf((np.arange(1, n + 1) - 0.375) / (n + 0.25))
        # the lognormal was of the time less the picks' (the same in every
        # emptied run)
        picking = max(r['picks'] for r in rows) * file.cell.pick_time / 60.0
        logs = np.log(times - picking)
        for row, (x, y, line, name) in enumerate((
                (gumbel, times, location + scale * gumbel, 'Gumbel quantile'),
                (normal, logs, logs.mean() + logs.std(ddof=1) * normal,
                 'normal quantile (lognormal)'))):
            ax = axes[row][column]
            ax.plot(x, y, 'o', markersize=3)
            ax.plot(x, line, '-', linewidth=1)
            ax.set_xlabel(name)
            ax.set_ylabel('time to empty, min' if row == 0 else
                          'log of the time to empty less the picks', fontsize=9)
            ax.set_title(f'{file.id}, {n} runs')
    figure.tight_layout()
    figure.savefig(out, dpi=90)
    print(out)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    sub = parser.add_subparsers(dest='command', required=True)
    files = sub.add_parser('files')
    files.add_argument('directory')
    files.add_argument('--moves', help="a feeder cycle in place of the test case's, names "
                       'separated by commas (centre,flip)')
    tab = sub.add_parser('table')
    tab.add_argument('run_dirs', nargs='+')
    tab.add_argument('--draws', type=int, default=2000)
    tab.add_argument('--seed', type=int, default=43)
    model = sub.add_parser('noise')
    model.add_argument('run_dirs', nargs='+')
    model.add_argument('--populations', type=int, default=60)
    model.add_argument('--draws', type=int, default=400)
    model.add_argument('--seed', type=int, default=44)
    drawn = sub.add_parser('plot')
    drawn.add_argument('run_dirs', nargs='+')
    drawn.add_argument('--out', required=True)
    args = parser.parse_args(argv)
    if args.command == 'files':
        print('\n'.join(write_files(args.directory,
                                     args.moves.split(',') if args.moves else None)))
    elif args.command == 'plot':
        plot(args.run_dirs, args.out)
    elif args.command == 'noise':
        noise(args.run_dirs, args.populations, args.draws, args.seed)
    else:
        table(args.run_dirs, args.draws, args.seed)
        cost(args.run_dirs)
    return 0


if __name__ == '__main__':
    sys.exit(main())
