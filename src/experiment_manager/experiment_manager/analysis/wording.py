"""How the report says numbers and counts, and its Markdown tables: shared by the decisions
(verdicts.py), the rendering (report/) and the terminal (commands/run.py)."""


def fmt(value, digits: int = 3) -> str:
    if value is None:
        return '-'
    if isinstance(value, float):
        return f'{value:.{digits}g}'
    return str(value)


def dims(values) -> str:
    """Sizes as '195 x 150 x 27' (the caller says the unit)."""
    return ' x '.join(fmt(x) for x in values)


def sampling_end(experiment) -> str:
    """How an adaptive experiment's sampling ended, from its summary (summary.py): 'settled'
    (for bins that tie, with them), or 'not settled', for bins with the ones the race could
    not tell from the leader."""
    a = experiment.sampling
    # a summary of version 0 has no race_confidence: its race compared 99.9 % intervals
    bound = (f'one-sided {100 * a.race_confidence:g} % bounds of the differences'
             if a.race_confidence is not None else '99.9 % intervals')
    if a.settled:
        if a.held is not None:
            return (f'settled: its range starts at or above the {a.held} parts its feeder '
                    'runs hold, which they put on the table whatever the range')
        if not a.tie:
            return 'settled'
        return (f'settled: bins {_bins(experiment, a.tie)} mm tie within '
                f'{pct(a.tie_within)} of the first, which has the highest mean ({bound})')
    if not a.tied_bins:
        return 'not settled'
    return f'not settled: bins {_bins(experiment, a.tied_bins)} mm could not be told apart ' \
        f'({bound})'


def _bins(experiment, indices: list[int]) -> str:
    sizes = {b.index: dims(b.size_mm) for b in experiment.bins}
    named = [sizes[g] for g in indices]
    return ' and '.join(filter(None, (', '.join(named[:-1]), named[-1])))


def count(n: int, noun: str) -> str:
    """'1 part', '35 parts': the report's sentences say a count as it is read."""
    return f'{n} {noun}' + ('' if n == 1 else 's')


def pct(value) -> str:
    return '-' if value is None else f'{100 * value:.1f} %'


def table(header: list[str], rows: list[list]) -> list[str]:
    """A Markdown table (GitHub's): a `|` inside a cell is escaped, so it stays in its cell."""
    def cell(value) -> str:
        return fmt(value).replace('|', '\\|')
    lines = ['| ' + ' | '.join(cell(h) for h in header) + ' |', '|' + ' --- |' * len(header)]
    lines += ['| ' + ' | '.join(cell(c) for c in r) + ' |' for r in rows]
    return lines


# How a gripper's dimensions (summary.json's gripper_mm) are said, shortest first.
GRIPPER_WORDS = {'body_diameter_mm': 'D', 'jaw_depth_mm': 'W', 'jaw_height_mm': 'V',
                 'body_length_mm': 'L', 'finger_clearance_mm': 'clearance'}


def gripper_label(variant, keys=tuple(GRIPPER_WORDS), grasp_set: bool = True) -> str:
    """A gripper_sweep variant as 'D 8, W 3 mm; grasps all': the dimensions `keys` (mm) and,
    when asked, the grasp set."""
    sizes = ', '.join(f'{GRIPPER_WORDS[k]} {fmt(float(variant.gripper_mm[k]))}'
                      for k in GRIPPER_WORDS if k in keys)
    out = f'{sizes} mm' if sizes else ''
    if grasp_set:
        out += ('; ' if out else '') + f'grasps {variant.grasp_set}'
    return out


def varying(variants: list) -> tuple[tuple[str, ...], bool]:
    """The gripper dimensions that differ between the variants, and whether the grasp set
    does: what a label needs to tell them apart."""
    keys = tuple(k for k in GRIPPER_WORDS
                 if len({v.gripper_mm[k] for v in variants}) > 1)
    return keys, len({v.grasp_set for v in variants}) > 1


def verdict_table(rows: list[tuple[str, str, str, str]]) -> list[str]:
    """The options' verdicts as aligned columns, option, verdict and the stage that stops
    most parts ('-' when none is known), from (option, verdict, stops, first reason) each;
    the first reason, in brackets, on the line below its row."""
    cells = [(option.replace('`', ''), verdict, stops or '-') for option, verdict, stops, _
             in rows]
    head = ('option', 'verdict', 'stops most parts')
    widths = [max(len(c[k]) for c in [head, *cells]) for k in range(3)]

    def line(c: tuple[str, ...]) -> str:
        return '  ' + '  '.join(x.ljust(w) for x, w in zip(c, widths, strict=True)).rstrip()
    out = [line(head)]
    for c, row in zip(cells, rows, strict=True):
        out += [line(c), f'      ({row[3]})']
    return out
