"""How the report says numbers and counts, and its Markdown tables: shared by the decisions
(verdicts.py) and the rendering (report.py)."""


def fmt(value, digits: int = 3) -> str:
    if value is None:
        return '-'
    if isinstance(value, float):
        return f'{value:.{digits}g}'
    return str(value)


def count(n: int, noun: str) -> str:
    """'1 part', '35 parts': the report's sentences say a count as it is read."""
    return f'{n} {noun}' + ('' if n == 1 else 's')


def pct(value) -> str:
    return '-' if value is None else f'{100 * value:.1f} %'


def of_type(summary: dict, kind: str) -> list[tuple[str, dict]]:
    return [(k, v) for k, v in summary['experiments'].items() if v['type'] == kind]


def table(header: list[str], rows: list[list]) -> list[str]:
    lines = ['| ' + ' | '.join(header) + ' |', '|' + ' --- |' * len(header)]
    lines += ['| ' + ' | '.join(fmt(c) for c in r) + ' |' for r in rows]
    return lines
