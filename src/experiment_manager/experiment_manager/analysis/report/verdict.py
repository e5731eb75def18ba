"""The report's head: the part, the gripper and the requirement, then the verdict per option
with its reasons, and the grounds each verdict rests on (the bound it was decided on)."""

from pick_validity.grippers import KINDS

from ..wording import fmt, pct, table
from .base import Run, Section


def _gripper(kind: str, values: dict) -> str:
    """The gripper a run ran with, as people read it ('parallel jaws: body diameter 8 mm,
    ...'), its keys' names and units its kind's (pick_validity.grippers)."""
    keys = {k.file_key: k for k in KINDS[kind].KEYS}
    return f'{KINDS[kind].description}: ' + ', '.join(
        f'{keys[key].field.replace("_", " ")} {fmt(value)}'
        + (f' {keys[key].unit}' if keys[key].unit else '') for key, value in values.items())


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


def _bound(ground) -> str:
    """A ground's bound as read: a time in minutes, a share in per cent, else a number."""
    if ground.quantity.startswith('time'):
        return f'{ground.bound / 60:.1f} min (refill interval {ground.refill_s / 60:g} min)'
    if ground.quantity.startswith('share'):
        return pct(ground.bound)
    return fmt(ground.bound)


class Head(Section):
    def lines(self, run: Run) -> list[str]:
        s = run.summary
        r = s.requirements
        lines = [f'# Picking feasibility: {s.id}', '',
                 f'Part `{run.part_model}`{_sizes(run.part_dimensions_mm, ", ")}; gripper '
                 f'{_gripper(run.gripper_type, run.gripper)}; seed {s.seed}.', '',
                 f'Requirement: {fmt(r.parts_per_hour)} parts per hour, a refill every '
                 f'{fmt(r.refill_interval_h)} h (capacity {r.capacity} parts), no bin longer '
                 f'than {fmt(r.max_dimension_mm)} mm in any dimension (every bin analysed '
                 'meets it: the experiment file refuses others).', '', '## Verdict', '']
        lines += table(['option', 'verdict', 'stops most parts', 'why'],
                       [[v.option, f'**{v.verdict}**', v.stops or '-', '; '.join(v.reasons)]
                        for v in run.verdicts])
        grounds = [[v.option, name, g.quantity, g.verdict,
                    '' if g.bound is None else _bound(g), g.interval, g.runs]
                   for v in run.verdicts for name, g in v.grounds.items()]
        if grounds:
            lines += ['', 'What each verdict rests on (the bound it was decided on; a ground '
                      'UNDECIDED is not settled by the runs so far):', '']
            lines += table(['option', 'ground', 'quantity', 'says', 'bound', 'interval',
                            'runs'], grounds)
        return lines
