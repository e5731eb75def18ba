"""The report of a run: the decision the engineer came for, with the figures behind it.

From a run directory (`summary.json`, `experiment.yaml`, and `pictures.json` with the pictures
of pictures.py when they were rendered) it writes
`report.md` and `report.html` (the same content) and the plots `fig14_bins.png` (fractions of
parts passing each stage per bin, paper figure 14) and `fig15_table.png` (valid parts against
parts on the tray with the 4th-order fit, paper figure 15). Tables follow the paper's Tables 2
and 3. For the paper's test-case files (ids pth0, pth1, pth2) the paper's numbers stand beside
ours, and a section "Against the paper" checks its three findings on this run and says where
and why ours differ (against_paper).

Verdicts, per option:
- static bin: feasible when every `bin_emptying` iteration emptied the bin and the bin holds a
  refill interval's parts (requirements.parts_per_hour x refill_interval_h);
- vibrating table: feasible when every `feeder_emptying` run emptied the feeder and the feeder
  held a refill interval's parts; the report gives the time per vibration this leaves.
An option whose experiment did not run is "not analysed".
"""

import html
import json
import os

import matplotlib

matplotlib.use('Agg')   # no display: files only
import matplotlib.pyplot as plt
import numpy as np
import yaml

from .metrics import FAULTS

# The paper's results (section 5) for its test case, by experiment-file id.
PAPER = {
    'pth0': {'best_bin_mm': [100, 175, 15], 'container_free': 0.2502, 'valid_first': 0.0036,
             'table2': {'iterations': 40, 'parts': 240, 'emptied': 0, 'mean': 0.8, 'min': 0,
                        'max': 4, 'std': 0.92},
             'n_star': 49, 'range': [44, 54],
             'table3': {'iterations': 50, 'parts': 240, 'emptied': 50, 'vibrations': 123.14}},
    'pth1': {'best_bin_mm': [300, 300, 26], 'container_free': 0.3477, 'valid_first': 0.0047,
             'table2': {'iterations': 40, 'parts': 480, 'emptied': 0, 'mean': 2.7, 'min': 0,
                        'max': 6, 'std': 1.67},
             'n_star': 22, 'range': [17, 27],
             'table3': {'iterations': 50, 'parts': 480, 'emptied': 50, 'vibrations': 166.96}},
    'pth2': {'best_bin_mm': [300, 300, 22], 'container_free': 0.388, 'valid_first': 0.0127,
             'table2': {'iterations': 40, 'parts': 480, 'emptied': 0, 'mean': 7.5, 'min': 2,
                        'max': 11, 'std': 2.28},
             'n_star': 27, 'range': [22, 32],
             'table3': {'iterations': 50, 'parts': 480, 'emptied': 50, 'vibrations': 139.07}},
}
FIGSIZE = (6.4, 4.0)   # inches
DIFFERS = 1.25     # a figure differs from the paper's when ours is over 1.25x or under 0.8x it
FALLS = 0.05       # past n*, the sweep's fit "falls" when it ends at least 5 % below its peak
FEASIBLE, NOT_FEASIBLE, NOT_ANALYSED = 'FEASIBLE', 'NOT FEASIBLE', 'not analysed'
# the feeder policy's stop decisions (feeder_controller.policy.NAMES), as a report says them
_STOPS = {'stop: empty': 'feeder and table empty', 'stop: vibration limit': 'vibration limit'}


def _fmt(value, digits: int = 3) -> str:
    if value is None:
        return '-'
    if isinstance(value, float):
        return f'{value:.{digits}g}'
    return str(value)


def _count(n: int, noun: str) -> str:
    """'1 part', '35 parts': the report's sentences say a count as it is read."""
    return f'{n} {noun}' + ('' if n == 1 else 's')


def _pct(value) -> str:
    return '-' if value is None else f'{100 * value:.1f} %'


def _of_type(summary: dict, kind: str) -> list[tuple[str, dict]]:
    return [(k, v) for k, v in summary['experiments'].items() if v['type'] == kind]


def verdicts(summary: dict, spec: dict) -> list[dict]:
    """The decision per option: option, verdict, and the reasons (for people)."""
    capacity = summary['requirements']['capacity']
    out = []
    emptying = _of_type(summary, 'bin_emptying')
    if emptying:
        _, s = emptying[-1]
        reasons = [f'{s["emptied"]} of {s["iterations"]} bins emptied; parts removed per bin: '
                   f'mean {_fmt(s["removed"]["mean"])}, max {_fmt(s["removed"]["max"])} '
                   f'of {s["parts"]}']
        ok = s['iterations'] > 0 and s['emptied'] == s['iterations']
        reasons += _fault_reason(s)
        if s['parts'] < capacity:
            ok = False
            reasons.append(f'the bin was filled with {s["parts"]} parts, fewer than the '
                           f'{capacity} a refill interval needs')
        out.append({'option': f'static bin {_fmt(s["bin_mm"])} mm',
                    'verdict': FEASIBLE if ok else NOT_FEASIBLE, 'reasons': reasons})
    else:
        out.append({'option': 'static bin', 'verdict': NOT_ANALYSED,
                    'reasons': ['no bin_emptying experiment in the file']})
    feeder = _of_type(summary, 'feeder_emptying')
    if feeder:
        _, s = feeder[-1]
        v = s['vibrations_to_empty']
        reasons = [f'{s["emptied"]} of {s["iterations"]} feeder runs emptied '
                   f'(optimal range {s["optimal_range"][0]}-{s["optimal_range"][1]} parts on '
                   f'the table; runs ended by: '
                   f'{", ".join(f"{_STOPS.get(k, k)} {n}" for k, n in s["stops"].items())})']
        if v['mean'] is not None:
            reasons.append(f'vibrations to empty the feeder: mean {_fmt(v["mean"], 4)}; the '
                           f'refill interval allows one vibration every '
                           f'{_fmt(s["minutes_per_vibration_allowed"])} min')
        if s['lost']:
            reasons.append(f'{_count(s["lost"], "part")} fell off the table')
        ok = s['iterations'] > 0 and s['emptied'] == s['iterations']
        reasons += _fault_reason(s)
        if s['parts'] < capacity:
            ok = False
            reasons.append(f'the feeder held {s["parts"]} parts, fewer than the {capacity} a '
                           'refill interval needs')
        out.append({'option': 'vibrating table', 'verdict': FEASIBLE if ok else NOT_FEASIBLE,
                    'reasons': reasons})
    else:
        out.append({'option': 'vibrating table', 'verdict': NOT_ANALYSED,
                    'reasons': ['no feeder_emptying experiment in the file']})
    return out


def plot_bins(summary: dict, path: str) -> bool:
    statics = _of_type(summary, 'bin_static')
    if not statics:
        return False
    _, s = statics[-1]
    bins = [b for b in s['bins'] if b['iterations']]
    area = [b['xy_area_mm2'] / 100.0 for b in bins]      # cm^2
    order = np.argsort(area)
    fig, ax = plt.subplots(figsize=FIGSIZE)
    for key, label in (('candidates', 'candidacy'), ('placeable', 'placeability'),
                       ('container_free', 'bin collision free')):
        mean = [100 * bins[i]['fractions'][key]['mean'] for i in order]
        std = [100 * bins[i]['fractions'][key]['std'] for i in order]
        ax.errorbar([area[i] for i in order], mean, yerr=std, marker='o', capsize=3,
                    label=label)
    ax.set_ylim(0, 100)
    _finish(fig, ax, path, f'{summary["id"]}: static bin analysis (figure 14)',
            'bin XY surface (cm$^2$)', 'parts passing the stage (%)')
    return True


def _finish(fig, ax, path: str, title: str, xlabel: str, ylabel: str) -> None:
    """Label, grid, legend, save and close a plot."""
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(alpha=0.3)
    ax.legend()
    ax.set_title(title)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_sweep(summary: dict, path: str) -> bool:
    sweeps = _of_type(summary, 'table_sweep')
    if not sweeps:
        return False
    _, s = sweeps[-1]
    n = np.array([p['n'] for p in s['per_n']], dtype=float)
    mean = np.array([p['valid']['mean'] for p in s['per_n']])
    fig, ax = plt.subplots(figsize=FIGSIZE)
    ax.plot(n, mean, 'o', markersize=3, label='mean valid parts')
    if 'coefficients' in s and len(n):
        grid = np.linspace(n.min(), n.max(), 200)
        ax.plot(grid, np.polyval(s['coefficients'], grid), '-',
                label=f'order-{s["order"]} fit')
        low, high = s['optimal_range']
        ax.axvspan(low, high, alpha=0.15, color='green',
                   label=f'optimal range {low}-{high} (n* = {s["n_star"]})')
    _finish(fig, ax, path, f'{summary["id"]}: vibrating table analysis (figure 15)',
            'parts on the table', 'valid parts')
    return True


def _fault_reason(s: dict) -> list[str]:
    f = s['faults']
    if not f['flagged']:
        return []
    return [f'{_count(len(f["flagged"]), "iteration")} flagged: ' + ', '.join(
        f'{k} {f[k]}' for k in FAULTS if f[k])
        + ' (see Physics faults)']


def _faults(summary: dict) -> list[str]:
    """Iterations flagged per experiment: a NaN state (left out of the figures), a settle
    that hit its cap with parts still moving, parts that left the container (both counted)."""
    rows = [[f'`{exp_id}`', len(s['faults']['flagged']), s['faults']['physics_fault'],
             s['faults']['unsettled'], s['faults']['escaped']]
            for exp_id, s in summary['experiments'].items() if s['faults']['flagged']]
    if not rows:
        return ['No iteration was flagged: every settle ended within its cap, no part left its '
                'container, no physics state became NaN.']
    return _table(['experiment', 'iterations flagged', 'physics fault (NaN; left out of the '
                   'figures)', 'unsettled at the cap (counted)', 'parts escaped (counted)'],
                  rows) + ['', 'Each flagged iteration has its fault in the `fault` column of '
                           '`iterations.csv`.']


def _table(header: list[str], rows: list[list]) -> list[str]:
    lines = ['| ' + ' | '.join(header) + ' |', '|' + ' --- |' * len(header)]
    lines += ['| ' + ' | '.join(_fmt(c) for c in r) + ' |' for r in rows]
    return lines


def markdown(summary: dict, spec: dict, figures: dict[str, bool],
             pictures: dict[str, str] | None = None) -> str:
    """The report as Markdown. pictures: {image file: caption} (pictures.py)."""
    paper = PAPER.get(summary['id'])
    part = spec.get('part', {})
    r = summary['requirements']
    lines = [f'# Picking feasibility: {summary["id"]}', '',
             f'Part `{part.get("model", "radial_capacitor")}` '
             f'{json.dumps(part.get("dimensions_mm", {}))}; gripper '
             f'{json.dumps(spec.get("gripper", {}))}; seed {summary["seed"]}.', '',
             f'Requirement: {_fmt(r["parts_per_hour"])} parts per hour, a refill every '
             f'{_fmt(r["refill_interval_h"])} h (capacity {r["capacity"]} parts), no bin longer '
             f'than {_fmt(r["max_dimension_mm"])} mm in any dimension (every bin analysed '
             'meets it: the experiment file refuses others).', '', '## Verdict', '']
    lines += _table(['option', 'verdict', 'why'],
                    [[v['option'], f'**{v["verdict"]}**', '; '.join(v['reasons'])]
                     for v in verdicts(summary, spec)])
    statics = _of_type(summary, 'bin_static')
    if statics:
        exp_id, s = statics[-1]
        lines += ['', f'## Static bins (`{exp_id}`, figure 14)', '']
        if figures.get('fig14'):
            lines += ['![figure 14](fig14_bins.png)', '']
        lines += _table(['bin (mm)', 'iterations', 'candidacy', 'placeability',
                         'bin collision free'],
                        [[' x '.join(_fmt(x) for x in b['size_mm']), b['iterations'],
                          _pct(b['fractions']['candidates']['mean']),
                          _pct(b['fractions']['placeable']['mean']),
                          _pct(b['fractions']['container_free']['mean'])]
                         for b in s['bins']])
        lines += ['', f'Best bin: {_fmt(s["best_bin_mm"])} mm.' + (
            f' Paper: {paper["best_bin_mm"]} mm, {_pct(paper["container_free"])} bin '
            'collision free.' if paper else '')]
    emptying = _of_type(summary, 'bin_emptying')
    if emptying:
        exp_id, s = emptying[-1]
        rm = s['removed']
        lines += ['', f'## Bin emptying (`{exp_id}`, Table 2)', '']
        rows = [['ours', s['iterations'], s['parts'], s['emptied'], rm['mean'], rm['min'],
                 rm['max'], rm['std']]]
        if paper:
            t = paper['table2']
            rows.append(['paper', t['iterations'], t['parts'], t['emptied'], t['mean'],
                         t['min'], t['max'], t['std']])
        lines += _table(['', 'iterations', 'parts', 'emptied bins', 'parts removed: mean',
                         'min', 'max', 'std'], rows)
        lines += ['', f'Valid at the first check (all four stages): '
                  f'{_pct(s["first_check"]["valid"]["mean"])} of the parts' + (
                      f' (paper: {_pct(paper["valid_first"])}).' if paper else '.'),
                  f'Parts looked at before each pick (search order): mean '
                  f'{_fmt(s["searches_per_pick"]["mean"])}.']
    sweeps = _of_type(summary, 'table_sweep')
    if sweeps:
        exp_id, s = sweeps[-1]
        lines += ['', f'## Vibrating table sweep (`{exp_id}`, figure 15)', '']
        if figures.get('fig15'):
            lines += ['![figure 15](fig15_table.png)', '']
        if 'n_star' in s:
            lines += [f'Fit of order {s["order"]}: the most valid parts at n* = {s["n_star"]} '
                      f'parts on the table; optimal range {s["optimal_range"][0]}-'
                      f'{s["optimal_range"][1]}' + (
                          f' (paper: n* = {paper["n_star"]}, {paper["range"][0]}-'
                          f'{paper["range"][1]}).' if paper else '.')]
    feeders = _of_type(summary, 'feeder_emptying')
    if feeders:
        exp_id, s = feeders[-1]
        v = s['vibrations_to_empty']
        lines += ['', f'## Feeder emptying (`{exp_id}`, Table 3)', '']
        rows = [['ours', s['iterations'], s['parts'],
                 f'{s["optimal_range"][0]}-{s["optimal_range"][1]}', s['emptied'], v['mean']]]
        if paper:
            t = paper['table3']
            rows.append(['paper', t['iterations'], t['parts'],
                         f'{paper["range"][0]}-{paper["range"][1]}', t['emptied'],
                         t['vibrations']])
        lines += _table(['', 'iterations', 'parts', 'optimal range', 'emptied',
                         'av. vibrations to empty'], rows)
        lines += ['', f'Time per vibration the refill interval allows: '
                  f'{_fmt(s["minutes_per_vibration_allowed"])} min. Parts lost over the edge: '
                  f'{s["lost"]}.']
    if paper:
        lines += against_paper(summary, paper)
    lines += ['', '## Physics faults', ''] + _faults(summary)
    if pictures:
        lines += ['', '## Pictures']
        for name, caption in pictures.items():
            lines += ['', f'![{name}]({name})', '', caption]
    return '\n'.join(lines) + '\n'


def _last(summary: dict, kind: str) -> dict | None:
    """The summary of the file's last experiment of this type (the one the report shows)."""
    found = _of_type(summary, kind)
    return found[-1][1] if found else None


def _ratio(ours, paper) -> str:
    return '-' if ours is None or not paper else f'{ours / paper:.2f}'


def _differs(ours, paper) -> bool:
    return ours is not None and bool(paper) and not 1 / DIFFERS <= ours / paper <= DIFFERS


def _sweep_shape(s: dict) -> tuple[str, bool]:
    """How valid parts go with the parts on the tray (the fit), and whether that is the
    paper's shape: up to a peak inside the sweep, then down by at least FALLS."""
    last = s['per_n'][-1]['n']
    if s['n_star'] >= last:
        return f"still rising at the sweep's last count, n = {last}", False
    fall = 1 - float(np.polyval(s['coefficients'], last)) / s['fit_max']
    shape = 'then fall' if fall >= FALLS else 'then level off'
    return (f'rise to n* = {s["n_star"]}, {shape}: {100 * fall:.0f} % below the peak at '
            f'n = {last} (fit)'), fall >= FALLS


def against_paper(summary: dict, paper: dict) -> list[str]:
    """The paper's three findings and its figures beside this run's, and where and why ours
    differ. The reasons are what we know differs between the two set-ups, not measured causes."""
    findings, figures, differ = [], [], set()
    e, b, w, f = (_last(summary, kind) for kind in (
        'bin_emptying', 'bin_static', 'table_sweep', 'feeder_emptying'))
    t2, t3 = paper['table2'], paper['table3']
    if b and b['best_bin'] is not None:
        best = b['bins'][b['best_bin']]
        free = best['fractions']['container_free']['mean']
        same = [float(x) for x in paper['best_bin_mm']] == [float(x) for x in b['best_bin_mm']]
        figures += [['best bin (mm)', ' x '.join(_fmt(x) for x in b['best_bin_mm']),
                     ' x '.join(_fmt(x) for x in paper['best_bin_mm']),
                     'the same' if same else 'another'],
                    ['its parts free of the bin (bin collision free)', _pct(free),
                     _pct(paper['container_free']), _ratio(free, paper['container_free'])]]
        if not same or _differs(free, paper['container_free']):
            differ.add('bins')
    if e:
        agrees = e['emptied'] == 0
        findings.append([f'static bins never emptied ({t2["emptied"]} of {t2["iterations"]})',
                         f'{e["emptied"]} of {e["iterations"]} emptied',
                         'agrees' if agrees else 'differs'])
        ours_valid, ours_removed = e['first_check']['valid']['mean'], e['removed']['mean']
        figures += [['valid at the first check of a full bin', _pct(ours_valid),
                     _pct(paper['valid_first']), _ratio(ours_valid, paper['valid_first'])],
                    ['parts removed per bin (mean)', _fmt(ours_removed), _fmt(t2['mean']),
                     _ratio(ours_removed, t2['mean'])]]
        if not agrees or _differs(ours_valid, paper['valid_first']) \
                or _differs(ours_removed, t2['mean']):
            differ.add('bins')
    if w and 'n_star' in w:
        shape, agrees = _sweep_shape(w)
        findings.append([f'valid parts rise with the parts on the tray, then fall (n* = '
                         f'{paper["n_star"]})', shape, 'agrees' if agrees else 'differs'])
        figures.append(['parts on the table at the optimum, n*', w['n_star'], paper['n_star'],
                        _ratio(w['n_star'], paper['n_star'])])
        if not agrees or _differs(w['n_star'], paper['n_star']):
            differ.add('table')
    if f:
        agrees = f['iterations'] > 0 and f['emptied'] == f['iterations']
        findings.append([f'the tray emptied in every feeder run ({t3["emptied"]} of '
                         f'{t3["iterations"]})', f'{f["emptied"]} of {f["iterations"]} emptied',
                         'agrees' if agrees else 'differs'])
        vib = f['vibrations_to_empty']['mean']
        figures.append(['vibrations to empty the feeder (mean)', _fmt(vib, 4),
                        _fmt(t3['vibrations'], 4), _ratio(vib, t3['vibrations'])])
        if not agrees or _differs(vib, t3['vibrations']):
            differ.add('feeder')
    lines = ['', '## Against the paper', '']
    lines += _table(['the paper found', 'this run', 'agrees?'], findings) + ['']
    lines += _table(['figure', 'ours', 'the paper', 'ours / paper'], figures)
    why = {
        'bins': "Static bins: our part models stand in for the paper's figure 13 and the "
                "gripper is ours (the paper gives the dimensions of neither; see the README's "
                'part table). Which parts a grasp can reach free of the walls and of their '
                'neighbours, and so the parts removed, follow from both.',
        'table': 'Table optimum: n* counts parts of our models on the tray, each with the '
                 'clearance our gripper needs: both are ours.',
        'feeder': "Feeder: the table's motion is a model of ours (the paper does not say how "
                  'its table moves); the vibrations to empty the feeder follow from it and from '
                  'the load, n* above.'}
    lines += ['', f'A figure differs when ours is over {DIFFERS:g} times or under '
              f"{1 / DIFFERS:g} times the paper's."
              + (' Where this run differs, and why:' if differ else ' None does.')]
    lines += [f'- {why[k]}' for k in ('bins', 'table', 'feeder') if k in differ]
    if f and f['lost']:
        lines.append(f'- {_count(f["lost"], "part")} fell over the tray\'s wall, in '
                     f'{f["faults"]["escaped"]} of {f["iterations"]} feeder runs; a run that '
                     'loses a part has not emptied the feeder.')
    lines += ['', 'No setting of the simulation was tuned to agree with the paper.']
    return lines


def to_html(text: str, title: str) -> str:
    """The Markdown above as HTML: headings, tables, lists, images, paragraphs (the subset we
    write)."""
    out = [f'<!DOCTYPE html><html><head><meta charset="utf-8"><title>{html.escape(title)}'
           '</title><style>body{font-family:sans-serif;max-width:60em;margin:2em auto}'
           'table{border-collapse:collapse}td,th{border:1px solid #aaa;padding:0.2em 0.5em}'
           '</style></head><body>']
    rows: list[list[str]] = []
    items: list[str] = []

    def inline(s: str) -> str:
        s = html.escape(s)
        parts = s.split('**')
        s = ''.join(f'<b>{p}</b>' if i % 2 else p for i, p in enumerate(parts))
        parts = s.split('`')
        return ''.join(f'<code>{p}</code>' if i % 2 else p for i, p in enumerate(parts))

    def flush() -> None:
        if rows:
            out.append('<table><tr>' + ''.join(f'<th>{inline(c)}</th>' for c in rows[0])
                       + '</tr>')
            out.extend('<tr>' + ''.join(f'<td>{inline(c)}</td>' for c in r) + '</tr>'
                       for r in rows[2:])
            out.append('</table>')
            rows.clear()
        if items:
            out.append('<ul>' + ''.join(f'<li>{inline(i)}</li>' for i in items) + '</ul>')
            items.clear()

    for line in text.splitlines():
        if line.startswith('|'):
            if items:
                flush()
            rows.append([c.strip() for c in line.strip('|').split('|')])
            continue
        if line.startswith('- '):
            if rows:
                flush()
            items.append(line[2:])
            continue
        flush()
        if line.startswith('#'):
            level = len(line) - len(line.lstrip('#'))
            out.append(f'<h{level}>{inline(line[level:].strip())}</h{level}>')
        elif line.startswith('!['):
            alt, src = line[2:].split('](')
            out.append(f'<p><img src="{html.escape(src.rstrip(")"))}" '
                       f'alt="{html.escape(alt)}"></p>')
        elif line.strip():
            out.append(f'<p>{inline(line)}</p>')
    flush()
    return '\n'.join(out) + '\n</body></html>\n'


def write(run_dir: str) -> str:
    """Write the report of a run directory; returns the path of report.html."""
    with open(os.path.join(run_dir, 'summary.json'), encoding='utf-8') as f:
        summary = json.load(f)
    with open(os.path.join(run_dir, 'experiment.yaml'), encoding='utf-8') as f:
        spec = yaml.safe_load(f) or {}
    figures = {'fig14': plot_bins(summary, os.path.join(run_dir, 'fig14_bins.png')),
               'fig15': plot_sweep(summary, os.path.join(run_dir, 'fig15_table.png'))}
    pictures = None
    if os.path.exists(os.path.join(run_dir, 'pictures.json')):
        with open(os.path.join(run_dir, 'pictures.json'), encoding='utf-8') as f:
            pictures = json.load(f)
    text = markdown(summary, spec, figures, pictures)
    with open(os.path.join(run_dir, 'report.md'), 'w', encoding='utf-8') as f:
        f.write(text)
    path = os.path.join(run_dir, 'report.html')
    with open(path, 'w', encoding='utf-8') as f:
        f.write(to_html(text, f'Picking feasibility: {summary["id"]}'))
    return path
