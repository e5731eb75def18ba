"""The static bins: the stage fractions per bin (the paper's figure 14) and the best bin, and the
bin emptying (its Table 2), with the paper's figures beside ours for its test case."""

from ..wording import dims, fmt, pct, table
from .base import Run, Section


class StaticBins(Section):
    def lines(self, run: Run) -> list[str]:
        found = run.summary.of_type('bin_static')
        if not found:
            return []
        exp_id, s = found[-1]
        paper = run.paper
        lines = ['', f'## Static bins (`{exp_id}`, figure 14)', '']
        if run.figures.get('fig14'):
            lines += ['![figure 14](fig14_bins.png)', '']
        lines += table(['bin (mm)', 'iterations', 'candidacy', 'placeability',
                        'bin collision free'],
                       [[dims(b.size_mm), b.iterations, pct(b.fractions.candidates.mean),
                         pct(b.fractions.placeable.mean), pct(b.fractions.container_free.mean)]
                        for b in s.bins])
        return lines + ['', f'Best bin: {fmt(s.best_bin_mm)} mm.' + (
            f' Paper: {paper["best_bin_mm"]} mm, {pct(paper["container_free"])} bin '
            'collision free.' if paper else '')]


class BinEmptying(Section):
    def lines(self, run: Run) -> list[str]:
        found = run.summary.of_type('bin_emptying')
        if not found:
            return []
        exp_id, s = found[-1]
        paper = run.paper
        rm = s.removed
        lines = ['', f'## Bin emptying (`{exp_id}`, Table 2)', '']
        rows = [['ours', s.iterations, s.parts, s.emptied, rm.mean, rm.min, rm.max, rm.std]]
        if paper:
            t = paper['table2']
            rows.append(['paper', t['iterations'], t['parts'], t['emptied'], t['mean'],
                         t['min'], t['max'], t['std']])
        lines += table(['', 'iterations', 'parts', 'emptied bins', 'parts removed: mean',
                        'min', 'max', 'std'], rows)
        return lines + ['', f'Valid at the first check (all four stages): '
                        f'{pct(s.first_check.valid.mean)} of the parts' + (
                            f' (paper: {pct(paper["valid_first"])}).' if paper else '.'),
                        f'Parts looked at before each pick (search order): mean '
                        f'{fmt(s.searches_per_pick.mean)}.']
