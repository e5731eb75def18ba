"""Where the parts of a finished run were turned down, from its run directory: the facts behind
the comparison with the paper (docs/paper-test-case.md), measured on the run rather than
guessed.

    tools/ws python -m studies.run_stages RUN_DIR [--counts 49 80]

Prints, per experiment type present:
- table_sweep: at each count asked for (default: the paper's n* for the file's id when it is a
  test-case part, and the run's n*), the mean per check of the parts checked and of those that
  passed each stage (candidacy, placeability, container collision, neighbour collision);
- bin_static: the same for the best bin's first checks;
- bin_emptying: the parts removed, and at each iteration's last check (where no part was valid)
  the stage that turned each part in the bin down, as shares of the parts left;
- feeder_emptying: vibrations to empty (emptied runs), the share of checks that found no valid
  part, and the stage shares over every check of every run.
"""

import argparse
import collections
import csv
import json
import os
import sys

from experiment_manager.analysis.results import read_csv
from experiment_manager.analysis.rows import parse_row
from experiment_manager.analysis.verdicts import PAPER
import numpy as np
from pick_validity.results import (
    STAGE_CANDIDACY,
    STAGE_CONTAINER,
    STAGE_NEIGHBOUR,
    STAGE_PLACEABILITY,
    STAGE_VALID,
)

STAGES = ('checked', 'candidates', 'placeable', 'container_free', 'valid')
REJECTED = {STAGE_CANDIDACY: 'candidacy', STAGE_PLACEABILITY: 'placeability',
            STAGE_CONTAINER: 'container', STAGE_NEIGHBOUR: 'neighbour', STAGE_VALID: 'valid'}


def stage_means(checks: list[dict]) -> str:
    """Mean parts per check that reached each stage, as one line."""
    means = {k: np.mean([c[k] for c in checks]) for k in STAGES}
    return ', '.join(f'{k} {means[k]:.1f}' for k in STAGES) + f' ({len(checks)} checks)'


def shares(stages: list[int]) -> str:
    """The share of parts turned down at each stage (or valid), as one line."""
    n = collections.Counter(stages)
    total = sum(n.values())
    return ', '.join(f'{name} {100 * n[s] / total:.1f} %' for s, name in REJECTED.items()
                     ) + f' ({total} parts)' if total else 'no parts'


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('run_dir')
    parser.add_argument('--counts', type=int, nargs='*', default=None,
                        help='parts on the tray at which to show the sweep (default: the '
                        "paper's n* and the run's)")
    args = parser.parse_args()
    d = args.run_dir
    with open(os.path.join(d, 'summary.json')) as f:
        summary = json.load(f)
    iterations, checks = read_csv(os.path.join(d, 'iterations.csv')), read_csv(
        os.path.join(d, 'checks.csv'))
    paper = PAPER.get(summary['id'], {})
    print(f'run {d} ({summary["id"]})')
    for exp_id, s in summary['experiments'].items():
        mine = [c for c in checks if c['experiment'] == exp_id]
        rows = [r for r in iterations if r['experiment'] == exp_id]
        if s['type'] == 'table_sweep':
            counts = args.counts or sorted({c for c in (paper.get('n_star'), s['n_star'])
                                            if c is not None})
            print(f'{exp_id} (table_sweep): n* {s["n_star"]}, range {s["optimal_range"]}')
            for n in counts:
                print(f'  {n} parts: ' + stage_means([c for c in mine if c['group'] == n]))
        elif s['type'] == 'bin_static':
            best = s['bins'][s['best_bin']]
            print(f'{exp_id} (bin_static): best bin {best["size_mm"]} mm: '
                  + stage_means([c for c in mine if c['group'] == s['best_bin']]))
        elif s['type'] == 'bin_emptying':
            last = {}
            for c in mine:
                last[c['iteration']] = c['check']
            stages = [p['stage'] for p in read_parts(d, exp_id)
                      if p['inside'] and last.get(p['iteration']) == p['check']]
            removed = [r['picks'] for r in rows]
            print(f'{exp_id} (bin_emptying): removed mean {np.mean(removed):.1f}, max '
                  f'{max(removed)} of {s["parts"]}; at the last checks: {shares(stages)}')
        elif s['type'] == 'feeder_emptying':
            emptied = [r['vibrations'] for r in rows if r['emptied']]
            none = sum(c['valid'] == 0 for c in mine)
            print(f'{exp_id} (feeder_emptying): {len(emptied)} of {len(rows)} emptied, '
                  + (f'vibrations mean {np.mean(emptied):.1f}, min {min(emptied)}, max '
                     f'{max(emptied)}; ' if emptied else '')
                  + f'{100 * none / len(mine):.1f} % of {len(mine)} checks found no valid '
                  'part')
            print('  per check: ' + stage_means([c for c in mine if c['parts_on_table']]))
    return 0


def read_parts(directory: str, exp_id: str) -> list[dict]:
    """The rows of parts.csv of one experiment (the file holds millions of rows: read once,
    filtered as read)."""
    with open(os.path.join(directory, 'parts.csv'), newline='', encoding='utf-8') as f:
        return [parse_row(r) for r in csv.DictReader(f) if r['experiment'] == exp_id]


if __name__ == '__main__':
    sys.exit(main())
