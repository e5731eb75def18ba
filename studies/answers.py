"""Do the answers a run reports hold at finer steps? The test case's own files (their gripper,
their parts' loads) run on the cores at the default step, half and a quarter of it, on the same
seeds, and the answers read from the run's summary as summary.json reports them
(studies/convergence.py checks the physics' own figures with a smaller gripper and loads):

- pth0-sweep: PTH0 on the tray at 40 to 100 parts (step 10, around the full sweep's n* of
  71-72): n* and its 95 % bootstrap interval, the fit's valid parts at n*, valid per check at
  each count;
- pth0-feeder: PTH0 feeder runs of the test case's 240 parts at [66, 76] (the adaptive run's
  range): vibrations to empty, the cell's time to empty and the table's 90 %
  bound (decisions.py), runs emptied, spilled;
- pth1-bins: 480 TO-220s (the test case's load) into PTH1's three widest bins, whose means
  tied within the flat bin's step bias, and its tallest: the container-free fraction per bin
  with its 95 % interval and the ranking a run reports (best bin first);
- pth1-feeder, pth2-feeder: feeder runs of the test case's 480 parts at the full sweeps' ranges
  [40, 50] and [49, 59].

A setting's mean is marked '*' when it lies outside the finest setting's 95 % interval, and
n* when its interval misses the finest one's. Jobs (a setting and a workload) run dearest
first over a process per CPU.

    tools/ws python -m studies.answers [--workloads pth0-sweep,...]
        [--settings default,dt/2,dt/4] [--seeds N]

What it found: docs/physics.md, "The answers as reported".
"""

import argparse
import multiprocessing
import os
import statistics
import time

from pick_common.stats import interval

from studies.cases import parse_args, summarise_on_cores
from studies.convergence import SETTINGS


def _feeder(part_file: str, parts: int, optimal_range: list[int], seeds: int) -> tuple:
    return (part_file, lambda n: [{'id': 'feeder', 'type': 'feeder_emptying', 'iterations': n,
                                   'parts': parts, 'optimal_range': optimal_range,
                                   'max_vibrations': 500}], seeds)


# name: (test-case file, experiments given the seeds, default seeds)
WORKLOADS = {
    'pth0-sweep': ('pth0.yaml', lambda n: [{'id': 'sweep', 'type': 'table_sweep',
                                            'iterations': n, 'margin': 5,
                                            'counts': {'first': 40, 'last': 100, 'step': 10}}],
                   8),
    'pth0-feeder': _feeder('pth0.yaml', 240, [66, 76], 4),
    'pth1-bins': ('pth1.yaml', lambda n: [{'id': 'bins', 'type': 'bin_static', 'iterations': n,
                                           'parts': 480,
                                           'bins_mm': [[300, 250, 32], [300, 275, 29],
                                                       [300, 300, 26], [200, 75, 158]]}], 6),
    'pth1-feeder': _feeder('pth1.yaml', 480, [40, 50], 3),
    'pth2-feeder': _feeder('pth2.yaml', 480, [49, 59], 3),
}
# wall time of one seed at the default step, s (the adaptive run and the
# convergence tables), to start the dearest jobs first
COST = {'pth0-sweep': 6, 'pth0-feeder': 57, 'pth1-bins': 40, 'pth1-feeder': 115,
        'pth2-feeder': 85}
STEP_COST = {'default': 1, 'dt/2': 2, 'dt/4': 4.5}


def job(args: tuple[str, str, int]) -> tuple[str, str, list[dict], dict, float]:
    setting, workload, seeds = args
    part_file, experiments, _ = WORKLOADS[workload]
    rows, summary, wall = summarise_on_cores(part_file, experiments(seeds), SETTINGS[setting])
    return setting, workload, rows, summary.experiments, wall


def mean_interval(values: list[float]) -> tuple[float, float, float]:
    """Mean and its 95 % interval (metrics.interval; the mean itself for one value)."""
    low, high = interval(values)
    m = statistics.fmean(values)
    return m, m if low is None else low, m if high is None else high


def cell(values: list[float], finest: tuple[float, float, float] | None, digits: int = 3) -> str:
    m, low, high = mean_interval(values)
    far = finest is not None and not finest[1] - 1e-12 <= m <= finest[2] + 1e-12
    return f'{m:.{digits}g} ({low:.{digits}g}-{high:.{digits}g})' + (' *' if far else '')


def sweep_table(results: dict, settings: list[str], finest: str) -> list[str]:
    counts = sorted({int(r['group']) for r in results[finest][0]})
    out = ['| setting | n* (95 % interval) | valid at n* (fit) | '
           + ' | '.join(f'valid at {n}' for n in counts) + ' | wall (s) |',
           '| --- |' + ' --- |' * (len(counts) + 3)]
    ref_ci = results[finest][1]['sweep'].n_star_ci95
    for s in settings:
        rows, summary, wall = results[s]
        sw = summary['sweep']
        ci = sw.n_star_ci95
        apart = ci and ref_ci and (ci[1] < ref_ci[0] or ci[0] > ref_ci[1])
        cells = []
        for n in counts:
            finest_n = mean_interval([float(r['valid']) for r in results[finest][0]
                                      if int(r['group']) == n])
            cells.append(cell([float(r['valid']) for r in rows if int(r['group']) == n],
                              finest_n))
        interval_text = f' ({ci[0]}-{ci[1]})' if ci else ''      # none from one seed
        out.append(f'| {s} | {sw.n_star}{interval_text}' + (' *' if apart else '')
                   + f' | {sw.fit_max:.1f} | ' + ' | '.join(cells) + f' | {wall:.0f} |')
    return out


def feeder_table(results: dict, settings: list[str], finest: str) -> list[str]:
    out = ['| setting | vibrations to empty | time to empty (min) | 90 % bound (min), verdict | '
           'emptied / spilled / thrown | wall (s) |', '| --- | --- | --- | --- | --- | --- |']

    def series(s: str) -> tuple[list[float], list[float]]:
        rows = results[s][0]
        return ([float(r['vibrations']) for r in rows if r['emptied'] in (True, 'True')],
                results[s][1]['feeder'].decision.time.times_s)

    ref_v, ref_t = series(finest)
    for s in settings:
        rows, summary, wall = results[s]
        vib, times = series(s)
        time_ground = summary['feeder'].decision.time
        bound = time_ground.bound
        emptied = sum(r['emptied'] in (True, 'True') for r in rows)
        spilled = sum(int(r['spilled']) for r in rows)
        thrown = sum(int(r.get('thrown') or 0) for r in rows)
        out.append(f'| {s} | {cell(vib, mean_interval(ref_v))} | '
                   f'{cell([t / 60 for t in times], mean_interval([t / 60 for t in ref_t]))} | '
                   + (f'{bound / 60:.1f}' if bound else '-') + f', {time_ground.verdict} | '
                   f'{emptied} of {len(rows)} / {spilled} / {thrown} | {wall:.0f} |')
    return out


def bins_table(results: dict, settings: list[str], finest: str) -> list[str]:
    sizes = [b.size_mm for b in results[finest][1]['bins'].bins]
    names = ['x'.join(f'{v:g}' for v in size) for size in sizes]
    out = ['| setting | ' + ' | '.join(f'container-free, {n}' for n in names)
           + ' | ranking (best first) | wall (s) |', '| --- |' + ' --- |' * (len(names) + 2)]

    def fractions(s: str, b: int) -> list[float]:
        return [int(r['container_free']) / max(1, int(r['checked'])) for r in results[s][0]
                if int(r['group']) == b]

    for s in settings:
        rows, summary, wall = results[s]
        means = [statistics.fmean(fractions(s, b)) for b in range(len(names))]
        ranking = ' > '.join(names[b] for b in sorted(range(len(names)), key=lambda b: -means[b]))
        out.append(f'| {s} | ' + ' | '.join(
            cell(fractions(s, b), mean_interval(fractions(finest, b))) for b in range(len(names)))
            + f' | {ranking} | {wall:.0f} |')
    return out


# the size of its smoke test (tests/test_studies.py): `--small`
SMALL = ['--workloads', 'pth0-sweep', '--settings', 'default', '--finest', 'default',
         '--seeds', '1']


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--workloads', default=','.join(WORKLOADS))
    parser.add_argument('--settings', default='default,dt/2,dt/4')
    parser.add_argument('--finest', default='dt/4')
    parser.add_argument('--seeds', type=int, help="seeds per group (default: each workload's)")
    args = parse_args(parser, SMALL)
    workloads = args.workloads.split(',')
    settings = args.settings.split(',')
    unknown = (set(workloads) - set(WORKLOADS)) | (set(settings + [args.finest]) - set(SETTINGS))
    if unknown:
        parser.error(f'unknown {sorted(unknown)}; workloads {", ".join(WORKLOADS)}; settings '
                     f'{", ".join(SETTINGS)}')
    if args.finest not in settings:
        settings.append(args.finest)
    jobs = [(s, w, args.seeds or WORKLOADS[w][2]) for w in workloads for s in settings]
    jobs.sort(key=lambda j: -COST[j[1]] * STEP_COST.get(j[0], 2) * j[2])
    start = time.perf_counter()
    with multiprocessing.Pool(min(len(jobs), os.cpu_count() or 1)) as pool:
        done = pool.map(job, jobs, chunksize=1)
    print(f'{len(jobs)} jobs, {(time.perf_counter() - start) / 60:.1f} min wall on '
          f"{os.cpu_count()} CPUs; the test case's gripper and loads")
    for w in workloads:
        results = {s: (rows, summary, wall) for s, ww, rows, summary, wall in done if ww == w}
        table = (sweep_table if w.endswith('sweep') else bins_table if w.endswith('bins')
                 else feeder_table)
        print(f'\n{w} ({WORKLOADS[w][0]}, {args.seeds or WORKLOADS[w][2]} seeds; * outside '
              f"{args.finest}'s 95 % interval)")
        print('\n'.join(table(results, settings, args.finest)))


if __name__ == '__main__':
    main()
