"""A board's page: its one answer (experiment_file.board.record) as Markdown and HTML, a row
per distinct part with each option's verdict and the best, then per part its sheet (the
part.png of its run) beside what decided each option, and the parts not decided and why."""

import os

from ...experiment_file.board.answer import absent, shown
from .page import to_html


def board_markdown(record: dict, directory: str) -> str:
    """The page's Markdown; links and images relative to `directory`, where it is written."""
    parts = record['parts']
    options = list(dict.fromkeys(o['option'] for p in parts for o in p['options']))
    lines = [f"# Board {os.path.basename(record['board'])}", '',
             f"{record['boards_per_hour']:g} boards per hour; each part's requirement is that "
             'times its quantity per board. The best option is the first feasible one in the '
             "cell's order (cheapest first).", '']
    if options:
        lines += ['| part | qty | references | ' + ' | '.join(options) + ' | best |',
                  '| --- | --- | --- | ' + ' | '.join('---' for _ in options) + ' | --- |']
        for p in parts:
            if p['status'] != 'decided':
                continue
            got = {o['option']: shown(o['verdict'], p['left_out']) for o in p['options']}
            lines.append(f"| {p['name']} | {p['quantity']} | "
                         f"{' '.join(p['references'])} | "
                         + ' | '.join(f'**{got[o]}**' if o in got
                                      else absent(o, p['left_out']) or '-' for o in options)
                         + f" | {p['best'] or 'none'} |")
        lines.append('')
    for p in parts:
        if p['status'] != 'decided':
            continue
        lines += [f"## {p['name']}", '',
                  f"{p['quantity']} per board ({', '.join(p['references'])}); model "
                  f"`{os.path.basename(p['model'])}`; mass {p['mass']}.", '']
        run = p['run']
        if run:
            rel = os.path.relpath(run, directory)
            lines += [f'![the part, its pieces and its grasps]({rel}/part.png)', '',
                      f'Its run: [{os.path.basename(run)}]({rel}/report.html).', '']
        for o in p['options']:
            verdict = shown(o['verdict'], p['left_out'])
            lines.append(f"- {o['option']}: **{verdict}**"
                         + (' (below)' if verdict != o['verdict'] else f": {o['reason']}"))
        lines += [f'- {what} left out: {why}' for what, why in p['left_out'].items()]
        lines.append('')
    others = [p for p in parts if p['status'] != 'decided']
    if others:
        lines += ['## Not decided', '', '| part | qty | references | status | why |',
                  '| --- | --- | --- | --- | --- |']
        lines += [f"| {p['name']} | {p['quantity']} | {' '.join(p['references'])} | "
                  f"{p['status']} | {p['reason'].replace('|', '/')} |" for p in others]
    return '\n'.join(lines) + '\n'


def write_board_page(record: dict, directory: str, stem: str) -> str:
    """The page written as <stem>.md and <stem>.html in `directory`; the HTML's path."""
    text = board_markdown(record, directory)
    with open(os.path.join(directory, f'{stem}.md'), 'w', encoding='utf-8') as f:
        f.write(text)
    path = os.path.join(directory, f'{stem}.html')
    with open(path, 'w', encoding='utf-8') as f:
        f.write(to_html(text, f"Board {os.path.basename(record['board'])}"))
    return path
