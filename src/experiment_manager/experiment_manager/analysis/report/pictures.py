"""The pictures of the scenes (analysis/pictures.py), each with its caption, and why parts were
turned down, per experiment (analysis/stages.py)."""

from .. import stages
from .base import Run, Section


class Pictures(Section):
    def lines(self, run: Run) -> list[str]:
        if not run.pictures:
            return []
        lines = ['', '## Pictures']
        for name, caption in run.pictures.items():
            lines += ['', f'![{name}]({name})', '', caption]
        return lines


class TurnedDown(Section):
    def lines(self, run: Run) -> list[str]:
        return stages.lines(run.stops) if run.stops is not None else []
