"""Has the physics converged? The same seeded workloads at the default settings, at half and a
quarter of the time step, with more solver iterations, and at the former defaults (30
iterations, pybullet's warm start of 0.1), with 95 % confidence intervals.

Workloads (the experiment procedures on the cores, so the figures are the ones a run reports;
every one with the D 8, W 3 mm gripper, GRIPPER below):
- sweep: PTH0 capacitors dropped onto the tray at three counts, checked with all four stages:
  valid parts per check;
- feeder: PTH0 feeder_emptying runs of 100 parts at the optimal range [80, 90] (the reduced
  test case's sweep): vibrations to empty the feeder, parts spilled;
- bins: 480 TO-220s (PTH1) into the test case's biggest and tallest bins, 300 x 300 x 26 and
  200 x 75 x 158 mm: the container-free fraction, parts left moving at the settle's end
  (flat-bin, tall-bin: one alone, for more seeds where the intervals are close);
- emptying: 150 TO-220s into a 100 x 100 x 48 mm bin, picked until no part is valid: parts
  removed per bin (the settle after each pick is where freezing acts most; 480 parts in the
  300 x 300 x 26 mm bin took 250 s per iteration at the default, too long for many seeds);
- the other parts, to tell a part's effect from a pile's: sweep-pth1 and sweep-pth2 (TO-220s
  and the 8 mm capacitors on the tray at 20, 40 and 60 parts), flat-bin-pth2 (480 capacitors
  into PTH2's 300 x 300 x 22 mm bin), feeder-pth1 and feeder-pth2 (their feeder runs of 100
  parts at [39, 49] and [53, 63]); bins also report the candidates' fraction;
and for every workload parts tunnelled, the deepest penetration (mm), the worst tray tracking
error and the wall time per iteration. An interval is mean +- t(0.975, n-1) s / sqrt(n); a
setting's mean is marked '*' when it lies outside the finest setting's interval (--finest,
default a quarter of the step).

    tools/ws python -m studies.convergence [--seeds 8] [--workloads sweep,feeder,bins,...]
        [--settings default,100-it,...] [--finest dt/4]

Runs are spread over a process per CPU. What it costs: docs/physics.md, "Convergence".
"""

import argparse
from dataclasses import replace
import json
import multiprocessing
import os
import statistics
import time

from pick_common.stats import interval as mean_interval
from pick_sim_world.config import PhysicsConfig

from studies.cases import parse_args, run_on_cores

DEFAULT = PhysicsConfig()
# The finer settings solve a tray with a bin's iterations too (100, not the tray's 50).
FINER = replace(DEFAULT, tray_solver_iterations=DEFAULT.solver_iterations)
SETTINGS = {
    'default': DEFAULT,         # 1/480 s, 100 iterations (50 on a tray), warm start 0.85
    '1/240': replace(DEFAULT, time_step=1 / 240),   # pybullet's step, an earlier default
    'dt/2': replace(FINER, time_step=DEFAULT.time_step / 2),
    'dt/4': replace(FINER, time_step=DEFAULT.time_step / 4),
    'dt/8': replace(FINER, time_step=DEFAULT.time_step / 8),
    '200-it': replace(DEFAULT, solver_iterations=200, tray_solver_iterations=200),
    # a tray solved with a bin's 100 iterations: an earlier default
    'tray-100-it': FINER,
    # fewer iterations at the default warm start: what a step costs is mostly the solver's
    '50-it': replace(DEFAULT, solver_iterations=50, tray_solver_iterations=50),
    '30-it-warm': replace(DEFAULT, solver_iterations=30, tray_solver_iterations=30),
    'warm-1': replace(DEFAULT, warm_starting_factor=1.0),   # an earlier default
    # the defaults before the convergence study: 30 iterations, pybullet's warm start
    '30-it': replace(DEFAULT, solver_iterations=30, tray_solver_iterations=30,
                     warm_starting_factor=0.1),
    # the parts' rolling and spinning friction arms of an earlier default (MATERIALS below)
    'arms-1mm': DEFAULT,
    # every part stepped to the end of every settle: an earlier default
    'no-freeze': replace(DEFAULT, settle_freeze=False),
    'dt/2-no-freeze': replace(FINER, time_step=DEFAULT.time_step / 2, settle_freeze=False),
    # the world in metres, as it simulated before (and its contact-breaking factor then)
    'metres': replace(DEFAULT, length_unit=1.0, contact_breaking_threshold=0.001),
}
# a setting's materials section (an experiment file's), for both pairs
MATERIALS = {'arms-1mm': {pair: {'rolling_friction_mm': 1.0, 'spinning_friction_mm': 1.0}
                          for pair in ('part_on_surface', 'part_on_part')}}
FINEST = 'dt/4'         # the reference the others are marked against


def _feeder(part_file: str, optimal_range: list[int]) -> tuple:
    """The workload of `part_file`'s feeder_emptying runs of 100 parts at `optimal_range`."""
    return (part_file, lambda n: [{'id': 'feeder', 'type': 'feeder_emptying', 'iterations': n,
                                   'parts': 100, 'optimal_range': optimal_range,
                                   'max_vibrations': 500}],
            ('vibrations', 'emptied', 'spilled', 'tunnelled', 'max_penetration', 'tray_error',
             'wall_time'))


WORKLOADS = {
    # the sweeps at their three counts only: a sweep whose fit peaks at its last count goes on
    # (extend), and the settings would not share their counts
    'sweep': ('pth0.yaml', lambda n: [{'id': 'sweep', 'type': 'table_sweep', 'iterations': n,
                                       'counts': {'first': 30, 'last': 90, 'step': 30},
                                       'extend': False}],
              ('valid', 'tunnelled', 'max_penetration', 'wall_time')),
    'feeder': _feeder('pth0.yaml', [80, 90]),
    # the other parts' feeder runs (the reduced test case's optimal ranges)
    'feeder-pth1': _feeder('pth1.yaml', [39, 49]),
    'feeder-pth2': _feeder('pth2.yaml', [53, 63]),
    'bins': ('pth1.yaml', lambda n: [{'id': 'bins', 'type': 'bin_static', 'iterations': n,
                                      'parts': 480, 'bins_mm': [[300, 300, 26],
                                                                [200, 75, 158]]}],
             ('container_free', 'unsettled', 'tunnelled', 'max_penetration', 'wall_time')),
    'flat-bin': ('pth1.yaml', lambda n: [{'id': 'bins', 'type': 'bin_static', 'iterations': n,
                                          'parts': 480, 'bins_mm': [[300, 300, 26]]}],
                 ('candidates', 'container_free', 'unsettled', 'tunnelled', 'max_penetration',
                  'wall_time')),
    'tall-bin': ('pth1.yaml', lambda n: [{'id': 'bins', 'type': 'bin_static', 'iterations': n,
                                          'parts': 480, 'bins_mm': [[200, 75, 158]]}],
                 ('candidates', 'container_free', 'unsettled', 'tunnelled', 'max_penetration',
                  'wall_time')),
    'emptying': ('pth1.yaml', lambda n: [{'id': 'emptying', 'type': 'bin_emptying',
                                          'iterations': n, 'parts': 150,
                                          'bin': [100, 100, 48]}],
                 ('picks', 'unsettled', 'tunnelled', 'max_penetration', 'wall_time')),
    # the other parts: is the step's effect the part's or the pile's?
    'flat-bin-pth2': ('pth2.yaml', lambda n: [{'id': 'bins', 'type': 'bin_static',
                                               'iterations': n, 'parts': 480,
                                               'bins_mm': [[300, 300, 22]]}],
                      ('candidates', 'container_free', 'unsettled', 'tunnelled',
                       'max_penetration', 'wall_time')),
    'sweep-pth1': ('pth1.yaml', lambda n: [{'id': 'sweep', 'type': 'table_sweep',
                                            'iterations': n, 'extend': False,
                                            'counts': {'first': 20, 'last': 60, 'step': 20}}],
                   ('candidates', 'valid', 'tunnelled', 'max_penetration', 'wall_time')),
    'sweep-pth2': ('pth2.yaml', lambda n: [{'id': 'sweep', 'type': 'table_sweep',
                                            'iterations': n, 'extend': False,
                                            'counts': {'first': 20, 'last': 60, 'step': 20}}],
                   ('candidates', 'valid', 'tunnelled', 'max_penetration', 'wall_time')),
}


# Every workload checks with the smallest gripper that meets PTH0's yield (grippers_pth0.yaml,
# docs/paper-test-case.md, "Which gripper"). Chosen when, with the test case's 20 mm one (and
# the earlier validity check), every PTH0 feeder run stopped at its vibration limit; since round
# bodies are gripped at any roll they empty (PTH0: 50 of 50, 33 vibrations on average), so that
# reason no longer holds: studies/answers.py checks the answers as reported with the test case's
# own gripper and loads.
GRIPPER = {'body_diameter_mm': 8, 'body_length_mm': 60, 'jaw_height_mm': 15, 'jaw_depth_mm': 3}


def job(args: tuple[str, str, int]) -> tuple[str, str, list[dict]]:
    setting, workload, seeds = args
    part_file, experiments, _ = WORKLOADS[workload]
    materials = {'materials': MATERIALS[setting]} if setting in MATERIALS else {}
    rows, _ = run_on_cores(part_file, experiments(seeds), SETTINGS[setting], gripper=GRIPPER,
                           **materials)
    return setting, workload, rows


def value(row: dict, column: str) -> float:
    if column in ('candidates', 'container_free'):    # fractions of the parts checked
        return int(row[column]) / max(1, int(row['checked']))
    if column == 'max_penetration':
        return 1000.0 * float(row[column])
    if column == 'emptied':
        return float(row[column] in (True, 'True'))
    return float(row[column])


def interval(values: list[float]) -> tuple[float, float] | None:
    """Mean and the half width of its 95 % confidence interval (metrics.interval; 0 for one
    value); None for no value."""
    if not values:
        return None
    low, high = mean_interval(values)
    return statistics.fmean(values), 0.0 if low is None else (high - low) / 2


# the size of its smoke test (tests/test_studies.py): `--small`
SMALL = ['--workloads', 'sweep', '--settings', 'default', '--finest', 'default', '--seeds', '1']


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--seeds', type=int, default=8, help='iterations per group')
    parser.add_argument('--workloads', default='sweep,feeder,bins')
    parser.add_argument('--settings', default=','.join(SETTINGS),
                        help='comma-separated names of SETTINGS')
    parser.add_argument('--finest', default=FINEST, help='the reference setting')
    parser.add_argument('--rows', default='',
                        help="a JSON file the runs' rows are written to, or read from when it "
                             'exists (the tables again without running)')
    args = parse_args(parser, SMALL)
    workloads = args.workloads.split(',')
    unknown = set(args.settings.split(',') + [args.finest]) - set(SETTINGS)
    if unknown:
        parser.error(f'--settings: unknown {sorted(unknown)}; known: {", ".join(SETTINGS)}')
    settings = [s for s in SETTINGS if s in args.settings.split(',') or s == args.finest]
    jobs = [(s, w, args.seeds) for w in workloads for s in settings]
    if args.rows and os.path.exists(args.rows):
        with open(args.rows, encoding='utf-8') as f:
            results = [tuple(r) for r in json.load(f)]
    else:
        start = time.perf_counter()
        with multiprocessing.Pool(min(len(jobs), os.cpu_count() or 1)) as pool:
            results = pool.map(job, jobs, chunksize=1)
        print(f'{len(jobs)} jobs, {args.seeds} seeds per group, '
              f'{(time.perf_counter() - start) / 60:.1f} min wall on {os.cpu_count()} CPUs')
        if args.rows:
            with open(args.rows, 'w', encoding='utf-8') as f:
                json.dump(results, f, default=str)
    by = {(s, w): rows for s, w, rows in results}
    for w in workloads:
        columns = WORKLOADS[w][2]
        groups = sorted({int(r['group']) for s in settings for r in by[(s, w)]})
        for g in groups:
            print(f'\n{w}' + (f', group {g}' if len(groups) > 1 else ''))
            print('| setting | ' + ' | '.join(columns) + ' |')
            print('| --- |' + ' --- |' * len(columns))
            finest = {c: interval([value(r, c) for r in by[(args.finest, w)]
                                   if int(r['group']) == g]) for c in columns}
            for s in settings:
                cells = []
                for c in columns:
                    got = interval([value(r, c) for r in by[(s, w)] if int(r['group']) == g])
                    if got is None:         # a group this setting did not run
                        cells.append('-')
                        continue
                    mean, half = got
                    far = finest[c] is not None and c != 'wall_time' and \
                        abs(mean - finest[c][0]) > finest[c][1] + 1e-12
                    cells.append(f'{mean:.3g} +- {half:.2g}' + (' *' if far else ''))
                print(f'| {s} | ' + ' | '.join(cells) + ' |')


if __name__ == '__main__':
    main()
