"""With adaptive sampling: how many iterations each experiment took, and whether its decision
was settled or its iterations ran out."""

from ..wording import sampling_end, table
from .base import Run, Section


class Sampling(Section):
    def lines(self, run: Run) -> list[str]:
        adaptive = [(exp_id, s) for exp_id, s in run.summary.experiments.items()
                    if s.sampling is not None]
        if not adaptive:
            return []
        return ['', '## Sampling', '',
                'Adaptive: each experiment ran in batches of iterations per group (bin, count) '
                'until its decision was settled at 99.9 % confidence, at most the iterations of '
                'its file; the figures and verdicts above come from the iterations that ran, '
                'at 95 %. Batches: the looks that released iterations (a later look of a sweep '
                'gives the counts that narrow n* most a batch or more each, and others none).',
                ''] + table(
            ['experiment', 'iterations run', 'at most', 'batches', 'ended'],
            [[f'`{exp_id}`', s.sampling.iterations_run, s.sampling.most, s.sampling.batches,
              ('' if s.sampling.settled else 'at the most iterations, ') + sampling_end(s)]
             for exp_id, s in adaptive])
