"""The report of a run: the decision the engineer came for, with the figures behind it.

From a run directory (`summary.json`, `experiment.yaml`, `pictures.json` with the pictures of
pictures.py when they were rendered, and `part.json` with the part's account and sheet of
part_sheet.py) it writes
`report.md` and `report.html` (the same content) and the plots `fig14_bins.png` (fractions of
parts passing each stage per bin, paper figure 14) and `fig15_table.png` (valid parts against
parts on the tray with the 4th-order fit, paper figure 15) and, for a gripper_sweep,
`grippers.png` (valid parts per check per gripper with the yield required), and for a
sensitivity experiment `sensitivity_<id>.png` (a tornado chart: each answer at each input's
low and high against the file's values) with its section, "How far the answers move".
Tables follow the
paper's Tables 2 and 3. For the paper's test-case files (ids pth0, pth1, pth2) the paper's
numbers stand beside ours, and a section "Against the paper" checks its three findings on
this run and says where and why ours differ. The decisions themselves (the verdicts and the
check against the paper) are verdicts.py's; this module renders them.
"""

import html
import json
import os

import matplotlib

matplotlib.use('Agg')   # no display: files only
import matplotlib.pyplot as plt
import numpy as np
import yaml

from . import stages
from .results import read_csv
from .sensitivity import ANSWERS
from .verdicts import (
    against_paper,
    FEASIBLE,
    interval_text,
    NOT_FEASIBLE,
    PAPER,
    shown_interval,
    UNDECIDED,
    verdicts,
)
from .wording import count, dims, fmt, gripper_label, of_type, pct, sampling_end, table, varying

FIGSIZE = (6.4, 4.0)   # inches
# the HTML class (colour) of a bold verdict
VERDICT_CLASS = {FEASIBLE: 'feasible', NOT_FEASIBLE: 'not-feasible', UNDECIDED: 'undecided'}


def plot_bins(summary: dict, path: str) -> bool:
    statics = of_type(summary, 'bin_static')
    if not statics:
        return False
    _, s = statics[-1]
    bins = [b for b in s['bins'] if b['iterations']]
    area = [b['xy_area_mm2'] / 100.0 for b in bins]      # cm^2
    order = np.argsort(area)
    fig, ax = plt.subplots(figsize=FIGSIZE)
    # Placeability passes a subset of the candidates, and often all of them: candidacy is drawn
    # on top, dashed with hollow rings, so that it stays visible where the two are equal (it
    # was hidden under placeability; issue 23).
    for key, label, style in (
            ('candidates', 'candidacy', {'marker': 'o', 'markersize': 9, 'linestyle': '--',
                                         'markerfacecolor': 'none', 'zorder': 3}),
            ('placeable', 'placeability', {'marker': 's', 'markersize': 4, 'zorder': 2}),
            ('container_free', 'bin collision free', {'marker': '^', 'zorder': 2})):
        mean = [100 * bins[i]['fractions'][key]['mean'] for i in order]
        std = [100 * bins[i]['fractions'][key]['std'] for i in order]
        ax.errorbar([area[i] for i in order], mean, yerr=std, capsize=3, label=label, **style)
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
    sweeps = of_type(summary, 'table_sweep')
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


def plot_grippers(summary: dict, path: str) -> bool:
    """The last gripper_sweep: valid parts per check (mean and 95 % interval) per gripper and
    grasp set, the yield it must reach, and the smallest that does in green."""
    sweeps = of_type(summary, 'gripper_sweep')
    if not sweeps:
        return False
    _, s = sweeps[-1]
    variants = s['variants']
    keys, sets = varying(variants)
    labels = [gripper_label(v, keys, sets) or f'variant {v["index"]}' for v in variants]
    mean = np.array([v['valid']['mean'] if v['valid']['mean'] is not None else np.nan
                     for v in variants])
    low, high = (np.array([np.nan if x is None else x for x in side]) for side in
                 zip(*(shown_interval(v) for v in variants), strict=True))
    x = np.arange(len(variants))
    fig, ax = plt.subplots(figsize=(max(FIGSIZE[0], 0.5 * len(variants) + 2), FIGSIZE[1] + 1))
    colours = ['tab:green' if v['index'] == s['smallest'] else
               'tab:blue' if v['meets'] else 'tab:gray' for v in variants]
    ax.bar(x, np.nan_to_num(mean), color=colours,
           label='mean valid parts per check (green: the smallest that meets)')
    ax.errorbar(x, mean, yerr=[np.nan_to_num(mean - low), np.nan_to_num(high - mean)],
                fmt='none', ecolor='black', capsize=3, label='95 % interval')
    ax.axhline(s['min_valid'], color='tab:red', linestyle='--',
               label=f'required: {fmt(s["min_valid"])} (min_valid)')
    ax.set_xticks(x, labels, rotation=60, ha='right', fontsize=8)
    ax.set_ylim(bottom=0)       # a count: an interval's low end below 0 is cut at 0
    _finish(fig, ax, path, f'{summary["id"]}: gripper sweep', '', 'valid parts per check')
    return True


def _physics_health(summary: dict) -> list[str]:
    """Per experiment: iterations flagged (a NaN state, a tunnelled and a thrown part leave an
    iteration out of the figures; a settle that hit its cap is counted) and the physics of all
    of them: parts spilled over a wall, tunnelled and thrown, the deepest penetration, the
    fastest part, the worst tray tracking."""
    rows = [[f'`{exp_id}`', len(s['faults']['flagged']), s['faults']['physics_fault'],
             s['faults']['tunnelled'], s['faults']['thrown'], s['faults']['unsettled'],
             s['physics']['spilled'], s['physics']['tunnelled'], s['physics']['thrown'],
             fmt(1000 * s['physics']['max_penetration'], 3), fmt(s['physics']['max_speed'], 2),
             pct(s['physics']['tray_error'])]
            for exp_id, s in summary['experiments'].items()]
    flagged = any(s['faults']['flagged'] for s in summary['experiments'].values())
    lead = [] if flagged else ['No iteration was flagged: every settle ended within its cap, '
                               'no part tunnelled or was thrown, no physics state became NaN.',
                               '']
    return lead + table(['experiment', 'iterations flagged', 'NaN state (left out)',
                  'tunnelled (left out)', 'thrown (left out)', 'unsettled at the cap (counted)',
                  'parts spilled', 'parts tunnelled', 'parts thrown', 'deepest penetration (mm)',
                  'fastest part (m/s)', 'worst tray tracking error'],
                 rows) + ['', 'Tunnelled: a part ended in or under the floor or in a wall, '
                          'which solid bodies cannot do; thrown: a part moved faster than a '
                          "fall from twice the walls' height plus a bounce off the tray can "
                          'make it, so the solver gave it energy; spilled: a part went over a '
                          'wall. Each flagged iteration has its fault in the `fault` column of '
                          '`iterations.csv`.']


def _sampling(summary: dict) -> list[str]:
    """With adaptive sampling: how many iterations each experiment took, and whether its
    decision was settled or its iterations ran out."""
    adaptive = [(exp_id, s, s['sampling']) for exp_id, s in summary['experiments'].items()
                if 'sampling' in s]
    if not adaptive:
        return []
    return ['', '## Sampling', '',
            'Adaptive: each experiment ran in batches of iterations per group (bin, count) '
            'until its decision was settled at 99.9 % confidence, at most the iterations of '
            'its file; the figures and verdicts above come from the iterations that ran, at '
            '95 %. Batches: the looks that released iterations (a later look of a sweep gives '
            'the counts that narrow n* most a batch or more each, and others none).', ''] + table(
        ['experiment', 'iterations run', 'at most', 'batches', 'ended'],
        [[f'`{exp_id}`', a['iterations_run'], a['most'], a['batches'],
          ('' if a['settled'] else 'at the most iterations, ') + sampling_end(s)]
         for exp_id, s, a in adaptive])


def _sizes(given: dict | None, lead: str) -> str:
    """The sizes an experiment file gave, as people read them ('body diameter 5 mm, ...'),
    after `lead`; '' for none. Keys ending in _mm carry the unit; a bare key is a part model's
    dimension, in mm too (part.dimensions_mm)."""
    if not given:
        return ''
    def size(key: str, value) -> str:
        name = key.removesuffix('_mm').replace('_', ' ')
        number = isinstance(value, int | float) and not isinstance(value, bool)
        return f'{name} {fmt(value)} mm' if number else f'{name} {value}'
    return lead + ', '.join(size(k, v) for k, v in given.items())


def _bound(ground: dict) -> str:
    """A ground's bound as read: a time in minutes, a share in per cent, else a number."""
    if ground['quantity'].startswith('time'):
        return f'{ground["bound"] / 60:.1f} min (refill interval {ground["refill_s"] / 60:g} min)'
    if ground['quantity'].startswith('share'):
        return pct(ground['bound'])
    return fmt(ground['bound'])


def markdown(summary: dict, spec: dict, figures: dict[str, bool],
             pictures: dict[str, str] | None = None, account: list[str] | None = None) -> str:
    """The report as Markdown. pictures: {image file: caption} (pictures.py); account: the
    part's account (part_sheet.describe), with its sheet `part.png`."""
    paper = PAPER.get(summary['id'])
    part = spec.get('part', {})
    r = summary['requirements']
    lines = [f'# Picking feasibility: {summary["id"]}', '',
             f'Part `{part.get("model", "radial_capacitor")}`'
             f'{_sizes(part.get("dimensions_mm"), ", ")}; gripper'
             f'{_sizes(spec.get("gripper"), " ") or " as the defaults"}; seed '
             f'{summary["seed"]}.', '',
             f'Requirement: {fmt(r["parts_per_hour"])} parts per hour, a refill every '
             f'{fmt(r["refill_interval_h"])} h (capacity {r["capacity"]} parts), no bin longer '
             f'than {fmt(r["max_dimension_mm"])} mm in any dimension (every bin analysed '
             'meets it: the experiment file refuses others).', '', '## Verdict', '']
    decided = verdicts(summary)
    lines += table(['option', 'verdict', 'why'],
                    [[v['option'], f'**{v["verdict"]}**', '; '.join(v['reasons'])]
                     for v in decided])
    grounds = [[v['option'], name, g['quantity'], g['verdict'],
                '' if g['bound'] is None else _bound(g), g['interval'], g['runs']]
               for v in decided for name, g in v.get('grounds', {}).items()]
    if grounds:
        lines += ['', 'What each verdict rests on (the bound it was decided on; a ground '
                  'UNDECIDED is not settled by the runs so far):', '']
        lines += table(['option', 'ground', 'quantity', 'says', 'bound', 'interval', 'runs'],
                       grounds)
    if account:
        lines += ['', '## The part', '', 'As the run saw it (the file, its frame, what the '
                  'physics and the checks collide, what each grasp closes on):', '']
        lines += [f'- {line.strip()}' for line in account]
        lines += ['', '![the part sheet: the part, its collision pieces, and the gripper at '
                  "each grasp's pick and place](part.png)"]
    lines += _sampling(summary)
    statics = of_type(summary, 'bin_static')
    if statics:
        exp_id, s = statics[-1]
        lines += ['', f'## Static bins (`{exp_id}`, figure 14)', '']
        if figures.get('fig14'):
            lines += ['![figure 14](fig14_bins.png)', '']
        lines += table(['bin (mm)', 'iterations', 'candidacy', 'placeability',
                         'bin collision free'],
                        [[dims(b['size_mm']), b['iterations'],
                          pct(b['fractions']['candidates']['mean']),
                          pct(b['fractions']['placeable']['mean']),
                          pct(b['fractions']['container_free']['mean'])]
                         for b in s['bins']])
        lines += ['', f'Best bin: {fmt(s["best_bin_mm"])} mm.' + (
            f' Paper: {paper["best_bin_mm"]} mm, {pct(paper["container_free"])} bin '
            'collision free.' if paper else '')]
    emptying = of_type(summary, 'bin_emptying')
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
        lines += table(['', 'iterations', 'parts', 'emptied bins', 'parts removed: mean',
                         'min', 'max', 'std'], rows)
        lines += ['', f'Valid at the first check (all four stages): '
                  f'{pct(s["first_check"]["valid"]["mean"])} of the parts' + (
                      f' (paper: {pct(paper["valid_first"])}).' if paper else '.'),
                  f'Parts looked at before each pick (search order): mean '
                  f'{fmt(s["searches_per_pick"]["mean"])}.']
    sweeps = of_type(summary, 'table_sweep')
    if sweeps:
        exp_id, s = sweeps[-1]
        lines += ['', f'## Vibrating table sweep (`{exp_id}`, figure 15)', '']
        if figures.get('fig15'):
            lines += ['![figure 15](fig15_table.png)', '']
        if s.get('no_valid'):
            lines += ['**No valid part at any count**: with this gripper and these grasps no '
                      'part on the table can be picked and placed, so n* and its range say '
                      'nothing (the feeder runs use them all the same, and cannot empty the '
                      'table).', '']
        if 'n_star' in s:
            ci = s.get('n_star_ci95')
            lines += [f'Fit of order {s["order"]}: the most valid parts at n* = {s["n_star"]} '
                      f'parts on the table' + (f' (95 % interval {ci[0]}-{ci[1]}, bootstrap)'
                                               if ci else '') +
                      f'; optimal range {s["optimal_range"][0]}-{s["optimal_range"][1]}' + (
                          f' (paper: n* = {paper["n_star"]}, {paper["range"][0]}-'
                          f'{paper["range"][1]}).' if paper else '.')]
            low, high = s['optimal_range']
            if ci and (ci[0] < low or ci[1] > high):
                lines += ['', f'**Note**: the interval of n* reaches beyond the optimal '
                          f'range: these drops do not pin n* down to it, and others of the same '
                          f'parts could put it anywhere in {ci[0]}-{ci[1]}. Compare the valid '
                          f'parts per check across that span (figure 15) before relying on '
                          f'the range.']
            tested = [p['n'] for p in s['per_n']]
            if tested and s['optimal_range'][1] > max(tested):
                lines += ['', f'**Warning**: the optimal range runs past the last count tested '
                          f'({max(tested)} parts): beyond it the fit is an extrapolation'
                          + (', and n* sits at that count, so the fit is still rising there: '
                             'test higher counts' if s['n_star'] >= max(tested) else '') + '.']
    feeders = of_type(summary, 'feeder_emptying')
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
        lines += table(['', 'iterations', 'parts', 'optimal range', 'emptied',
                         'av. vibrations to empty'], rows)
        lines += ['', f'Time per vibration the refill interval allows: '
                  f'{fmt(s["minutes_per_vibration_allowed"])} min. Parts spilled over the '
                  f'walls: {s["physics"]["spilled"]} (in {s["runs_spilling"]} runs; a run may '
                  f'spill {s["max_spilled"]}); runs emptied within that: {s["accepted"]}.']
        rate = s.get('parts_per_hour')     # absent in run directories before 2026-11-26
        if rate and rate['mean'] is not None:
            low, high = s['parts_per_hour_ci95']
            lines += ['', f'The cell would pick {fmt(rate["mean"], 4)} parts per hour (mean of '
                      f'{count(rate["n"], "run")}'
                      + (f', 95 % interval {fmt(low, 4)} to {fmt(high, 4)}' if low is not None
                         else '') + f'; required {fmt(summary["requirements"]["parts_per_hour"])}'
                      f'): {fmt(s["cell"]["pick_s"])} s per pick (`cell.pick_s`), '
                      f'{fmt(s["cell"]["image_s"])} s per image after every pick and vibration '
                      '(`cell.image_s`), and the simulated time each feed and vibration took '
                      'until the parts rested.']
    gripper_sweeps = of_type(summary, 'gripper_sweep')
    for exp_id, s in gripper_sweeps:
        lines += ['', f'## Gripper sweep (`{exp_id}`)', '']
        if figures.get('grippers') and exp_id == gripper_sweeps[-1][0]:   # the one plotted
            lines += ['![gripper sweep](grippers.png)', '']
        lines += [f'Every gripper and grasp set checked (all four stages) on the same '
                  f'{s["iterations"]} scenes of {s["parts"]} parts in the '
                  f'{dims(s["scene_mm"])} mm container. A gripper meets the yield when the '
                  f'95 % interval of its valid parts per check lies at or above '
                  f'{fmt(s["min_valid"])} (min_valid). D: body diameter, W: jaw depth, V: jaw '
                  "height, L: body length, clearance: fingertips above the part's bottom.", '']
        rows = []
        for v in s['variants']:
            f = v['fractions']
            rows.append([gripper_label(v), pct(f['candidates']['mean']),
                         pct(f['placeable']['mean']), pct(f['container_free']['mean']),
                         pct(f['valid']['mean']), fmt(v['valid']['mean']),
                         interval_text(v),
                         f'{v["scenes_with_valid"]}/{v["scenes"]}',
                         ('**smallest**' if v['index'] == s['smallest'] else 'yes')
                         if v['meets'] else 'no'])
        lines += table(['gripper', 'candidacy', 'placeability', 'container free', 'valid',
                        'valid per check', '95 % interval', 'scenes with a valid part',
                        'meets'], rows)
    for exp_id, s in of_type(summary, 'sensitivity'):
        lines += _sensitivity(exp_id, s, figures.get(f'sensitivity_{exp_id}'))
    if paper:
        lines += against_paper(summary, paper)
    lines += ['', '## Physics health', ''] + _physics_health(summary)
    if pictures:
        lines += ['', '## Pictures']
        for name, caption in pictures.items():
            lines += ['', f'![{name}]({name})', '', caption]
    return '\n'.join(lines) + '\n'


def _sensitivity(exp_id: str, s: dict, plotted: bool) -> list[str]:
    """A sensitivity experiment's section: its inputs with their sources, whether each
    verdict holds over them, the tornado chart and each scenario's answers and verdicts."""
    lines = ['', f'## How far the answers move (`{exp_id}`)', '',
             f'The experiments {", ".join(f"`{e}`" for e in s["of"])} repeated in '
             f'{count(len(s["scenarios"]), "scenario")} (each input at its low and its high, '
             "the others at the file's values; `joint_*`: all at once, a Latin hypercube; "
             "`grid_*`: every combination of the grid's levels), "
             f'at most {count(s["iterations"], "iteration")} each, on the seeds of the runs '
             'they repeat:', '']
    lines += table(['input', "file's value", 'low', 'high', 'source of the range'],
                   [[f'`{x["name"]}`', x['base'], x['low'], x['high'], x['source']]
                    for x in s['inputs']])
    if s.get('held'):
        lines += ['', 'Not repeated, so the same in every scenario: '
                  + '; '.join(f'`{e}` ran at the {h["what"]} of `{h["from"]}`'
                              for e, h in s['held'].items())
                  + '. A verdict that flips may flip for that: repeat it too (add it to `of`) '
                  'for a range or bin that follows the inputs.']
    lines += ['', 'Verdicts over the ranges:', '']
    lines += [f'- {r["line"]}' for r in s['robustness']] or ['- no verdict to compare']
    if plotted:
        lines += ['', f'![tornado chart of {exp_id}](sensitivity_{exp_id}.png)']
    if 'map' in s:
        m = s['map']
        rows, columns = m['rows'], m['columns']
        for option, grid in m['verdicts'].items():
            lines += ['', f'{option}: the verdict over `{rows["input"]}` (rows) and '
                      f'`{columns["input"]}` (columns), the other inputs at the file\'s values:',
                      '']
            lines += table([f'{rows["input"]} \\ {columns["input"]}']
                           + [fmt(c, 4) for c in columns['values']],
                           [[fmt(r, 4)] + [f'**{v}**' if v else '-' for v in row]
                            for r, row in zip(rows['values'], grid, strict=True)])
    keys = [k for k in ANSWERS if k in s['ranges']]
    options = list(s['base']['verdicts'])
    rows = []
    for name, said in [("file's values", s['base'])] + [(x['name'], x) for x in s['scenarios']]:
        values = ', '.join(f'{k} {fmt(v, 3)}' for k, v in said.get('values', {}).items())
        rows.append([name, values or '-']
                    + [fmt(said['answers'].get(k), 4) if k in said['answers'] else '-'
                       for k in keys] + [said['verdicts'].get(o, '-') for o in options])
    lines += ['', f"Each scenario's answers are from at most {count(s['iterations'], 'iteration')}"
              ' of each experiment: a difference between scenarios within the spread of '
              "their runs is the draw's, not the input's (a scenario whose inputs are the "
              "file's, or an earlier scenario's, is not run again)."]
    lines += ['', "Each scenario's answers ("
              + '; '.join(f'{ANSWERS[k][0]}' + (f', {ANSWERS[k][1]}' if ANSWERS[k][1] else '')
                          for k in keys) + ') and verdicts:', '']
    lines += table(['scenario', 'inputs set'] + [ANSWERS[k][0] for k in keys] + options, rows)
    return lines


def tornado_bars(by_input: dict, base: float) -> list[tuple[str, float | None, float | None]]:
    """One panel's bars, bottom to top: (label, low, high) per input, ordered by how far it
    moves the answer from `base`; an input with an end that gave no value (no run emptied, say,
    or a bound the fit check refused) last, so on top, its label saying which end: the
    answer's bar cannot show it, and such an end is where a verdict may have flipped."""
    def key(b: tuple) -> tuple:
        return (any(x is None for x in b[1:]),
                max(abs((x if x is not None else base) - base) for x in b[1:]))
    bars = sorted(((name, v['low'], v['high']) for name, v in by_input.items()), key=key)
    return [(name + ''.join(f' ({end}: no value)' for end, x in (('low', low), ('high', high))
                            if x is None), low, high) for name, low, high in bars]


def plot_tornado(exp_id: str, s: dict, path: str) -> bool:
    """Each answer of a sensitivity experiment (a panel) at each input's low and high (a bar
    from one to the other, the low end marked), the file's values' answer a line; inputs
    ordered by how far they move it, an end with no value marked x at the line (tornado_bars)."""
    # an answer no input moved has no bars to draw (the scenarios' table says so)
    base_answers = s['base']['answers']
    panels = [(k, v) for k, v in s['tornado'].items() if base_answers.get(k) is not None
              and any(x is None or x != base_answers[k]
                      for ends in v.values() for x in ends.values())]
    if not panels:
        return False
    fig, axes = plt.subplots(len(panels), 1, figsize=(FIGSIZE[0], 1.0 + 1.6 * len(panels)),
                             squeeze=False)
    for ax, (key, by_input) in zip(axes[:, 0], panels, strict=True):
        base = s['base']['answers'][key]
        bars = tornado_bars(by_input, base)
        for y, (_, low, high) in enumerate(bars):
            ends = [x if x is not None else base for x in (low, high)]
            ax.barh(y, ends[1] - ends[0], left=ends[0], height=0.5,
                    color='#1f77b4' if ends[1] >= ends[0] else '#d62728')
            if low is not None:
                ax.plot([low], [y], 'k|', markersize=12)
            if low is None or high is None:
                ax.plot([base], [y], 'x', color='#c62828', markersize=9, markeredgewidth=2)
        ax.axvline(base, color='k', linewidth=1)
        seen = [base] + [x for b in bars for x in b[1:] if x is not None]
        pad = 0.06 * (max(seen) - min(seen)) or 1.0
        ax.set_xlim(min(seen) - pad, max(seen) + pad)    # the low ends' marks clear of the frame
        ax.set_yticks(range(len(bars)), [b[0] for b in bars], fontsize=7)
        words, unit = ANSWERS[key]
        ax.set_title(words + (f', {unit}' if unit else ''), fontsize=9)
    fig.suptitle(f'{exp_id}: each input from low (|) to high; blue rises, red falls;\n'
                 "x: an end with no value (the scenarios' table says why)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return True


def to_html(text: str, title: str) -> str:
    """The Markdown above as HTML: headings, tables, lists, images, paragraphs (the subset we
    write)."""
    out = [f'<!DOCTYPE html><html><head><meta charset="utf-8"><title>{html.escape(title)}'
           '</title><style>body{font-family:sans-serif;max-width:60em;margin:2em auto}'
           'table{border-collapse:collapse}td,th{border:1px solid #aaa;padding:0.2em 0.5em}'
           '.feasible{color:#1a7f37}.not-feasible{color:#c62828}.undecided{color:#9a6700}'
           '</style></head><body>']
    rows: list[list[str]] = []
    items: list[str] = []

    def inline(s: str) -> str:
        s = html.escape(s)
        parts = s.split('**')
        s = ''.join((f'<b class="{VERDICT_CLASS[p]}">{p}</b>' if p in VERDICT_CLASS
                     else f'<b>{p}</b>') if i % 2 else p for i, p in enumerate(parts))
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
               'fig15': plot_sweep(summary, os.path.join(run_dir, 'fig15_table.png')),
               'grippers': plot_grippers(summary, os.path.join(run_dir, 'grippers.png'))}
    for exp_id, s in of_type(summary, 'sensitivity'):
        figures[f'sensitivity_{exp_id}'] = plot_tornado(
            exp_id, s, os.path.join(run_dir, f'sensitivity_{exp_id}.png'))
    pictures = None
    if os.path.exists(os.path.join(run_dir, 'pictures.json')):
        with open(os.path.join(run_dir, 'pictures.json'), encoding='utf-8') as f:
            pictures = json.load(f)
    account = None
    if os.path.exists(os.path.join(run_dir, 'part.json')):
        with open(os.path.join(run_dir, 'part.json'), encoding='utf-8') as f:
            account = json.load(f)
    text = markdown(summary, spec, figures, pictures, account)
    checks = os.path.join(run_dir, 'checks.csv')
    if os.path.exists(checks):
        text += '\n'.join(stages.lines(stages.turned_down(read_csv(checks)))) + '\n'
    with open(os.path.join(run_dir, 'report.md'), 'w', encoding='utf-8') as f:
        f.write(text)
    path = os.path.join(run_dir, 'report.html')
    with open(path, 'w', encoding='utf-8') as f:
        f.write(to_html(text, f'Picking feasibility: {summary["id"]}'))
    return path
