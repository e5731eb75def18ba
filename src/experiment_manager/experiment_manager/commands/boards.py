"""`run` on a board: a board file (or `run --board FILE.kicad_pcb` with the built-in cell,
config/board_cell.yaml) becomes its parts' experiment files, run in turn; at the end, the
board's one answer (experiment_file.board.answer)."""

import argparse
from dataclasses import dataclass, field
import hashlib
import json
import os
import sys

from pick_common.errors import InvalidArgument
import yaml

from ..analysis.redecide import redecide
from ..analysis.report.board import write_board_page
from ..analysis.summary import Summary
from ..analysis.verdicts import verdicts
from ..experiment_file.board import (
    answer,
    Board,
    cut_side_by_side,
    load_board,
    record,
    settle,
    table,
    write_parts,
)
from ..experiment_file.model import ExperimentFile


@dataclass
class BoardRun:
    """A board being run: the board, what became of each part before the run (`said`), the
    part by its file's path, each part's file as `settle` read it by its path (`read`: the
    run's check reads it no more), and each part's options as the run decided them."""
    board: Board
    said: dict[str, str]
    by_path: dict[str, str]
    decided: dict[str, list[tuple[str, str, str]]] = field(default_factory=dict)
    left: dict[str, dict[str, str]] = field(default_factory=dict)
    runs: dict[str, str] = field(default_factory=dict)
    shas: dict[str, str] = field(default_factory=dict)
    read: dict[str, ExperimentFile] = field(default_factory=dict)
    directory: str = ''

    def lines(self) -> list[str]:
        return answer(self.board, self.said, self.decided, self.left)

    def write(self) -> str:
        """The board's answer written (`write_answer`); the data's path."""
        return write_answer(record(self.board, self.said, self.decided, self.left, self.runs,
                                   self.shas), self.directory, self.board.id)


def write_answer(data: dict, directory: str, board_id: str) -> str:
    """A board's answer (`record`'s data) as <directory>/<board id>_board.json and as a
    page, <board id>_board.html (analysis/report/board.py); the data's path."""
    path = os.path.join(directory, f'{board_id}_board.json')
    with open(path, 'w', encoding='utf-8') as f:
        json.dump(data, f, indent=1)
    write_board_page(data, directory, f'{board_id}_board')
    return path


def cell_file(share: str) -> str:
    """The built-in cell a bare board runs in."""
    return os.path.join(share, 'config', 'board_cell.yaml')


def board_file(pcb: str, models: str | None, boards_per_hour: float | None, cell: str,
               directory: str) -> str:
    """The board file of `run --board`: the built-in cell with the board named, written into
    `directory` (the run's output), its path returned."""
    with open(cell, encoding='utf-8') as f:
        data = yaml.safe_load(f)
    data['board']['pcb'] = os.path.abspath(pcb)
    if models is not None:
        data['board']['models'] = os.path.abspath(models)
    if boards_per_hour is not None:
        data['board']['boards_per_hour'] = boards_per_hour
    stem = os.path.splitext(os.path.basename(pcb))[0]
    data['id'] = ''.join(c if c.isalnum() or c in '_-' else '_' for c in stem)[:48] or 'board'
    os.makedirs(directory, exist_ok=True)
    path = os.path.join(directory, f'{data["id"]}_board.yaml')
    with open(path, 'w', encoding='utf-8') as f:
        f.write(f'# run --board {pcb}: the built-in cell ({cell}) with this board\n'
                + yaml.safe_dump(data, sort_keys=False))
    return path


def expand_boards(files: list[str], args: argparse.Namespace,
                  boards: list[BoardRun]) -> list[str]:
    """The files to run: each board file in `files` replaced by its parts' experiment files
    (written into <output>/<board id>_parts/, whose runs go beside), each read as a run reads
    it (`settle`: a named gripper that cannot pick a part leaves its options out for that
    part); the board's table printed. A part whose file does not read is refused with its
    error, and the others run. Each board run is added to `boards`."""
    out = []
    for given in files:
        board = load_board(os.path.abspath(given))
        if board is None:
            out.append(given)
            continue
        directory = os.path.abspath(os.path.expanduser(args.output or board.output_dir))
        run = BoardRun(board, {}, {}, directory=directory)
        done = _done_before(os.path.join(directory, f'{board.id}_board.json'))
        files = write_parts(board, os.path.join(directory, f'{board.id}_parts'))
        cut_side_by_side(list(files.values()), args.workers)
        for name, path in files.items():
            try:
                file, dropped = settle(path)
            except InvalidArgument as exc:
                run.said[name] = f'refused: {exc}'
                continue
            with open(path, 'rb') as f:
                run.shas[name] = hashlib.sha256(f.read()).hexdigest()
            run.left[name] = dropped
            before = done.get(name)
            kept = (options_of(before['run']) if before is not None
                    and before['file_sha256'] == run.shas[name] else None)
            if kept is not None:
                run.decided[name] = kept
                run.runs[name] = before['run']
                run.said[name] = f'done before: {before["run"]}'
                continue
            run.said[name] = 'to run' + ''.join(f'; {g} left out: {why}'
                                                 for g, why in dropped.items())
            run.by_path[path] = name
            run.read[path] = file
            out.append(path)
        print('\n'.join(table(board, run.said)), file=sys.stderr)
        run.write()
        if not run.by_path and not run.decided:
            raise InvalidArgument(given, board.path, 'has no part that can be decided (the '
                                  'table above says why of each)')
        boards.append(run)
    return out


def options(summary: Summary) -> list[tuple[str, str, str]]:
    """A part's options from its run's summary, as the board's answer lists them: (option,
    verdict, the first reason)."""
    return [(v.kind, v.verdict, v.reasons[0]) for v in verdicts(summary)]


def options_of(run_dir: str) -> list[tuple[str, str, str]] | None:
    """A part decided before: its options as today's decisions give them from its run
    directory's records (redecide), so that a board run again after an update answers by
    today's rules, not by those its parts ran under; None when the directory no longer
    reads (the part runs again)."""
    try:
        return options(redecide(run_dir))
    except (InvalidArgument, ValueError, OSError):
        return None


def interrupted(directory: str, file_id: str, path: str) -> str | None:
    """The newest run directory in `directory` of the file at `path` (id `file_id`: a board's
    part not decided before, as it is to run): it holds iterations.csv, and its
    experiment.yaml is the file's text to the byte (a run resumes only the file it ran). Its
    summary.json says nothing here: a run rewrites it after each experiment, so an interrupted
    one has it too; and resuming a run that had finished only summarises it again. None when
    there is none: the part runs anew."""
    with open(path, 'rb') as f:
        text = f.read()
    try:
        names = sorted(os.listdir(directory), reverse=True)
    except OSError:
        return None
    for name in names:
        run_dir = os.path.join(directory, name)
        if not name.startswith(f'{file_id}_') or not os.path.isfile(
                os.path.join(run_dir, 'iterations.csv')):
            continue
        try:
            with open(os.path.join(run_dir, 'experiment.yaml'), 'rb') as f:
                if f.read() == text:
                    return run_dir
        except OSError:
            continue
    return None


def _done_before(path: str) -> dict[str, dict]:
    """The parts an earlier run of the board decided (its <id>_board.json at `path`), by
    name, each whose run directory still holds its summary.json; {} when there is none."""
    try:
        with open(path, encoding='utf-8') as f:
            parts = json.load(f)['parts']
    except (OSError, ValueError, KeyError, TypeError):
        return {}
    return {p['name']: p for p in parts if isinstance(p, dict) and p.get('status') == 'decided'
            and p.get('file_sha256') and p.get('run')
            and os.path.isfile(os.path.join(p['run'], 'summary.json'))}


def decided(boards: list[BoardRun], path: str, options: list[tuple[str, str, str]],
            results: str) -> None:
    """A part's options as its run (in `results`) decided them, for its board's answer,
    which is written again after each part: an interrupted board keeps the parts done."""
    for run in boards:
        if path in run.by_path:
            run.decided[run.by_path[path]] = options
            run.runs[run.by_path[path]] = results
            run.write()
