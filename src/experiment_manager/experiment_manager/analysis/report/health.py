"""Physics health, per experiment: the iterations flagged (a NaN state, a tunnelled and a
thrown part leave an iteration out of the figures; a settle that hit its cap is counted) and
the physics of all of them: parts spilled over a wall, tunnelled and thrown, the deepest
penetration, the fastest part, the worst tray tracking."""

from ..wording import fmt, pct, table
from .base import Run, Section


class Health(Section):
    def lines(self, run: Run) -> list[str]:
        experiments = run.summary.experiments
        rows = [[f'`{exp_id}`', len(s.faults.flagged), s.faults.physics_fault,
                 s.faults.tunnelled, s.faults.thrown, s.faults.unsettled,
                 s.physics.spilled, s.physics.tunnelled, s.physics.thrown,
                 fmt(1000 * s.physics.max_penetration, 3), fmt(s.physics.max_speed, 2),
                 pct(s.physics.tray_error)]
                for exp_id, s in experiments.items()]
        flagged = any(s.faults.flagged for s in experiments.values())
        lead = [] if flagged else ['No iteration was flagged: every settle ended within its '
                                   'cap, no part tunnelled or was thrown, no physics state '
                                   'became NaN.', '']
        return ['', '## Physics health', ''] + lead + table(
            ['experiment', 'iterations flagged', 'NaN state (left out)', 'tunnelled (left out)',
             'thrown (left out)', 'unsettled at the cap (counted)', 'parts spilled',
             'parts tunnelled', 'parts thrown', 'deepest penetration (mm)',
             'fastest part (m/s)', 'worst tray tracking error'],
            rows) + ['', 'Tunnelled: a part ended in or under the floor or in a wall, which '
                     'solid bodies cannot do; thrown: a part moved faster than a fall from '
                     "twice the walls' height or its drop height plus a bounce off the tray can "
                     'make it, so the solver gave it energy; spilled: a part went over a wall. '
                     'Each flagged iteration has its fault in the `fault` column of '
                     '`iterations.csv`.']
