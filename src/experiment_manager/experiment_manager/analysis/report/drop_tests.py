"""Each drop_test: the aspects its parts came to rest on, beside the quasi-static prediction
and the user's own drop test when the file gives its counts, and how to make one."""

import math

from pick_common.parts import aspects

from ..wording import fmt, pct, table
from .base import Run, Section

# How many drops a real test needs: the 95 % interval of a share near 0.3 is about +-0.1 after
# 80 drops and +-0.05 after 320 (Wilson: 1.96^2 p (1 - p) / half-width^2).
HOW_TO = ('To check these against your own parts: drop one part at a time from the height '
          'it falls in the cell (the hopper lip, the pour) onto the plate the cell will use, '
          'with a different, random orientation each time, and count the face it comes to '
          'rest on (the aspects below, named by the outward normal of that face in the part '
          "file's frame). About 80 drops tell each share to +-0.1, 320 to +-0.05 (95 %). Give "
          "the counts as the drop test's `measured: {aspect: count, ...}`.")


class DropTests(Section):
    def lines(self, run: Run) -> list[str]:
        lines = []
        for exp_id, s in run.summary.of_type('drop_test'):
            lines += ['', f'## Drop test (`{exp_id}`)', '']
            if run.figures.get(f'drop_{exp_id}'):
                lines += [f'![drop test {exp_id}](drop_{exp_id}.png)', '']
            if run.figures.get('aspects'):
                lines += ['![each aspect: the part resting on it, with its quasi-static share]'
                          '(aspects.png)', '']
            lines += [f'{s.drops} single parts dropped from {fmt(s.height_mm)} mm onto the '
                      f'plate, each at a random orientation, at rest on the aspects below: a '
                      'part rests on an aspect when gravity lies within '
                      f"{math.degrees(aspects.MATCH_ANGLE):g} degrees of its face's normal (of "
                      f"a round side's circle of normals). {s.other} rested on none, left out "
                      "of the shares: leaning on the plate's wall, or at rest on an edge or on a "
                      'face the quasi-static analysis finds the part cannot stand on. '
                      'Quasi-static: the share of orientations that would roll onto the face '
                      'without momentum.', '']
            measured = s.measured is not None
            rows = []
            for a in s.aspects:
                normal = '(' + ', '.join(f'{v:.2f}' for v in a.normal) + ')'
                row = [f'`{a.name}`', normal, str(a.count),
                       pct(a.share) if a.share is not None else '-',
                       f'{pct(a.ci95[0])} - {pct(a.ci95[1])}', pct(a.quasi_static)]
                if measured:
                    row += [str(a.measured or 0), pct(a.measured_share or 0.0),
                            f'{100 * a.difference:+.1f} %' if a.difference is not None else '-']
                rows.append(row)
            lines += table(['aspect', 'normal', 'drops', 'share', '95 % interval',
                            'quasi-static'] + (['measured', 'measured share', 'difference']
                                               if measured else []), rows)
            if measured:
                m = s.measured
                lines += ['', f'Against the {m.drops} measured drops: G-test p = {m.p:.3g}: '
                          + ('the simulation **agrees** with the measurement (p >= 0.05).'
                             if m.agrees else 'the simulation **disagrees** with the '
                             'measurement (p < 0.05): see where in the differences.')]
            lines += ['', HOW_TO]
        return lines
