"""`run` on a board: a board file (or `run --board FILE.kicad_pcb` with the built-in cell,
config/board_cell.yaml) becomes its parts' experiment files, run in turn; at the end, the
board's one answer (experiment_file.board.answer)."""

import argparse
from dataclasses import dataclass, field
import os
import sys

from pick_common.errors import InvalidArgument
import yaml

from ..experiment_file.board import answer, Board, load_board, settle, table, write_parts


@dataclass
class BoardRun:
    """A board being run: the board, what became of each part before the run (`said`), the
    part by its file's path, and each part's options as the run decided them."""
    board: Board
    said: dict[str, str]
    by_path: dict[str, str]
    decided: dict[str, list[tuple[str, str, str]]] = field(default_factory=dict)
    left: dict[str, dict[str, str]] = field(default_factory=dict)

    def lines(self) -> list[str]:
        return answer(self.board, self.said, self.decided, self.left)


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
        run = BoardRun(board, {}, {})
        for name, path in write_parts(board, os.path.join(directory,
                                                          f'{board.id}_parts')).items():
            try:
                _, dropped = settle(path)
            except InvalidArgument as exc:
                run.said[name] = f'refused: {exc}'
                continue
            run.said[name] = 'to run' + ''.join(f'; {g} left out: {why}'
                                                 for g, why in dropped.items())
            run.by_path[path] = name
            run.left[name] = dropped
            out.append(path)
        print('\n'.join(table(board, run.said)), file=sys.stderr)
        if not run.by_path:
            raise InvalidArgument(given, board.path, 'has no part that can be decided (the '
                                  'table above says why of each)')
        boards.append(run)
    return out


def record(boards: list[BoardRun], path: str, options: list[tuple[str, str, str]]) -> None:
    """A part's options as its run decided them, for its board's answer."""
    for run in boards:
        if path in run.by_path:
            run.decided[run.by_path[path]] = options
