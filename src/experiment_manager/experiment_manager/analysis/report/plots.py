"""The report's figures, each from summary.json (summary.py) to a PNG in the run directory:
`fig14_bins.png` (fractions of parts passing each stage per bin, the paper's figure 14),
`fig15_table.png` (valid parts against parts on the tray with the fit, its figure 15),
`grippers.png` (valid parts per check per gripper with the yield required) and
`sensitivity_<id>.png` (a tornado chart: each answer at each input's low and high against the
file's values). Each returns whether it drew (the run had the experiment)."""

import matplotlib

matplotlib.use('Agg')   # no display: files only
import matplotlib.pyplot as plt
import numpy as np

from ..sensitivity import ANSWERS
from ..summary import Sensitivity, Summary
from ..verdicts import shown_interval
from ..wording import fmt, gripper_label, varying

FIGSIZE = (6.4, 4.0)   # inches


def draw_all(summary: Summary, path) -> dict[str, bool]:
    """Every figure of the run; `path(name)`: where the file `name` goes. {figure: drawn}."""
    figures = {'fig14': plot_bins(summary, path('fig14_bins.png')),
               'fig15': plot_sweep(summary, path('fig15_table.png')),
               'grippers': plot_grippers(summary, path('grippers.png'))}
    for exp_id, s in summary.of_type('sensitivity'):
        figures[f'sensitivity_{exp_id}'] = plot_tornado(exp_id, s,
                                                        path(f'sensitivity_{exp_id}.png'))
    for exp_id, s in summary.of_type('drop_test'):
        figures[f'drop_{exp_id}'] = plot_drop_test(exp_id, s, path(f'drop_{exp_id}.png'))
    return figures


def plot_drop_test(exp_id: str, s, path: str) -> bool:
    """A drop test's shares per aspect: simulated (with its 95 % interval), quasi-static and
    measured, side by side."""
    if not s.drops:
        return False
    names = [a.name for a in s.aspects]
    x = np.arange(len(names))
    series = [('simulated', [a.share or 0.0 for a in s.aspects]),
              ('quasi-static', [a.quasi_static for a in s.aspects])]
    if s.measured is not None:
        series.append(('measured', [a.measured_share or 0.0 for a in s.aspects]))
    width = 0.8 / len(series)
    fig, ax = plt.subplots(figsize=FIGSIZE)
    for k, (label, values) in enumerate(series):
        ax.bar(x + (k - (len(series) - 1) / 2) * width, values, width, label=label)
    # the interval holds the share; a share of 0 or 1 may sit a rounding outside it
    low = [max(0.0, a.share - a.ci95[0]) if a.share is not None else 0.0 for a in s.aspects]
    high = [max(0.0, a.ci95[1] - a.share) if a.share is not None else 0.0 for a in s.aspects]
    ax.errorbar(x - (len(series) - 1) / 2 * width, [a.share or 0.0 for a in s.aspects],
                yerr=[low, high], fmt='none', ecolor='black', capsize=3)
    ax.set_xticks(x, names)
    ax.set_ylim(0, 1)
    _finish(fig, ax, path, f'{exp_id}: resting aspects of {s.drops} drops from '
            f'{s.height_mm:g} mm', 'aspect: the face the part rests on', 'share of drops')
    return True


def plot_bins(summary: Summary, path: str) -> bool:
    s = summary.last('bin_static')
    if s is None:
        return False
    bins = [b for b in s.bins if b.iterations]
    area = [b.xy_area_mm2 / 100.0 for b in bins]      # cm^2
    order = np.argsort(area)
    fig, ax = plt.subplots(figsize=FIGSIZE)
    # Placeability passes a subset of the candidates, and often all of them: candidacy is drawn
    # on top, dashed with hollow rings, so that it stays visible where the two are equal.
    for key, label, style in (
            ('candidates', 'candidacy', {'marker': 'o', 'markersize': 9, 'linestyle': '--',
                                         'markerfacecolor': 'none', 'zorder': 3}),
            ('placeable', 'placeability', {'marker': 's', 'markersize': 4, 'zorder': 2}),
            ('container_free', 'bin collision free', {'marker': '^', 'zorder': 2})):
        mean = [100 * getattr(bins[i].fractions, key).mean for i in order]
        std = [100 * getattr(bins[i].fractions, key).std for i in order]
        ax.errorbar([area[i] for i in order], mean, yerr=std, capsize=3, label=label, **style)
    ax.set_ylim(0, 100)
    _finish(fig, ax, path, f'{summary.id}: static bin analysis (figure 14)',
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


def plot_sweep(summary: Summary, path: str) -> bool:
    s = summary.last('table_sweep')
    if s is None:
        return False
    n = np.array([p.n for p in s.per_n], dtype=float)
    mean = np.array([p.valid.mean for p in s.per_n])
    fig, ax = plt.subplots(figsize=FIGSIZE)
    ax.plot(n, mean, 'o', markersize=3, label='mean valid parts')
    if s.coefficients is not None and len(n):
        grid = np.linspace(n.min(), n.max(), 200)
        ax.plot(grid, np.polyval(s.coefficients, grid), '-', label=f'order-{s.order} fit')
        low, high = s.optimal_range
        ax.axvspan(low, high, alpha=0.15, color='green',
                   label=f'optimal range {low}-{high} (n* = {s.n_star})')
    _finish(fig, ax, path, f'{summary.id}: vibrating table analysis (figure 15)',
            'parts on the table', 'valid parts')
    return True


def plot_grippers(summary: Summary, path: str) -> bool:
    """The last gripper_sweep: valid parts per check (mean and 95 % interval) per gripper and
    grasp set, the yield it must reach, and the smallest that does in green."""
    s = summary.last('gripper_sweep')
    if s is None:
        return False
    variants = s.variants
    keys, sets = varying(variants)
    labels = [gripper_label(v, keys, sets) or f'variant {v.index}' for v in variants]
    mean = np.array([v.valid.mean if v.valid.mean is not None else np.nan for v in variants])
    low, high = (np.array([np.nan if x is None else x for x in side]) for side in
                 zip(*(shown_interval(v) for v in variants), strict=True))
    x = np.arange(len(variants))
    fig, ax = plt.subplots(figsize=(max(FIGSIZE[0], 0.5 * len(variants) + 2), FIGSIZE[1] + 1))
    colours = ['tab:green' if v.index == s.smallest else
               'tab:blue' if v.meets else 'tab:gray' for v in variants]
    ax.bar(x, np.nan_to_num(mean), color=colours,
           label='mean valid parts per check (green: the smallest that meets)')
    ax.errorbar(x, mean, yerr=[np.nan_to_num(mean - low), np.nan_to_num(high - mean)],
                fmt='none', ecolor='black', capsize=3, label='95 % interval')
    ax.axhline(s.min_valid, color='tab:red', linestyle='--',
               label=f'required: {fmt(s.min_valid)} (min_valid)')
    ax.set_xticks(x, labels, rotation=60, ha='right', fontsize=8)
    ax.set_ylim(bottom=0)       # a count: an interval's low end below 0 is cut at 0
    _finish(fig, ax, path, f'{summary.id}: gripper sweep', '', 'valid parts per check')
    return True


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


def plot_tornado(exp_id: str, s: Sensitivity, path: str) -> bool:
    """Each answer of a sensitivity experiment (a panel) at each input's low and high (a bar
    from one to the other, the low end marked), the file's values' answer a line; inputs
    ordered by how far they move it, an end with no value marked x at the line (tornado_bars)."""
    # an answer no input moved has no bars to draw (the scenarios' table says so)
    base_answers = s.base.answers
    panels = [(k, v) for k, v in s.tornado.items() if base_answers.get(k) is not None
              and any(x is None or x != base_answers[k]
                      for ends in v.values() for x in ends.values())]
    if not panels:
        return False
    fig, axes = plt.subplots(len(panels), 1, figsize=(FIGSIZE[0], 1.0 + 1.6 * len(panels)),
                             squeeze=False)
    for ax, (key, by_input) in zip(axes[:, 0], panels, strict=True):
        base = base_answers[key]
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
