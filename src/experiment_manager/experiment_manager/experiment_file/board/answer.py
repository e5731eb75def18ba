"""A board's one answer, in words (`answer`: the terminal's table) and as data (`record`:
`<output>/<board id>_board.json`), from what became of each of its parts."""

from collections.abc import Mapping
import os
from typing import TYPE_CHECKING

from .parts import DECIDE, REFUSED

if TYPE_CHECKING:
    from . import Board


SHORT = {'FEASIBLE': 'yes', 'NOT FEASIBLE': 'no', 'UNDECIDED': '?', 'not analysed': '-',
         'left out': 'out'}


def absent(option: str, left_out: Mapping[str, str]) -> str:
    """An option a part's run does not list: 'left out' when it is of a gripper left out for
    the part (`left_out`, settle's, a key 'gripper <name>': none of that gripper's experiments
    ran; an option of it ends ', gripper <name>'), else ''. A left-out experiment's id is no
    gripper, whatever option's name it happens to be part of."""
    return 'left out' if any(g.startswith('gripper ') and option.endswith(f', {g}')
                             for g in left_out) else ''


def shown(verdict: str, left_out: Mapping[str, str]) -> str:
    """An option's verdict as the board says it: an option a part's run did not analyse
    because its experiment was left out for the part (`left_out`, settle's) is 'left out'."""
    return 'left out' if verdict == 'not analysed' and left_out else verdict


def answer(board: 'Board', said: Mapping[str, str],
           decided: Mapping[str, list[tuple[str, str, str]]],
           left: Mapping[str, Mapping[str, str]] | None = None) -> list[str]:
    """The board's one answer: a row per distinct part (its quantity, references, each
    option's verdict, the best option), then per part what stops each option that is not
    feasible. `decided`: per part that ran, its options in the run's order as (option,
    verdict, the first reason); `said`: what became of the others; `left`: per part, the
    grippers and experiments left out for it (`settle`) and why. The best option is the
    first feasible one in the run's order, which lists the cheapest cell first: a static bin
    before a bin with a regrasp station before a vibrating table, the file's gripper before
    its named ones."""
    options = list(dict.fromkeys(o for rows in decided.values() for o, _, _ in rows))
    head = ['part', 'qty', 'references', *[f'[{i + 1}]' for i in range(len(options))], 'best']
    rows, notes = [], []
    for p in board.parts:
        gone = (left or {}).get(p.name, {})
        got = {o: (shown(v, gone), why) for o, v, why in decided.get(p.name, [])}
        cells = [SHORT.get(got[o][0], got[o][0]) if o in got else
                 SHORT.get(absent(o, gone), '') if p.name in decided else '' for o in options]
        best = next((f'[{i + 1}]' for i, o in enumerate(options)
                     if got.get(o, ('',))[0] == 'FEASIBLE'), '')
        if p.name not in decided:
            best = said.get(p.name) or (p.status + (f': {p.reason}' if p.reason else ''))
        refs = ' '.join(p.references)
        rows.append([p.name, str(p.quantity), refs if len(refs) <= 28 else refs[:25] + '...',
                     *cells, best or 'none'])
        notes += [f'  {p.name} [{options.index(o) + 1}] {v}: {why}'
                  for o, (v, why) in got.items() if v not in ('FEASIBLE', 'left out')]
        notes += [f'  {p.name}: {what} left out: {why}' for what, why in gone.items()]
    width = [max(len(r[i]) for r in [head, *rows]) for i in range(len(head) - 1)]
    lines = [f'board {os.path.basename(board.path)}: {board.boards_per_hour:g} boards per '
             'hour; verdicts yes, no, ? (undecided), - (not analysed), out (left out for the '
             'part, said below)']
    lines += ['  ' + '  '.join(c.ljust(w) for c, w in zip(r[:-1], width, strict=True))
              + '  ' + r[-1] for r in [head, *rows]]
    lines += [f'  [{i + 1}] {o}' for i, o in enumerate(options)]
    return lines + (['what stops the options not feasible:'] + notes if notes else [])


def record(board: 'Board', said: Mapping[str, str],
           decided: Mapping[str, list[tuple[str, str, str]]],
           left: Mapping[str, Mapping[str, str]] | None = None,
           runs: Mapping[str, str] | None = None,
           shas: Mapping[str, str] | None = None) -> dict:
    """The board's answer as data (`<output>/<board id>_board.json`, its model and schema in
    `board_json`): per distinct part its model, references, quantity, status with its reason,
    its mass's account, what was left out for it and why, its run directory, the SHA-256 of
    the experiment file it ran (a board run again keeps a part done only when its file is the
    same), and its options' verdicts with the first reason and the best option (`answer`'s
    rule)."""
    # the records' module is also a command (it writes their schema): loaded here, not above
    from .board_json import BOARD_JSON_VERSION, BoardOption, BoardPartRecord, BoardRecord
    parts = []
    for p in board.parts:
        options = [BoardOption(option=o, verdict=v, reason=why)
                   for o, v, why in decided.get(p.name, [])]
        status = p.status
        if p.name in decided:
            status = 'decided'
        elif p.status == DECIDE:
            status = REFUSED if said.get(p.name, '').startswith('refused') else 'not run'
        reason = p.reason or (said.get(p.name, '') if status == REFUSED else '')
        parts.append(BoardPartRecord(
            name=p.name, model=p.step or (p.model.path if p.model else ''),
            references=list(p.references), quantity=p.quantity, status=status,
            reason=reason.removeprefix('refused: '), mass=board.masses.get(p.name, ''),
            left_out=dict((left or {}).get(p.name, {})), run=(runs or {}).get(p.name, ''),
            file_sha256=(shas or {}).get(p.name, ''), options=options,
            best=next((o.option for o in options if o.verdict == 'FEASIBLE'), None)))
    return BoardRecord(board_json_version=BOARD_JSON_VERSION, board=board.path, id=board.id,
                       boards_per_hour=board.boards_per_hour, parts=parts).model_dump()
