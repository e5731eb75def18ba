"""Whether two run directories hold the same results, wall times aside.

    python3 tools/same_results.py RUN_DIR_A RUN_DIR_B

Compares the result files a run writes (iterations.csv, checks.csv, parts.csv, picks.csv as
text, row by row, without their wall_time columns; summary.json without its wall-time keys
and its schema_version, which names the file's format, not a result)
and prints, per file, 'same' or the first difference. Exit 0 when every file is the same, 1
otherwise, 2 for a directory that is not a run directory. Standard library only, so that it
compares runs made by two versions of the code (a restructure must not change a result).
"""

import csv
import json
import os
import sys

CSV_FILES = ('iterations', 'checks', 'parts', 'picks')
TIMES = ('wall_time',)    # a key or column is a time when its name contains one of these
FORMAT = ('schema_version',)    # keys that name the format of summary.json


def _is_time(name: str) -> bool:
    return any(t in name for t in TIMES)


def _rows(path: str) -> list[dict]:
    with open(path, newline='', encoding='utf-8') as f:
        return [{k: v for k, v in row.items() if not _is_time(k)} for row in csv.DictReader(f)]


def _without_times(value):
    if isinstance(value, dict):
        return {k: _without_times(v) for k, v in value.items()
                if not _is_time(k) and k not in FORMAT}
    if isinstance(value, list):
        return [_without_times(v) for v in value]
    return value


def _first_difference(a, b, where: str = '') -> str:
    if type(a) is not type(b):
        return f'{where or "top"}: {a!r} against {b!r}'
    if isinstance(a, dict):
        for key in sorted(set(a) | set(b)):
            if key not in a or key not in b:
                return f'{where}.{key}: only in {"the first" if key in a else "the second"}'
            found = _first_difference(a[key], b[key], f'{where}.{key}')
            if found:
                return found
        return ''
    if isinstance(a, list):
        if len(a) != len(b):
            return f'{where or "top"}: {len(a)} items against {len(b)}'
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            found = _first_difference(x, y, f'{where}[{i}]')
            if found:
                return found
        return ''
    return '' if a == b else f'{where or "top"}: {a!r} against {b!r}'


def compare(dir_a: str, dir_b: str) -> list[tuple[str, str]]:
    """(file, '' when the same or the first difference) for each result file."""
    out = []
    for name in CSV_FILES:
        a, b = (_rows(os.path.join(d, f'{name}.csv')) for d in (dir_a, dir_b))
        out.append((f'{name}.csv', _first_difference(a, b, 'rows')))
    a, b = (_without_times(json.load(open(os.path.join(d, 'summary.json'), encoding='utf-8')))
            for d in (dir_a, dir_b))
    out.append(('summary.json', _first_difference(a, b)))
    return out


def main(argv: list[str]) -> int:
    if len(argv) != 2:
        print(__doc__.split('\n\n')[1], file=sys.stderr)
        return 2
    for d in argv:
        if not os.path.isfile(os.path.join(d, 'summary.json')):
            print(f'same_results: {d!r} is not a run directory (no summary.json)',
                  file=sys.stderr)
            return 2
    results = compare(*argv)
    for name, difference in results:
        print(f'{name:<16} {difference or "same"}')
    return 0 if not any(d for _, d in results) else 1


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
