"""Each sensitivity experiment, "How far the answers move": its inputs with their sources,
whether each verdict holds over their ranges, the tornado chart, a verdict map over a grid of
two inputs, and each scenario's answers and verdicts."""

from ..calibration import noise_said
from ..sensitivity import ANSWERS
from ..summary import Sensitivity as SensitivitySummary
from ..wording import count, fmt, table
from .base import Run, Section


class Sensitivity(Section):
    def lines(self, run: Run) -> list[str]:
        lines = []
        for exp_id, s in run.summary.of_type('sensitivity'):
            lines += section(exp_id, s, bool(run.figures.get(f'sensitivity_{exp_id}')))
        return lines


def section(exp_id: str, s: SensitivitySummary, plotted: bool) -> list[str]:
    """One sensitivity experiment's section (`plotted`: its tornado chart was drawn)."""
    lines = ['', f'## How far the answers move (`{exp_id}`)', '',
             f'The experiments {", ".join(f"`{e}`" for e in s.of)} repeated in '
             f'{count(len(s.scenarios), "scenario")} (each input at its low and its high, '
             "the others at the file's values; `joint_*`: all at once, a Latin hypercube; "
             "`grid_*`: every combination of the grid's levels), "
             f'at most {count(s.iterations, "iteration")} each, on the seeds of the runs '
             'they repeat:', '']
    lines += table(['input', "file's value", 'low', 'high', 'source of the range'],
                   [[f'`{x.name}`', x.base, x.low, x.high, x.source] for x in s.inputs])
    if s.held:
        lines += ['', 'Not repeated, so the same in every scenario: '
                  + '; '.join(f'`{e}` ran at the {h.what} of `{h.source}`'
                              for e, h in s.held.items())
                  + '. A verdict that flips may flip for that: repeat it too (add it to `of`) '
                  'for a range or bin that follows the inputs.']
    lines += ['', 'Verdicts over the ranges:', '']
    lines += [f'- {r.line}' for r in s.robustness] or ['- no verdict to compare']
    if plotted:
        lines += ['', f'![tornado chart of {exp_id}](sensitivity_{exp_id}.png)']
    if s.map is not None:
        rows, columns = s.map.rows, s.map.columns
        for option, grid in s.map.verdicts.items():
            lines += ['', f'{option}: the verdict over `{rows.input}` (rows) and '
                      f"`{columns.input}` (columns), the other inputs at the file's values:",
                      '']
            lines += table([f'{rows.input} \\ {columns.input}']
                           + [fmt(c, 4) for c in columns.values],
                           [[fmt(r, 4)] + [f'**{v}**' if v else '-' for v in row]
                            for r, row in zip(rows.values, grid, strict=True)])
    keys = [k for k in ANSWERS if k in s.ranges]
    options = list(s.base.verdicts)
    rows = []
    for name, said in [("file's values", s.base)] + [(x.name, x) for x in s.scenarios]:
        values = ', '.join(f'{k} {fmt(v, 3)}' for k, v in getattr(said, 'values', {}).items())
        rows.append([name, values or '-']
                    + [fmt(said.answers.get(k), 4) if k in said.answers else '-'
                       for k in keys] + [said.verdicts.get(o, '-') for o in options])
    lines += ['', f"Each scenario's answers are from at most {count(s.iterations, 'iteration')}"
              ' of each experiment: a difference between scenarios within the spread of '
              "their runs is the draw's, not the input's (a scenario whose inputs are the "
              "file's, or an earlier scenario's, is not run again)."]
    lines += ['', "Each scenario's answers ("
              + '; '.join(f'{ANSWERS[k][0]}' + (f', {ANSWERS[k][1]}' if ANSWERS[k][1] else '')
                          for k in keys) + ') and verdicts:', '']
    lines += table(['scenario', 'inputs set'] + [ANSWERS[k][0] for k in keys] + options, rows)
    for c in s.calibration or ():
        lines += ['', f"**Calibrated on `{c.experiment}`'s measured counts**: the likeliest "
                  f'of the {len(c.points)} scenarios (G-test p there {c.p:.3g}; '
                  + ('the simulation agrees' if c.p >= 0.05 else 'even the likeliest '
                     'disagrees: the ranges may not hold the value, or the physics cannot '
                     'make the measured shares') + "), each input's 95 % interval the "
                  'scenarios within 1.92 of its log likelihood (no finer than the grid). '
                  'File keys to paste (the interval as a sensitivity range):', '', '```']
        lines += c.keys + ['```']
        if said := noise_said(c.noise_sd, c.noise_outside):
            lines += ['', said[0].upper() + said[1:] + '.']
    return lines
