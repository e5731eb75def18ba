"""Does adaptive sampling reach the fixed counts' decisions, and in how much less time? Runs
experiments of a test-case file on the cores with fixed counts and with adaptive sampling side by
side (a process each, the same seeds), and prints each experiment's decision, the iterations
run and the wall time of both, with the ratio.

    tools/ws python -m bench.experiment.bench_adaptive [--file pth0.yaml] [--experiments bins]
        [--iterations N] [--batch 5]

--experiments: ids of the file's experiments, run in the file's order (an experiment that
takes its bin or range from another needs that one listed too); --iterations caps every
experiment (the fixed run's count and the adaptive run's most).
"""

import argparse
import multiprocessing
import os
import tempfile
import time

from experiment_manager.analysis.results import ResultsWriter
from experiment_manager.analysis.verdicts import verdicts
from experiment_manager.running.local_backend import LocalBackend
from experiment_manager.running.scheduler import Runner
import yaml

from bench.paper_case import TEST_CASE, variant


def run(args: tuple[str, list[dict], dict]) -> tuple[dict, float]:
    part_file, experiments, sampling = args
    file = variant(part_file, experiments, sampling=sampling)
    with tempfile.TemporaryDirectory() as out, LocalBackend() as backend, \
            ResultsWriter(out, file.text) as writer:
        start = time.perf_counter()
        summary = Runner(file, [backend], writer).run()
        return summary, time.perf_counter() - start


def decision(s) -> str:
    kind = s.type
    if kind == 'bin_static':
        return f'best bin {s.best_bin_mm} mm'
    if kind == 'table_sweep':
        return f'n* {s.n_star}, range {s.optimal_range}'
    if kind == 'gripper_sweep':
        return f'smallest meeting: variant {s.smallest}'
    done, (low, high) = ((s.accepted, s.accepted_ci95) if kind == 'feeder_emptying'
                         else (s.emptied, s.emptied_ci95))
    return f'{done} of {s.iterations} succeeded, 95 % interval [{low:.3f}, {high:.3f}]'


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--file', default='pth0.yaml')
    parser.add_argument('--experiments', default='bins')
    parser.add_argument('--iterations', type=int)
    parser.add_argument('--batch', type=int, default=5)
    args = parser.parse_args()
    with open(os.path.join(TEST_CASE, args.file), encoding='utf-8') as f:
        data = yaml.safe_load(f)
    wanted = args.experiments.split(',')
    experiments = [e for e in data['experiments'] if e['id'] in wanted]
    if args.iterations:
        experiments = [{**e, 'iterations': min(e['iterations'], args.iterations)}
                       for e in experiments]
    jobs = [(args.file, experiments, {'mode': mode, 'batch': args.batch})
            for mode in ('fixed', 'adaptive')]
    with multiprocessing.Pool(2) as pool:
        (fixed, fixed_wall), (adaptive, adaptive_wall) = pool.map(run, jobs, chunksize=1)
    print(f'{args.file}, experiments {args.experiments}, batch {args.batch}: fixed counts '
          f'{fixed_wall / 60:.1f} min, adaptive {adaptive_wall / 60:.1f} min '
          f'(ratio {adaptive_wall / fixed_wall:.2f}), a core each, side by side')
    for exp_id, s in fixed.experiments.items():
        a = adaptive.experiments[exp_id]
        same = 'same' if decision(a).split(',')[0] == decision(s).split(',')[0] else 'DIFFERS'
        if s.type in ('feeder_emptying', 'bin_emptying'):
            same = 'see verdicts'
        print(f'  {exp_id}: fixed {decision(s)} | adaptive {decision(a)}, '
              f'{a.sampling.iterations_run} of {a.sampling.most} iterations, '
              f'{"settled" if a.sampling.settled else "not settled"} | {same}')
    for f, a in zip(verdicts(fixed), verdicts(adaptive), strict=True):
        print(f'  verdict {f.option}: fixed {f.verdict} | adaptive {a.verdict}')


if __name__ == '__main__':
    main()
