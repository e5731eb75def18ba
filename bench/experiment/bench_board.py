"""A board through the graph twice, in one run: with one worker and with two (issue 63's "the
same board on two workers against one"), or with its parts one after another and two at once
(`--workers 2 2 --at-once 1 2`). The `run` command on the board each time; each part's span and
iterations, the workers' busy share (the iterations' wall time over span x workers), the
board's span (its first part's start to its last part's summary) and the two runs' ratio, and
whether each part's result files and options' verdicts are identical (they must be: the graph
gives the answer of the cores with any number of workers, and parts side by side change no
result). With parts at once their spans overlap: the board's span is the measure.

    tools/ws python -m bench.experiment.bench_board (BOARD.yaml | --board FILE.kicad_pcb
        [--models DIR] [--boards-per-hour N]) [--iterations N] [--workers A B]
        [--at-once A B]

--iterations N caps every experiment of every part at N iterations (as `run --iterations`
does): a board's full decision takes hours a part (docs/boards.md), so the ratio is measured
on the first iterations of the same plan.
"""

import argparse
import glob
import json
import os
import subprocess
import sys
import tempfile
import time

from experiment_manager.analysis.rows import FILES
from experiment_manager.commands.launcher import executable

from bench.experiment.bench_experiment import per_type, rows, run_span, span_times


def board_run(args: argparse.Namespace, work: str, workers: int, at_once: int
              ) -> tuple[dict, float]:
    """`run` on the board with `workers` workers and `at_once` parts at once into
    work/w<workers>a<at_once>: (its board JSON, the command's wall time, s)."""
    out = os.path.join(work, f'w{workers}a{at_once}')
    given = [args.board_file] if args.board_file else ['--board', args.board]
    if args.models:
        given += ['--models', args.models]
    if args.boards_per_hour is not None:
        given += ['--boards-per-hour', str(args.boards_per_hour)]
    if args.iterations is not None:
        given += ['--iterations', str(args.iterations)]
    start = time.perf_counter()
    done = subprocess.run([executable('experiment_manager', 'run'), *given, '--output', out,
                           '--namespace', f'/bench_board_{os.getpid()}_{workers}_{at_once}',
                           '--workers', str(workers), '--at-once', str(at_once)],
                          capture_output=True, text=True)
    wall = time.perf_counter() - start
    if done.returncode != 0:
        sys.exit(f'run --workers {workers} failed ({done.returncode}):\n{done.stderr[-3000:]}')
    answers = glob.glob(os.path.join(out, '*_board.json'))
    if len(answers) != 1:
        sys.exit(f'run --workers {workers}: expected one board answer in {out}, found {answers}')
    with open(answers[0], encoding='utf-8') as f:
        return json.load(f), wall


def busy(run_dir: str) -> float:
    """The summed wall time of a part's iterations, s."""
    return sum(per_type(run_dir)[0].values())


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('board_file', nargs='?', help='a board experiment file (board:)')
    parser.add_argument('--board', metavar='FILE.kicad_pcb',
                        help='a KiCad board in the built-in cell (run --board)')
    parser.add_argument('--models', metavar='DIR', help="KiCad's 3D library (run --models)")
    parser.add_argument('--boards-per-hour', type=float, metavar='N')
    parser.add_argument('--iterations', type=int, metavar='N',
                        help='cap every experiment of every part at N iterations')
    parser.add_argument('--workers', type=int, nargs=2, default=[1, 2], metavar=('A', 'B'))
    parser.add_argument('--at-once', type=int, nargs=2, default=[2, 2], metavar=('A', 'B'),
                        help='parts at once in each run (run --at-once; default 2 2)')
    args = parser.parse_args()
    if bool(args.board_file) == bool(args.board):
        parser.error('give a board experiment file or --board FILE.kicad_pcb, one of them')
    os.environ.setdefault('ROS_DOMAIN_ID', str(150 + os.getpid() % 50))
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    work = tempfile.mkdtemp(prefix='bench_board_')
    (a, b), (at_a, at_b) = args.workers, args.at_once
    (board_a, wall_a), (board_b, wall_b) = (board_run(args, work, a, at_a),
                                            board_run(args, work, b, at_b))
    parts_b = {p['name']: p for p in board_b['parts']}
    identical = True
    print(f'{board_a["board"]}: {len(board_a["parts"])} part(s); {a} worker(s), {at_a} part(s) '
          f'at once against {b} and {at_b}; spans from the first iteration to the last '
          'summary, s')
    print(f'  {"part":48s} {"iter.":>5s} {f"span, {a}":>9s} {f"span, {b}":>9s} {"ratio":>6s} '
          f'{f"busy, {b}":>8s}  verdicts')
    total_a = total_b = work_b = 0.0
    spans_a, spans_b = [], []
    for p in board_a['parts']:
        q = parts_b.get(p['name'], {})
        if not p.get('run') or not q.get('run'):
            print(f'  {p["name"][:48]:48s} {p["status"]}: {p["reason"][:60]}')
            continue
        same_files = all(rows(p['run'], name, ('wall_time',)) == rows(q['run'], name,
                                                                         ('wall_time',))
                         for name in FILES)
        same_verdicts = p['options'] == q['options']
        identical &= same_files and same_verdicts
        spans_a.append(span_times(p['run']))
        spans_b.append(span_times(q['run']))
        span_a, span_b, busy_b = run_span(p['run']), run_span(q['run']), busy(q['run'])
        total_a, total_b, work_b = total_a + span_a, total_b + span_b, work_b + busy_b
        n = sum(per_type(p['run'])[1].values())
        verdicts = ' '.join(f'{o["option"]}:{o["verdict"]}' for o in p['options'])
        print(f'  {p["name"][:48]:48s} {n:5d} {span_a:9.1f} {span_b:9.1f} '
              f'{span_a / span_b:6.2f} {busy_b / (span_b * b):8.0%}  {verdicts}'
              + ('' if same_files and same_verdicts else '  DIFFERENT'))
    if total_b:
        print(f'  {"all parts, their spans summed":48s} {"":5s} {total_a:9.1f} {total_b:9.1f} '
              f'{total_a / total_b:6.2f} {work_b / (total_b * b):8.0%}')
        whole_a = max(e for _, e in spans_a) - min(s for s, _ in spans_a)
        whole_b = max(e for _, e in spans_b) - min(s for s, _ in spans_b)
        print(f'  {"the board, first part begun to last ended":48s} {"":5s} {whole_a:9.1f} '
              f'{whole_b:9.1f} {whole_a / whole_b:6.2f} {work_b / (whole_b * b):8.0%}')
    print(f'the whole command (reading the board, starting the processes, the reports): '
          f'{a} worker(s) {wall_a:.1f} s, {b} worker(s) {wall_b:.1f} s, ratio '
          f'{wall_a / wall_b:.2f}')
    print(f"each part's result files and verdicts identical (wall times aside): {identical}")
    return 0 if identical else 1


if __name__ == '__main__':
    sys.exit(main())
