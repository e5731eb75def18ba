"""Each gripper_sweep: every gripper and grasp set checked on the same scenes, their stage
fractions and valid parts per check against the yield required, the smallest that meets it."""

from ..verdicts import interval_text
from ..wording import dims, fmt, gripper_label, pct, table
from .base import Run, Section


class Grippers(Section):
    def lines(self, run: Run) -> list[str]:
        sweeps = run.summary.of_type('gripper_sweep')
        lines = []
        for exp_id, s in sweeps:
            lines += ['', f'## Gripper sweep (`{exp_id}`)', '']
            if run.figures.get('grippers') and exp_id == sweeps[-1][0]:   # the one plotted
                lines += ['![gripper sweep](grippers.png)', '']
            lines += [f'Every gripper and grasp set checked (all four stages) on the same '
                      f'{s.iterations} scenes of {s.parts} parts in the '
                      f'{dims(s.scene_mm)} mm container. A gripper meets the yield when the '
                      f'95 % interval of its valid parts per check lies at or above '
                      f'{fmt(s.min_valid)} (min_valid). D: body diameter, W: jaw depth, V: jaw '
                      "height, L: body length, clearance: fingertips above the part's bottom.",
                      '']
            rows = []
            for v in s.variants:
                f = v.fractions
                rows.append([gripper_label(v), pct(f.candidates.mean), pct(f.placeable.mean),
                             pct(f.container_free.mean), pct(f.valid.mean), fmt(v.valid.mean),
                             interval_text(v), f'{v.scenes_with_valid}/{v.scenes}',
                             ('**smallest**' if v.index == s.smallest else 'yes')
                             if v.meets else 'no'])
            lines += table(['gripper', 'candidacy', 'placeability', 'container free', 'valid',
                            'valid per check', '95 % interval', 'scenes with a valid part',
                            'meets'], rows)
        return lines
