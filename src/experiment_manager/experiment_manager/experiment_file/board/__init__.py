"""A board as the input: an experiment file with `board:` in place of `part:` becomes one
experiment file per distinct through-hole part of the KiCad board (`expand`), each an
ordinary file a user could have written: its part read from the model's STEP file in KiCad's
frame, its mass from the model's solids (pick_common.parts.solids) unless the board section
gives it, `grasps: auto` unless given, and its requirement the board's `boards_per_hour`
times its quantity per board; a bin's or a feeder's emptying that leaves out `parts` holds
the part's refill (that rate times requirements.refill_interval_h: the load it must hold,
`_loaded`); every other section of the file is the same for every part.

The board section (mm, g as the other sections):
    board:
      pcb: FILE.kicad_pcb          # relative to the experiment file
      models: DIR                   # KiCad's 3D library; default: KiCad's variables
      boards_per_hour: 30
      parts:                        # per part, by its name (run --check lists them)
        R_Axial_DIN0207_L6.3mm_D2.5mm_P10.16mm_Horizontal: {mass_g: 0.25}

Placement from KiCad's frame: a footprint's frame has the board's top surface at z = 0 and
the leads going into -z, and KiCad draws the model at its offset, rotation and scale
(kicad.Model.transform). In the model file's frame the part is placed along the footprint's
-z turned back into the file (`axis`), and its seating plane, the board's top, lies at
offset_z / scale along that axis (`seat_offset_mm`).
"""

from collections.abc import Mapping
from dataclasses import dataclass, field
import os
import re
from typing import Any

import numpy as np
from pick_common.errors import DoesNotFit, InvalidArgument, MeshError
from pick_common.parts.solids import solid_mass, SolidMass
from pydantic import BaseModel, ConfigDict
import yaml

from .. import loading
from ..errors import read as read_keys
from ..experiment_keys import Counts, TableSweepKeys
from ..kinds import keys_model
from ..model import MAX_FILE_BYTES, Requirements
from ..schema import NamedGripper, RequirementsSection
from ..values import Number, Text
from . import kicad
from .answer import answer, record
from .cutting import cut_side_by_side
from .parts import board_parts, BoardPart, DECIDE, NOT_THROUGH_HOLE, REFUSED

# The experiments that hold a refill of the part: their `parts`, left out in a board file, is
# each part's own refill.
REFILLED = ('bin_emptying', 'feeder_emptying')
# The fewest counts a table_sweep cut to what fits keeps: its 4th-order fit's five
# (analysis.metrics.FIT_ORDER + 1); with fewer it is left out.
FEWEST_COUNTS = 5

__all__ = ['answer', 'Board', 'BoardPart', 'cut_side_by_side', 'DECIDE', 'expand', 'is_board',
           'load_board', 'NOT_THROUGH_HOLE', 'placement', 'record', 'REFUSED', 'settle',
           'table', 'write_parts']


class _Keys(BaseModel):
    model_config = ConfigDict(extra='forbid', frozen=True, validate_default=True)


class PartOverride(_Keys):
    """What the file says of one of the board's parts, in place of what the model gives."""
    mass_g: Number(0.0, 10_000.0, low_open=True) | None = None
    grasps: Any = None


class BoardSection(_Keys):
    pcb: Text()
    models: Text() | None = None
    boards_per_hour: Number(0.0, 1e6, low_open=True)
    parts: dict[str, PartOverride] = {}


@dataclass
class Board:
    """A board read: its parts (every distinct model, decided or not, and why), and per part
    to decide its experiment file's text (`files`, by part name) and its mass's account."""
    path: str
    id: str
    boards_per_hour: float
    parts: list[BoardPart]
    output_dir: str = 'results'
    files: dict[str, str] = field(default_factory=dict)
    masses: dict[str, str] = field(default_factory=dict)


def is_board(data: Any) -> bool:
    """An experiment file's data that names a board."""
    return isinstance(data, Mapping) and 'board' in data


def placement(model: kicad.Model) -> tuple[list[float], float]:
    """(place axis in the model file's frame, seat offset mm along it) of a model KiCad draws
    at `model`'s offset, rotation and scale (an even scale: BoardPart refuses others)."""
    matrix = model.transform()
    turn = matrix[:3, :3] / model.scale[0]
    axis = turn.T @ np.array([0.0, 0.0, -1.0])
    axis = [0.0 if abs(v) < 1e-12 else round(float(v), 12) for v in axis]
    return axis, round(float(model.offset[2]) / model.scale[0], 9)


def _part_section(p: BoardPart, override: PartOverride | None, mass: SolidMass | None
                  ) -> dict:
    axis, seat = placement(p.model)
    mass_g = override.mass_g if override is not None and override.mass_g is not None \
        else round(mass.mass * 1000.0, 4)
    grasps = override.grasps if override is not None and override.grasps is not None \
        else 'auto'
    return {'model': 'mesh', 'mesh': p.step, 'mass_g': mass_g,
            'place': {'axis': axis, 'seat_offset_mm': seat}, 'grasps': grasps}


def expand(data: Mapping, path: str, environ: Mapping[str, str] | None = None) -> Board:
    """The board file's `data` (its YAML read) at `path` as a Board. InvalidArgument naming the
    key (board.pcb, board.parts.<name>, ...) for a board section that cannot be read."""
    environ = os.environ if environ is None else environ
    if 'part' in data:
        raise InvalidArgument('part', '...', 'and board are both given: a board file takes '
                              'its parts from the board (board.parts.<name> for what to '
                              'give of one)')
    requirements = data.get('requirements') or {}
    if isinstance(requirements, Mapping) and 'parts_per_hour' in requirements:
        raise InvalidArgument('requirements.parts_per_hour', requirements['parts_per_hour'],
                              'is set per part from board.boards_per_hour times its quantity '
                              'per board: leave it out')
    section, errors = read_keys(BoardSection, data['board'], 'board')
    # the keys every part's file shares: an error there is the file's, refused here, not an
    # option one part cannot run (`settle`)
    refill, more = read_keys(RequirementsSection, requirements, 'requirements')
    errors += more
    raw = data.get('experiments')
    for i, item in enumerate(raw if isinstance(raw, list) else []):
        errors += read_keys(keys_model(item), _loaded(item, 1), f'experiments[{i}]')[1]
    named = data.get('grippers')
    for name, entry in (named.items() if isinstance(named, Mapping) else ()):
        errors += read_keys(NamedGripper, entry, f'grippers.{name}')[1]
    if errors:
        raise errors[0] if len(errors) == 1 else loading.InvalidFile(errors)
    base = os.path.dirname(os.path.abspath(path)) if path else os.getcwd()
    pcb = os.path.normpath(os.path.join(base, os.path.expanduser(section.pcb)))
    models = None
    if section.models is not None:
        models = os.path.normpath(os.path.join(base, os.path.expanduser(section.models)))
        if not os.path.isdir(models):
            raise InvalidArgument('board.models', models, 'is not a folder')
    _, footprints = kicad.read(pcb)
    parts = board_parts(footprints, os.path.dirname(pcb), models, environ, pcb)
    names = {p.name for p in parts}
    for name in section.parts:
        if name not in names:
            raise InvalidArgument(f'board.parts.{name}', name, 'names no part of the board: '
                                  f'its parts are {", ".join(sorted(names))}')
    board_id = data.get('id', 'board')
    if not isinstance(board_id, str) or not re.fullmatch(r'[A-Za-z0-9_-]{1,64}', board_id):
        raise InvalidArgument('id', board_id, 'must be 1..64 letters, digits, _ or -')
    board = Board(path=pcb, id=board_id,
                  boards_per_hour=section.boards_per_hour, parts=[],
                  output_dir=str(data.get('output_dir') or 'results'))
    rest = {k: v for k, v in data.items() if k != 'board'}
    for p in parts:
        if p.status != DECIDE:
            board.parts.append(p)
            continue
        override = section.parts.get(p.name)
        mass = None
        if override is None or override.mass_g is None:
            try:
                mass = solid_mass(p.step)
            except MeshError as exc:
                board.parts.append(_refused(p, f'its model cannot be weighed: {exc.rule}'))
                continue
        board.masses[p.name] = (mass.account() if mass is not None else
                                f'{override.mass_g:g} g, given in board.parts.{p.name}.mass_g')
        rate = section.boards_per_hour * p.quantity
        capacity = Requirements(parts_per_hour=rate,
                                refill_interval=3600.0 * refill.refill_interval_h).capacity
        one = {**rest, 'id': _file_id(board.id, p.name, board.files),
               'part': _part_section(p, override, mass),
               'requirements': {**requirements, 'parts_per_hour': rate}}
        if isinstance(raw, list):
            one['experiments'] = [_loaded(item, capacity) for item in raw]
        header = (f'# {os.path.basename(pcb)}: {p.name}, {p.quantity} per board '
                  f'({", ".join(p.references)}), from the board file {path or "given"}\n'
                  f'# mass: {board.masses[p.name]}\n')
        board.files[p.name] = header + yaml.safe_dump(one, sort_keys=False)
        board.parts.append(p)
    return board


def _loaded(item: Any, capacity: int) -> Any:
    """A board's experiment that holds parts (a bin's or a feeder's emptying) and leaves out
    its `parts`: with `capacity`, the parts of one refill interval of this part (its
    boards_per_hour x quantity x refill_interval_h), the load its bin or feeder must hold."""
    if (isinstance(item, Mapping) and item.get('type') in REFILLED and 'parts' not in item):
        return {**item, 'parts': capacity}
    return item


def _file_id(board_id: str, name: str, taken: Mapping[str, str]) -> str:
    """A part's file id: the board's and the part's names in the id's letters (a '.' of a
    model's name as '_'), at most 64, numbered where two would be the same."""
    base = re.sub(r'[^A-Za-z0-9_-]', '_', f'{board_id}-{name}')[:64]
    ids = {yaml.safe_load(text)['id'] for text in taken.values()}
    out, n = base, 1
    while out in ids:
        n += 1
        out = f'{base[:60]}-{n}'
    return out


def _refused(p: BoardPart, reason: str) -> BoardPart:
    return BoardPart(**{**p.__dict__, 'status': REFUSED, 'reason': reason})


def load_board(path: str) -> Board | None:
    """The board of the experiment file at `path`, or None when the file names no board.
    InvalidArgument for a file that cannot be read, or a board that cannot."""
    try:
        if os.path.getsize(path) > MAX_FILE_BYTES:
            return None                         # the experiment file's loader says why
        with open(path, encoding='utf-8') as f:
            data = yaml.safe_load(f)
    except (OSError, UnicodeDecodeError, yaml.YAMLError):
        return None                             # the experiment file's loader says why
    return expand(data, path) if is_board(data) else None


def write_parts(board: Board, directory: str) -> dict[str, str]:
    """Each part's experiment file written into `directory` (created): its path by part
    name."""
    os.makedirs(directory, exist_ok=True)
    out = {}
    for name, text in board.files.items():
        out[name] = os.path.join(directory, f'{yaml.safe_load(text)["id"]}.yaml')
        with open(out[name], 'w', encoding='utf-8') as f:
            f.write(text)
    return out


def table(board: Board, said: Mapping[str, str] | None = None) -> list[str]:
    """The board as lines of a table, a row per distinct part: its name, quantity per board,
    references, and what became of it (`said`, by part name, over its status and reason)."""
    said = said or {}
    rows = [(p.name, str(p.quantity), ' '.join(p.references),
             said.get(p.name) or (p.status + (f': {p.reason}' if p.reason else '')))
            for p in board.parts]
    width = [max(len(r[i]) for r in rows + [('part', 'qty', 'references', '')])
             for i in range(2)]
    refs = min(28, max(len(r[2]) for r in rows))
    lines = [f'board {os.path.basename(board.path)}: {len(board.parts)} distinct part(s), '
             f'{sum(p.quantity for p in board.parts)} footprint(s); '
             f'{board.boards_per_hour:g} boards per hour',
             f'  {"part":{width[0]}}  {"qty":>{width[1]}}  {"references":{refs}}  status']
    for name, qty, ref, what in rows:
        ref = ref if len(ref) <= refs else ref[:refs - 3] + '...'
        lines.append(f'  {name:{width[0]}}  {qty:>{width[1]}}  {ref:{refs}}  {what}')
    return lines


# An experiment's keys that name another experiment or a gripper.
REFERENCES = ('scenes_of', 'optimal_range', 'bin', 'gripper', 'of')


def settle(path: str) -> tuple[Any, dict[str, str]]:
    """A part's experiment file at `path` read as a run reads it, with what cannot run for
    this part left out: a named gripper that cannot pick it (a cup too large for a resistor's
    body) and its experiments, and an experiment the part cannot run (240 terminal blocks do
    not fit the bin). Those options are not feasible for this part; the others still run. A
    table_sweep whose last count does not fit the tray runs on the counts that do
    (`_cut_to_fit`), its file saying so. Returns (the ExperimentFile, per gripper or
    experiment left out the error that left it out); the file is rewritten without them.
    InvalidArgument (or InvalidFile) for an error of the part itself, or when no experiment is
    left."""
    dropped: dict[str, str] = {}
    while True:
        try:
            return loading.load(path), dropped
        except InvalidArgument as exc:
            errors = exc.errors if isinstance(exc, loading.InvalidFile) else [exc]
            found = [(m, e) for e in errors
                     if (m := re.match(r'grippers\.(\w+)|experiments\[(\d+)\]', e.field))]
            if len(found) < len(errors):
                raise
        with open(path, encoding='utf-8') as f:
            head = ''.join(line for line in f if line.startswith('#'))
        with open(path, encoding='utf-8') as f:
            data = yaml.safe_load(f)
        experiments = data['experiments']
        cut = _cut_to_fit(experiments, found)
        if cut:                     # what it cuts may be all that was wrong: read it again
            _rewrite(path, head + ''.join(f'# {note}\n' for note in cut), data)
            continue
        left: set[str] = set()
        for m, e in found:
            if m.group(1):
                dropped.setdefault(f'gripper {m.group(1)}', str(e))
                data.get('grippers', {}).pop(m.group(1), None)
                left |= {x['id'] for x in experiments if x.get('gripper') == m.group(1)}
        for m, e in found:
            if m.group(2) and int(m.group(2)) < len(experiments):
                exp = experiments[int(m.group(2))]
                # an error for naming what is left out is not news: the experiment's own is
                if e.field.rsplit('.', 1)[-1] not in REFERENCES and exp['id'] not in left:
                    dropped.setdefault(exp['id'], str(e))
                elif exp['id'] not in left:
                    dropped.setdefault(exp['id'], 'it names ' + ', '.join(
                        str(exp[k]) for k in REFERENCES if isinstance(exp.get(k), str)
                        and exp[k] in left | {g.split()[-1] for g in dropped}))
                left.add(exp['id'])
        kept = [x for x in experiments if x['id'] not in left]
        ids = {x['id'] for x in kept}
        for x in kept:              # scenes of an experiment left out: its own seeds
            if x.get('scenes_of') is not None and x['scenes_of'] not in ids:
                del x['scenes_of']
        if not kept or len(kept) == len(experiments):
            raise InvalidArgument('experiments', [x['id'] for x in experiments],
                                  'cannot run for this part: ' + '; '.join(dropped.values()))
        data['experiments'] = kept
        if not data.get('grippers'):
            data.pop('grippers', None)
        _rewrite(path, head + f'# left out for this part: {", ".join(sorted(left))}\n', data)


def _rewrite(path: str, head: str, data: Any) -> None:
    with open(path, 'w', encoding='utf-8') as f:
        f.write(head + yaml.safe_dump(data, sort_keys=False))


def _cut_to_fit(experiments: list, found: list) -> list[str]:
    """The table_sweeps of `experiments` whose last count does not fit the tray (`found`'s
    DoesNotFit on their counts.last) cut to the last of their counts that fits with their
    margin, when at least FEWEST_COUNTS are left: the sweep of a part too large for the
    cell's counts runs on the counts that fit it (and a feeder reading its range, whose max
    is checked the same way, holds no more than they). Returns a note per sweep cut."""
    notes = []
    for m, e in found:
        if not (m.group(2) and isinstance(e, DoesNotFit) and e.field.endswith('.counts.last')):
            continue
        exp = experiments[int(m.group(2))]
        counts = exp.get('counts') or {}
        first = counts.get('first', Counts().first)
        step = counts.get('step', Counts().step)
        top = e.most - exp.get('margin', TableSweepKeys.model_fields['margin'].default)
        last = first + (top - first) // step * step
        if top < first or (last - first) // step + 1 < FEWEST_COUNTS:
            continue
        exp['counts'] = {**counts, 'first': first, 'last': last, 'step': step}
        notes.append(f'{exp["id"]}: counts.last {e.value} cut to {last}: at most {e.most} of '
                     'these parts fit the tray within the packing limit, with the margin')
    return notes
