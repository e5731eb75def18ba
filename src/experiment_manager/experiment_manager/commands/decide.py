"""`decide`: decide finished runs again with today's rules, and say what moved.

    decide RUN_DIR [RUN_DIR ...] [--write]

For each run directory, every experiment's summary is computed anew from the run's result
files and what it ran with (its resolved.json's records: no experiment file is read again and
no part built; analysis/redecide.py), and the headlines and verdicts are printed as `run`
prints them, each verdict that differs from the one the run's summary.json holds marked with
what it was. --write replaces summary.json (current schema version) and the report with
today's. No graph is started. Exit 0, or 2 for a directory that is not a run directory, whose
resolved.json, summary.json or result files are broken, or (a run directory whose
resolved.json keeps no records) whose experiment file no longer reads (each said with the
directory).
"""

import argparse
import os
import sys

from pick_common.errors import InvalidArgument

from ..analysis import report
from ..analysis import summary as summary_model
from ..analysis.headlines import headlines
from ..analysis.redecide import redecide
from ..analysis.results import write_summary
from ..analysis.verdicts import verdicts
from ..analysis.wording import verdict_table

RESULT_FILES = ('experiment.yaml', 'iterations.csv', 'picks.csv', 'checks.csv')


def decide(run_dir: str, write: bool) -> list[str]:
    """The lines said of one run directory; with `write`, its summary.json and report
    replaced. Raises InvalidArgument for a directory that is not a run directory."""
    missing = [n for n in RESULT_FILES if not os.path.isfile(os.path.join(run_dir, n))]
    if missing:
        raise InvalidArgument('run_dir', run_dir, 'is not a run directory: it has no '
                              + ', '.join(missing))
    path = os.path.join(run_dir, 'summary.json')
    recorded = summary_model.read(path) if os.path.exists(path) else None
    before = {v.kind: v.verdict for v in verdicts(recorded)} if recorded is not None else {}
    now = redecide(run_dir, recorded)
    rows = []
    for v in verdicts(now):
        was = before.get(v.kind)
        moved = f' [was {was}]' if was is not None and was != v.verdict else ''
        rows.append((v.option, v.verdict + moved, v.stops, v.reasons[0]))
    lines = [run_dir, *headlines(now), 'verdicts:', *verdict_table(rows)]
    if write:
        write_summary(run_dir, now)
        lines.append(f'written: {path}, {report.write(run_dir)}')
    return lines


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog='decide', description=__doc__.split('\n\n')[0])
    parser.add_argument('run_dirs', nargs='+', metavar='RUN_DIR')
    parser.add_argument('--write', action='store_true',
                        help="replace each run's summary.json and report with today's")
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    status = 0
    for run_dir in args.run_dirs:
        try:
            print('\n'.join(decide(run_dir, args.write)))
        except InvalidArgument as exc:
            print(f'decide: {exc}', file=sys.stderr)
            status = 2
        except (OSError, ValueError) as exc:    # an unreadable or broken summary.json or CSV
            print(f'decide: {run_dir}: {exc}', file=sys.stderr)
            status = 2
    return status


if __name__ == '__main__':
    sys.exit(main())
