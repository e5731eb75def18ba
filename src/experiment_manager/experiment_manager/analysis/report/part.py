"""The part as the run saw it: the file, its frame, what the physics and the checks collide and
what each grasp closes on (part_sheet.describe), with its sheet."""

from .base import Run, Section


class Part(Section):
    def lines(self, run: Run) -> list[str]:
        if not run.account:
            return []
        lines = ['', '## The part', '', 'As the run saw it (the file, its frame, what the '
                 'physics and the checks collide, what each grasp closes on):', '']
        lines += [f'- {line.strip()}' for line in run.account]
        return lines + ['', '![the part sheet: the part, its collision pieces, and the gripper '
                        "at each grasp's pick and place](part.png)"]
