"""Two runs of feeder runs side by side on the seeds they share: what a change to the cell (its
moves, say) did to the same drops. Reads each run directory's iterations.csv and checks.csv.

    tools/ws python -m studies.compare_runs RUN_DIR_A RUN_DIR_B [--experiment feeder]
        [--picture PNG [--iteration N]]

Prints, for each run over the iterations whose seeds both ran: runs emptied, vibrations and
feeds to empty (mean, min-max), the table's simulated time (s, mean), valid parts per check
(mean over every check), parts spilled, the tray's worst tracking error, and the wall time
per run (s, mean). --picture draws one iteration of each run from above (parts.csv: each part's
centre on the tray, the valid ones green) at its first check after vibration 1, 2 and 5 and at
its last check; the iteration is the first that one of the runs did not empty, else 0.
"""

import argparse
import os
import statistics

from experiment_manager.analysis.results import read_csv
from pick_validity.results import STAGE_VALID


def load(run: str, experiment: str, names: tuple[str, ...]) -> dict[str, list[dict]]:
    """The run's results files `names` (iterations, checks, parts), typed, rows of `experiment`
    only."""
    return {name: [r for r in read_csv(os.path.join(run, f'{name}.csv'))
                   if r['experiment'] == experiment] for name in names}


def describe(rows: dict[str, list[dict]], seeds: set[int]) -> str:
    its = [r for r in rows['iterations'] if r['seed'] in seeds]
    kept = {r['iteration'] for r in its}
    checks = [c for c in rows['checks'] if c['iteration'] in kept]

    def spread(key: str) -> str:
        v = [r[key] for r in its]
        return f'{statistics.mean(v):.1f} ({min(v):g}-{max(v):g})'
    return (f'{sum(r["emptied"] for r in its)} of {len(its)} emptied; vibrations '
            f'{spread("vibrations")}; feeds {spread("feeds")}; table '
            f'{statistics.mean(r["table_time"] for r in its):.1f} s; valid per check '
            f'{statistics.mean(c["valid"] for c in checks):.2f}; spilled '
            f'{sum(r["spilled"] for r in its)}; tray error '
            f'{100 * max(r["tray_error"] for r in its):.1f} %; wall '
            f'{statistics.mean(r["wall_time"] for r in its):.0f} s a run')


def picture(runs: dict[str, dict[str, list[dict]]], experiment: str, iteration: int | None,
            path: str) -> int:
    """Draw the runs' iteration (see the module's doc) into `path`; returns the iteration."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    if iteration is None:
        failed = sorted({r['iteration'] for rows in runs.values() for r in rows['iterations']
                         if not r['emptied']})
        iteration = failed[0] if failed else 0
    fig, axes = plt.subplots(len(runs), 4, figsize=(16, 3.3 * len(runs)), squeeze=False)
    for row, (name, rows) in zip(axes, runs.items(), strict=True):
        checks = [c for c in rows['checks'] if c['iteration'] == iteration]
        firsts: dict[int, dict] = {}
        for c in checks:
            firsts.setdefault(c['vibrations'], c)
        shown = [firsts.get(v) for v in (1, 2, 5)] + [checks[-1] if checks else None]
        parts = [p for p in rows['parts'] if p['iteration'] == iteration]
        for ax, c in zip(row, shown, strict=True):
            ax.set_xlim(-100, 100)
            ax.set_ylim(-78, 78)
            ax.set_aspect('equal')
            ax.add_patch(plt.Rectangle((-97.5, -75), 195, 150, fill=False))
            if c is None:
                ax.set_title(f'{name}: no such check', fontsize=8)
                continue
            ps = [p for p in parts if p['check'] == c['check']]
            ax.scatter([p['x'] * 1e3 for p in ps], [p['y'] * 1e3 for p in ps], s=8,
                       c=['green' if p['stage'] == STAGE_VALID else 'grey' for p in ps])
            ax.set_title(f'{name}\nafter {c["vibrations"]} vibration(s): {c["parts_on_table"]} '
                         f'parts, {c["valid"]} valid (green)', fontsize=8)
    fig.suptitle(f'{experiment}, iteration {iteration}: parts from above, mm (the 195 x 150 mm '
                 'tray)', fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=70)
    return iteration


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('runs', nargs=2)
    parser.add_argument('--experiment', default='feeder')
    parser.add_argument('--picture')
    parser.add_argument('--iteration', type=int)
    args = parser.parse_args()
    names = ('iterations', 'checks') + (('parts',) if args.picture else ())
    runs = {os.path.basename(os.path.normpath(run)): load(run, args.experiment, names)
            for run in args.runs}
    a, b = ({r['seed'] for r in rows['iterations']} for rows in runs.values())
    seeds = a & b
    print(f'{len(seeds)} seeds in both runs of {args.experiment}')
    for name, rows in runs.items():
        print(f'{name}: {describe(rows, seeds)}')
    if args.picture:
        drawn = picture(runs, args.experiment, args.iteration, args.picture)
        print(f'{args.picture}: iteration {drawn}')


if __name__ == '__main__':
    main()
