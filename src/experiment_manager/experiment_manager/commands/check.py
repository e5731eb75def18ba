"""`run --check FILE...`: read each experiment file as a run would, without starting the graph,
print what the run will use of its part and grasps, and draw the part sheet
(analysis/part_sheet.py) beside it, so that a wrong file is seen before it runs."""

import os
import sys

from pick_common.errors import InvalidArgument

from .. import experiment_file
from ..analysis import part_sheet


def check(paths: list[str], output: str | None) -> int:
    """0 when every file reads and its sheet is drawn; 2 at the first file that does not (its
    errors printed, each naming the file, the key, the value and the rule)."""
    for given in paths:
        path = os.path.abspath(given)
        try:
            file = experiment_file.load(path)
        except InvalidArgument as exc:
            errors = exc.errors if isinstance(exc, experiment_file.InvalidFile) else [exc]
            for e in errors:
                print(f'run --check: {path}: {e}', file=sys.stderr)
            return 2
        checks = part_sheet.validator(file)
        print(f'{path}: reads as a run would')
        print('\n'.join(part_sheet.describe(file, checks)))
        directory = os.path.abspath(os.path.expanduser(output or file.output_dir))
        sheet = part_sheet.write(checks, os.path.join(directory, f'{file.id}_part.png'))
        print(f'sheet: {sheet}')
    return 0
