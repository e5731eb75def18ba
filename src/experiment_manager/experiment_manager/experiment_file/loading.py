"""Reading an experiment file: YAML, then each section and each experiment through its model
(`schema`; its errors named by `errors`), then the SI dataclasses a run uses (`model`), with
the checks that relate one section to another and the cores' own checks, under the file's key
names.

Every error is an `InvalidArgument` naming the key by its path in the file, the value and the
rule. Every section and every experiment is read, and all their errors come at once
(`InvalidFile`); the checks that relate sections (a bin within requirements.max_dimension_mm,
parts that fit their container, an experiment named by another) run where the sections they
relate were read without error. The annotated example is `config/default_experiment.yaml`.
"""

from collections.abc import Callable, Mapping
from dataclasses import replace
import os
from typing import Any

from pick_common.errors import check_int, InvalidArgument
from pick_common.parts.aspects import part_aspects
from pick_common.parts.spec import PartSpec
from pick_validity.config import check_place, Setup, tilts
import yaml

from . import experiment_keys, grippers, schema, sections
from . import part as part_section
from .errors import checked as checked_as
from .errors import read as read_keys
from .kinds import Context, keys_model, KINDS
from .kinds.context import earlier
from .model import (
    ADAPTIVE,
    Cell,
    Experiment,
    ExperimentFile,
    MAX_EXPERIMENTS,
    MAX_FILE_BYTES,
    MAX_ITERATIONS,
    MM,
    Sampling,
)
from .values import short


class InvalidFile(InvalidArgument):
    """Every error found in an experiment file. `errors` lists them; field, value and rule
    are the first's, and the message lists all."""

    def __init__(self, errors: list[InvalidArgument]) -> None:
        first = errors[0]
        super().__init__(first.field, first.value, first.rule)
        self.errors = list(errors)
        if len(errors) > 1:
            self.args = (f'{len(errors)} errors:\n' + '\n'.join(f'  {e}' for e in errors),)


# -------------------------------------------------------------------------- experiments
def _experiment(e: experiment_keys.ExperimentKeys, where: str, c: Context) -> list[Experiment]:
    """The experiment read at `where` (with, for a sensitivity experiment, its repeats): what
    every kind reads (its id, and of an experiment of the cell's picking its parts, gripper,
    scenes and station), then its kind's own keys (kinds.ExperimentKind.read)."""
    if e.id in c.earlier:
        raise InvalidArgument(f'{where}.id', e.id, 'is the id of an earlier experiment')
    out: dict[str, Any] = {'id': e.id, 'iterations': e.iterations}
    if 'parts' in type(e).model_fields:
        out['parts'] = e.parts
    if getattr(e, 'gripper', None) is not None:
        if e.gripper not in c.named:
            raise InvalidArgument(f'{where}.gripper', e.gripper, 'names no gripper of the '
                                  f"file's grippers ({', '.join(c.named) or 'none'})")
        out['gripper'], out['setup'] = e.gripper, c.named[e.gripper]
    if getattr(e, 'scenes_of', None) is not None:
        earlier(f'{where}.scenes_of', e.scenes_of, c, e.type, 'leave scenes_of out')
        out['seeded_by'] = c.earlier[e.scenes_of].seeded_by or e.scenes_of
    if getattr(e, 'regrasp_station', False):
        mine = out.get('setup', c.setup)
        out['station'] = True
        out['setup'] = replace(mine, config=replace(mine.config, regrasp_station=True))
    return KINDS[e.type].read(e, where, c, out)


# ------------------------------------------------------------------------------- the file
def parse(text: str, path: str = '') -> ExperimentFile:
    """Read and check an experiment file's text. Raises InvalidArgument for one error,
    InvalidFile (an InvalidArgument) listing every error found when there are more."""
    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, 'problem_mark', None)
        where = f'line {mark.line + 1}, column {mark.column + 1}' if mark else 'file'
        raise InvalidArgument(where, path, f'is not valid YAML: '
                              f'{getattr(exc, "problem", None) or exc}') from None
    if not isinstance(data, Mapping):
        raise InvalidArgument('file', short(data), 'must be a mapping of keys')
    if 'board' in data:
        raise InvalidArgument('board', short(data['board']), 'names a board, whose parts are '
                              'each an experiment file of their own: `run` and `run --check` '
                              'read it part by part (experiment_file.board)')
    base_dir = os.path.dirname(os.path.abspath(path)) if path else os.getcwd()
    errors: list[InvalidArgument] = []

    def checked(step: Callable[[], Any]) -> Any:
        """One check run; its error kept, and the next check run."""
        try:
            return step()
        except InvalidArgument as exc:
            errors.append(exc)
        return None

    def read(model: type[schema.Section], value: Any, where: str) -> Any:
        value, found = read_keys(model, value, where)
        errors.extend(found)
        return value

    top = read(schema.FileKeys, data, '')
    s = {key: read(model, data.get(key, {}), key) for key, model in schema.SECTIONS.items()}
    gripper = sections.gripper(s['gripper']) if s['gripper'] else None
    read_part = checked(lambda: part_section.read_part(s['part'], s['materials'], base_dir)
                        ) if s['part'] and s['materials'] else None
    part, place = read_part or (None, None)
    check = sections.check(s['check']) if s['check'] else None
    requirements = sections.requirements(s['requirements']) if s['requirements'] else None
    tray = checked(lambda: sections.tray(top)) if top else None
    moves = checked(lambda: sections.moves(top)) if top else None
    # The cores' own checks, under the file's names.
    if gripper is not None:
        gripper = checked(lambda: checked_as(lambda g: g.check(), gripper, 'gripper'))
    auto_grasps = s['part'] is not None and s['part'].grasps == part_section.AUTO
    if part is not None and checked(lambda: checked_as(check_place, place, 'part.place')) is None:
        place = None
    if check is not None and checked(lambda: checked_as(tilts, check, 'check')) is None:
        check = None
    geometry = checked(lambda: part_section.geometry(part)) if part is not None else None
    grasps = None
    if None not in (geometry, gripper, place, check):
        grasps = checked(lambda: part_section.grasps_for(
            s['part'].grasps, gripper, geometry, Setup(part, gripper, (), place, check)))
    if None not in (top, geometry, tray) and top.feeder_zone_mm is not None:
        checked(lambda: sections.zone_holds(top.feeder_zone_mm.size, geometry))
    context = None
    if None not in (top, geometry, tray, moves, requirements, gripper, grasps, check):
        context = Context(geometry, tray, MM * top.bin_wall_mm, MM * top.bin_drop_mm,
                           requirements.max_dimension,
                           Setup(part, gripper, grasps, place, check), moves, top.seed)
        context.named = checked(lambda: grippers.named(top.grippers, context.setup,
                                                       geometry)) or {}
    raw = data.get('experiments')
    for i, item in enumerate(raw if isinstance(raw, list) and len(raw) <= MAX_EXPERIMENTS
                             else []):
        where = f'experiments[{i}]'
        keys = read(keys_model(item), item, where)
        if keys is not None and context is not None:
            read_here = checked(lambda keys=keys, where=where: _experiment(keys, where,
                                                                            context))
            for e in read_here or ():
                context.earlier[e.id] = e
    # one error per field: a check that fails again on a value already refused is not news
    fields: set[str] = set()
    errors = [e for e in errors if not (e.field in fields or fields.add(e.field))]
    if errors:
        raise errors[0] if len(errors) == 1 else InvalidFile(errors)
    return ExperimentFile(
        id=top.id, seed=top.seed, output_dir=top.output_dir,
        setup=Setup(part, gripper, grasps, place, check), search_order=s['check'].search_order,
        tray=tray, moves=moves, bin_wall=MM * top.bin_wall_mm, requirements=requirements,
        experiments=tuple(context.earlier.values()),
        sampling=Sampling(mode=s['sampling'].mode, batch=s['sampling'].batch),
        cell=Cell(pick_time=s['cell'].pick_s, image_time=s['cell'].image_s,
                  regrasp_time=s['cell'].regrasp_s),
        path=os.path.abspath(path) if path else '', text=text, auto_grasps=auto_grasps,
        given=frozenset(top.model_fields_set),
        part_volume=geometry.volume, aspects=part_aspects(geometry),
        material_account=part_section.material_account(s['materials']))


def load(path: str) -> ExperimentFile:
    """Read and check the experiment file at `path`."""
    return parse(load_text(path), path)


def load_text(path: str) -> str:
    """The text of the experiment file at `path`; InvalidArgument naming why it cannot be
    read (too large, unreadable, not UTF-8)."""
    try:
        size = os.path.getsize(path)
        if size > MAX_FILE_BYTES:
            raise InvalidArgument('experiment_file', path, f'is {size} bytes (limit '
                                  f'{MAX_FILE_BYTES})')
        with open(path, encoding='utf-8') as f:
            text = f.read()
    except OSError as exc:
        raise InvalidArgument('experiment_file', path,
                              f'cannot be read: {exc.strerror or exc}') from None
    except UnicodeDecodeError as exc:
        raise InvalidArgument('experiment_file', path, f'is not UTF-8 text: {exc}') from None
    return text


def part_of(path: str) -> PartSpec:
    """The part of the experiment file at `path` as `load` reads it (its `part` and
    `materials` sections only: what its geometry is built from), without the rest of the
    file's checks. InvalidArgument for the first error."""
    data = yaml.safe_load(load_text(path))
    if not isinstance(data, Mapping):
        raise InvalidArgument('file', short(data), 'must be a mapping of keys')
    s = {}
    for key in ('part', 'materials'):
        s[key], errors = read_keys(schema.SECTIONS[key], data.get(key, {}), key)
        if errors:
            raise errors[0]
    return part_section.read_part(s['part'], s['materials'],
                                  os.path.dirname(os.path.abspath(path)))[0]


def reduced(file: ExperimentFile, max_iterations: int | None, adaptive: bool = False) -> str:
    """The text of `file` with every experiment's iterations capped at `max_iterations` (None:
    as they are), with adaptive sampling when `adaptive`, and the mesh path made absolute, as
    a file that can live anywhere (a quick look at a long study; the run directory keeps the
    file that ran). Comments are not kept."""
    data = yaml.safe_load(file.text)
    said = []
    if max_iterations is not None:
        check_int('max_iterations', max_iterations, low=1, high=MAX_ITERATIONS)
        for item in data['experiments']:
            item['iterations'] = min(int(item['iterations']), max_iterations)
        said.append(f'every experiment capped at {max_iterations} iteration(s)')
    if adaptive:
        data['sampling'] = {**(data.get('sampling') or {}), 'mode': ADAPTIVE}
        said.append('adaptive sampling')
    if file.part.mesh_path:
        data['part']['mesh'] = file.part.mesh_path
    header = f'# {file.path or file.id}, with {" and ".join(said) or "no change"}\n'
    return header + yaml.safe_dump(data, sort_keys=False)
