"""`run --check FILE...`: read each experiment file as a run would, without starting the graph,
print what the run will use of its part and grasps and what it will run (each experiment's
iterations, a sensitivity's scenarios and the repeats they add, the feeder's cycle of moves
when a feeder runs), and draw the part sheet
(analysis/part_sheet.py) beside it, so that a wrong file is seen before it runs. With
--output DIR, DIR/check.json holds the part's account and each grasp's figures and verdicts
(part_sheet.write_check; DIR/<id>_check.json per file when there are several)."""

import os
import sys

from pick_common.errors import InvalidArgument
from pick_common.specs import CENTRE, FIXED, MOVES, RANDOM, Vibration

from .. import experiment_file
from ..analysis import part_sheet
from ..experiment_file.board import (
    Board,
    cut_side_by_side,
    load_board,
    record,
    settle,
    table,
    write_parts,
)
from ..experiment_file.kinds import kind_of
from ..experiment_file.model import ExperimentFile
from ..experiment_file.part import NoGrasp
from ..experiment_file.plan import count_iterations, experiment_iterations
from .boards import write_answer


def check(paths: list[str], output: str | None, iterations: int | None = None,
          adaptive: bool = False, workers: int = 1) -> int:
    """0 when every file reads and its sheet is drawn; 2 at the first file that does not (its
    errors printed, each naming the file, the key, the value and the rule). `iterations` and
    `adaptive` as the run's options: the plan printed is the one the run would follow; a
    board's parts are cut on up to `workers` processes (board.cutting)."""
    for given in paths:
        path = os.path.abspath(given)
        try:
            board = load_board(path)
        except InvalidArgument as exc:
            print(f'run --check: {path}: {exc}', file=sys.stderr)
            return 2
        if board is not None:
            check_board(board, output, iterations, adaptive, workers)
            continue
        try:
            file = _capped(experiment_file.load(path), path, iterations, adaptive)
        except InvalidArgument as exc:
            errors = exc.errors if isinstance(exc, experiment_file.InvalidFile) else [exc]
            for e in errors:
                print(f'run --check: {path}: {e}', file=sys.stderr)
            _no_grasp(errors, path, output)
            return 2
        _check_file(file, path, output,
                    'check.json' if len(paths) == 1 else f'{file.id}_check.json')
    return 0


def _capped(file: ExperimentFile, path: str, iterations: int | None,
            adaptive: bool) -> ExperimentFile:
    """`file` as the run's options make it: read again from its reduced text when
    --iterations or --adaptive change it, else as it is (read once)."""
    if iterations is None and not adaptive:
        return file
    return experiment_file.parse(experiment_file.reduced(file, iterations, adaptive), path)


def _check_file(file: ExperimentFile, path: str, output: str | None, name: str) -> None:
    """What the run will use of the read `file` (at `path`) and what it will run, printed;
    its part sheet drawn, and with `output`, its figures written to <output>/`name`."""
    checks = part_sheet.validator(file)
    print(f'{path}: reads as a run would')
    print('\n'.join(part_sheet.describe(file, checks)))
    for gripper, mine, theirs in part_sheet.named_grippers(file, checks):
        print(f'  gripper {gripper!r} (grippers.{gripper}), for the experiments that name it:')
        print('\n'.join('  ' + line for line in part_sheet.grasp_lines(mine, theirs)))
    directory = os.path.abspath(os.path.expanduser(output or file.output_dir))
    sheet = part_sheet.write(checks, os.path.join(directory, f'{file.id}_part.png'))
    print(f'sheet: {sheet}')
    if output:          # one file: DIR/check.json; several: DIR/<id>_check.json
        print('figures: ' + part_sheet.write_check(file, checks, os.path.join(directory, name)))
    print('\n'.join(describe_plan(file)))


def _no_grasp(errors: list[InvalidArgument], path: str, output: str | None) -> None:
    """For a part `grasps: auto` found no grasp on: its account and the sheet of the part
    alone (what it is, where its mass centre lies, what collides), to write its grasps from."""
    found = next((e for e in errors if isinstance(e, NoGrasp)), None)
    if found is None:
        return
    part = found.geometry
    print(f'{path}: no grasp found; the part as the run would read it:')
    print('\n'.join(part_sheet.part_lines(part) + part_sheet.aspect_lines(part)))
    directory = os.path.abspath(os.path.expanduser(output or os.path.dirname(path)))
    stem = os.path.splitext(os.path.basename(path))[0]
    print('sheet: ' + part_sheet.write_part(part, os.path.join(directory, f'{stem}_part.png')))


def check_board(board: Board, output: str | None, iterations: int | None,
                adaptive: bool, workers: int = 1) -> None:
    """A board's check: each part's experiment file written beside the sheets
    (<output>/<board id>_parts/) and checked as a file of its own; a part whose file does
    not read is refused with its error, and the rest go on; then the board's table."""
    directory = os.path.abspath(os.path.expanduser(output or board.output_dir))
    files = write_parts(board, os.path.join(directory, f'{board.id}_parts'))
    cut_side_by_side(list(files.values()), workers)
    said, left = {}, {}
    for name, part_file in files.items():
        print(f'--- {name} ({part_file})')
        try:
            file, dropped = settle(part_file)
            file = _capped(file, part_file, iterations, adaptive)
        except InvalidArgument as exc:
            errors = exc.errors if isinstance(exc, experiment_file.InvalidFile) else [exc]
            for e in errors:
                print(f'run --check: {part_file}: {e}', file=sys.stderr)
            _no_grasp(errors, part_file, os.path.join(directory, name) if output else None)
            said[name] = f'refused: {errors[0]}'
            continue
        _check_file(file, part_file, os.path.join(directory, name) if output else None,
                    'check.json')
        left[name] = dropped
        said[name] = 'checked: ' + board.masses[name].split(':')[0] + ''.join(
            f'; {g} left out: {why}' for g, why in dropped.items())
    print('\n'.join(table(board, said)))
    print(f'board: {write_answer(record(board, said, {}, left), directory, board.id)}')


def describe_plan(file: ExperimentFile) -> list[str]:
    """What the run will do, one experiment a line, in the order it runs them: its iterations
    (at most, when sampling is adaptive); a sensitivity's inputs and scenarios, and the repeats
    they add (each an experiment of its own, `<id>@<scenario>`, listed under it)."""
    adaptive = file.sampling.mode == experiment_file.ADAPTIVE
    at_most = 'at most ' if adaptive else ''
    own = [e for e in file.experiments if e.scenario is None]     # not a sensitivity's repeat
    lines = [f'plan: {len(own)} experiment(s), '
             f'{at_most}{count_iterations(file)} iterations'
             + (' (sampling adaptive: each stops once its decision is settled)' if adaptive
                else '')]
    for exp in own:
        if not kind_of(exp).repeats_others:
            lines.append(f'  {exp.id} ({exp.type}): {at_most}{experiment_iterations(exp)} '
                         'iterations')
            continue
        added = [file.experiment(f'{e}@{s.name}') for s in exp.scenarios for e in exp.of]
        lines.append(f'  {exp.id} (sensitivity of {", ".join(exp.of)}): '
                     f'{len(exp.inputs)} input(s), {len(exp.scenarios)} scenario(s), '
                     f'{len(added)} repeat(s) of {at_most}'
                     f'{sum(experiment_iterations(e) for e in added)} iterations')
        for s in exp.scenarios:
            values = ', '.join(f'{name} {value:g}' for name, value in s.values)
            lines.append(f'    {s.name}: {values}')
    if any(kind_of(e).feeds for e in own):
        lines.append('feeder cycle, one vibration: ' + ', '.join(describe_move(m)
                                                                for m in file.moves))
    return lines


DIRECTION_WORDS = {FIXED: 'as given', RANDOM: 'turned to a random direction',
                   CENTRE: "toward the tray's centre"}


def describe_move(move: Vibration) -> str:
    """A move by its name in MOVES when it is one, and its stroke, frequency, duration and
    direction: 'flip (0, 0, 1.4 mm at 26 Hz for 0.5 s, as given)'."""
    name = next((n for n, m in MOVES.items() if m == move), 'own move')
    stroke = ', '.join(f'{a * 1000:g}' for a in move.amplitude)
    span = (f"up to {move.duration:g} s by the parts' offset" if move.direction == CENTRE
            else f'{move.duration:g} s')
    return (f'{name} ({stroke} mm at {move.frequency:g} Hz for {span}, '
            f'{DIRECTION_WORDS[move.direction]})')
