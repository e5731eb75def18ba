"""What a run ran with, every default applied: `resolved.json` in its run directory, written
once when the run starts (graph/session.py) and read by the report and by `decide` instead of
the raw experiment.yaml, so that a default changed later never changes what an old run's
report says or how it is decided again, and no part is built to decide it.

It holds the part (its model, dimensions, mesh, mass, placing, and the aspects it can rest on
with their normals), its materials with the basis of each value, the gripper (its kind and
every key in the file's units), the grasps, the file's named grippers its experiments run
with (each with its grasps), the tray (size, walls, feeder zone, the hopper's lip), each
feeder run's dose, the table's moves, the requirements and the cell's times, and `defaulted`:
the file's top keys it left to their defaults. In the file's units (mm, g, deg),
as the file would say them; and `records`, what deciding the run reads (the requirements, the
cell, the aspects and every experiment's record), in SI as the run held them
(experiment_file.ran). Pure: no rclpy, no simulator.
"""

import json
import os

from . import ran as ran_records
from .kinds import kind_of
from .loading import load
from .model import ExperimentFile, MM, Ran
from .ran import grasp_keys

NAME = 'resolved.json'
# the top keys of the file the report speaks of when the file leaves them out
TOP_KEYS = ('tray_mm', 'feeder_zone_mm', 'hopper_lip_mm', 'hopper_rate', 'hopper_speed_mm_s',
            'bin_wall_mm', 'bin_drop_mm', 'moves')


def _mm(values) -> list[float]:
    return [round(v / MM, 6) for v in values]


def resolved(file: ExperimentFile) -> dict:
    """The record of `file` as a run uses it."""
    part, gripper, tray, r = file.part, file.gripper, file.tray, file.requirements
    (cx, cy), (sx, sy) = tray.feeder_zone_center, tray.feeder_zone_size
    return {
        'id': file.id, 'seed': file.seed,
        'part': {'model': part.model,
                 'dimensions_mm': {k: (v if k == 'pins_per_row' else round(v / MM, 6))
                                   for k, v in part.dimensions.items()},
                 'mesh': os.path.basename(part.mesh_path) if part.mesh_path else '',
                 'mass_g': None if part.mass is None else round(part.mass / 1e-3, 6),
                 'place': {'axis': list(file.place.place_axis),
                           'seat_offset_mm': round(file.place.seat_offset / MM, 6)},
                 'aspects': [{'name': a.name, 'normal': [round(v, 6) for v in a.normal],
                              'quasi_static': round(a.quasi_static, 6)}
                             for a in file.aspects]},
        'materials': [{'pair': pair, 'basis': dict(bases), 'source': said}
                      for pair, bases, said in file.material_account],
        'gripper': _gripper(gripper),
        'grasps': [grasp_keys(g) for g in file.grasps],
        'grippers': {e.gripper: {**_gripper(e.setup.gripper),
                                 'grasps': [grasp_keys(g) for g in e.setup.grasps]}
                     for e in file.experiments if e.gripper},
        'auto_grasps': file.auto_grasps,
        'tray': {'tray_mm': _mm(tray.inner_size), 'wall_mm': round(tray.wall_thickness / MM, 6),
                 'feeder_zone_mm': {'center': _mm((cx, cy)), 'size': _mm((sx, sy))},
                 'hopper_lip_mm': round(tray.drop_height / MM, 6),
                 'hopper_rate': tray.hopper_rate,
                 'hopper_speed_mm_s': round(tray.hopper_speed / MM, 6)},
        'bin_wall_mm': round(file.bin_wall / MM, 6),
        'doses': {e.id: e.max_feed for e in file.experiments if kind_of(e).feeds},
        'moves': [{'amplitude_mm': _mm(m.amplitude), 'frequency_hz': m.frequency,
                   'duration_s': m.duration, 'direction': m.direction} for m in file.moves],
        'requirements': {'parts_per_hour': r.parts_per_hour,
                         'refill_interval_h': r.refill_interval / 3600.0,
                         'max_dimension_mm': round(r.max_dimension / MM, 6),
                         'max_spilled_parts': r.max_spilled, 'success_rate': r.success_rate},
        'cell': {'pick_s': file.cell.pick_time, 'image_s': file.cell.image_time,
                 'regrasp_s': file.cell.regrasp_time},
        'defaulted': [k for k in TOP_KEYS if k not in file.given],
        'records': ran_records.plain(file.ran),
    }


def _gripper(gripper) -> dict:
    """A gripper's kind and every key of it, in the file's units."""
    return {'type': gripper.kind, **gripper.file_values()}


def write(file: ExperimentFile, run_dir: str) -> str:
    """resolved.json of `file` in `run_dir`; returns its path."""
    path = os.path.join(run_dir, NAME)
    with open(path, 'w', encoding='utf-8') as f:
        json.dump(resolved(file), f, indent=1)
        f.write('\n')
    return path


def read(run_dir: str) -> dict:
    """What the run in `run_dir` ran with: its resolved.json, or, for a run directory made
    before runs wrote one, its experiment.yaml resolved by today's rules (the defaults it left
    out are today's: said by `defaulted`)."""
    path = os.path.join(run_dir, NAME)
    if os.path.exists(path):
        with open(path, encoding='utf-8') as f:
            return json.load(f)
    return json.loads(json.dumps(resolved(load(os.path.join(run_dir, 'experiment.yaml')))))


def ran(run_dir: str) -> Ran:
    """What deciding the run in `run_dir` reads of what it ran with: its resolved.json's
    `records` (experiment_file.ran); for a run directory whose resolved.json keeps none (or
    that has none), its experiment.yaml read again by today's rules. InvalidArgument when that
    file no longer reads; ValueError naming resolved.json when its records are broken."""
    data = read(run_dir)
    if 'records' not in data:
        return load(os.path.join(run_dir, 'experiment.yaml')).ran
    try:
        return ran_records.read(data['records'], data['id'], data['seed'])
    except (KeyError, TypeError, ValueError) as exc:
        raise ValueError(f'{os.path.join(run_dir, NAME)}: its records do not read '
                         f'({type(exc).__name__}: {exc})') from None
