"""The rows of a run's results: what one iteration records (`Record`) and the columns of each
results file, in one place. The iteration procedures fill the rows; results.py writes and
reads them; metrics.py and the report read them back.

A row is a dict keyed by column name. Poses are xyz in metres and an xyzw quaternion.
"""

from dataclasses import dataclass, field

POSE = ('x', 'y', 'z', 'qx', 'qy', 'qz', 'qw')
GRIPPER_POSE = ('gripper_x', 'gripper_y', 'gripper_z', 'gripper_qx', 'gripper_qy',
                'gripper_qz', 'gripper_qw')
KEY = ('experiment', 'group', 'iteration')
ITERATION_COLUMNS = (
    'experiment', 'type', 'group', 'iteration', 'seed', 'container_x', 'container_y',
    'container_z', 'parts', 'checked', 'outside', 'candidates', 'placeable', 'container_free',
    'valid', 'checks', 'picks', 'settled', 'unsettled', 'spilled', 'tunnelled', 'thrown',
    'max_penetration', 'max_speed', 'tray_error', 'emptied', 'vibrations', 'feeds', 'stop',
    'fault', 'table_time', 'wall_time', 'aspect', 'regrasps')
CHECK_COLUMNS = (*KEY, 'check', 'parts_on_table', 'checked', 'outside', 'candidates',
                 'placeable', 'container_free', 'valid', 'picked_id', 'searches', 'vibrations',
                 'wall_time')
PART_COLUMNS = (*KEY, 'check', 'part_id', *POSE, 'inside', 'stage', 'grasp', 'tilts')
PICK_COLUMNS = (*KEY, 'pick', 'check', 'part_id', 'searches', 'vibrations', 'grasp',
                *GRIPPER_POSE, 'regrasp')
FILES = {'iterations': ITERATION_COLUMNS, 'checks': CHECK_COLUMNS, 'parts': PART_COLUMNS,
         'picks': PICK_COLUMNS}
TEXT = {'experiment', 'type', 'stop', 'fault', 'aspect'}
FLOAT = {'container_x', 'container_y', 'container_z', 'max_penetration', 'max_speed',
         'tray_error', 'table_time', 'wall_time', *POSE, *GRIPPER_POSE}
BOOL = {'settled', 'emptied', 'inside'}


def parse_row(row: dict) -> dict:
    """A CSV row with its values typed again."""
    out = {}
    for k, v in row.items():
        if k in TEXT:
            out[k] = v
        elif k in FLOAT:
            out[k] = float(v)
        elif k in BOOL:
            out[k] = v == 'True'
        else:
            out[k] = int(v)
    return out


@dataclass
class Record:
    """The rows of one finished iteration: its `iterations.csv` row and its rows of the other
    files."""

    iteration: dict
    checks: list[dict] = field(default_factory=list)
    parts: list[dict] = field(default_factory=list)
    picks: list[dict] = field(default_factory=list)
