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

from feeder_controller.policy import check_feeder, FeederConfig
from pick_common.containers import check_container, check_fits, ContainerSpec
from pick_common.errors import check_int, InvalidArgument
from pick_common.parts.geometry import PartGeometry
from pick_common.specs import Vibration
from pick_validity.config import (
    check_grasps,
    check_gripper,
    check_place,
    is_suction,
    Setup,
    tilts,
)
import yaml

from . import experiment_keys, grippers, schema, sections
from . import part as part_section
from . import scenarios as scenario_inputs
from .drop_test import drop_test, drop_test_height
from .errors import checked as checked_as
from .errors import read as read_keys
from .model import (
    ADAPTIVE,
    BIN_EMPTYING,
    BIN_STATIC,
    Cell,
    DROP_TEST,
    Experiment,
    ExperimentFile,
    FEEDER_EMPTYING,
    GRIPPER_SWEEP,
    Input,
    MAX_EXPERIMENTS,
    MAX_FILE_BYTES,
    MAX_ITERATIONS,
    MM,
    Sampling,
    SENSITIVITY,
    TABLE_SWEEP,
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
class _Context:
    """What an experiment's checks relate to: the part's geometry, the tray, the bins' wall
    and size limit, the setup (part, gripper, grasps) and table moves, the file's seed, and
    the experiments read before it."""

    def __init__(self, geometry: PartGeometry, tray: ContainerSpec, bin_wall: float,
                 bin_drop: float, max_dimension: float, setup: Setup,
                 moves: tuple[Vibration, ...], seed: int) -> None:
        self.geometry, self.tray, self.bin_wall = geometry, tray, bin_wall
        self.bin_drop = bin_drop
        self.max_dimension, self.setup, self.moves, self.seed = max_dimension, setup, moves, seed
        self.gripper, self.grasps = setup.gripper, setup.grasps
        self.earlier: dict[str, Experiment] = {}
        self.named: dict[str, Setup] = {}           # the file's `grippers`


def _bin(size_mm: tuple[float, ...], where: str, c: _Context) -> ContainerSpec:
    size = tuple(MM * s for s in size_mm)
    for i, s in enumerate(size):
        if s > c.max_dimension + 1e-12:
            raise InvalidArgument(f'{where}[{i}]', round(s / MM, 6),
                                  f'mm is over the size limit requirements.max_dimension_mm '
                                  f'= {c.max_dimension / MM:g}')
    spec = ContainerSpec(inner_size=size, wall_thickness=c.bin_wall, drop_height=c.bin_drop)
    checked_as(check_container, spec, where)
    return spec


def _earlier(where: str, exp_id: str, c: _Context, kind: str, alternative: str) -> Experiment:
    """The earlier experiment of type `kind` named by id at `where`."""
    source = c.earlier.get(exp_id)
    if source is None or source.type != kind:
        raise InvalidArgument(where, exp_id, f'names no earlier {kind} experiment (give its '
                              f'id, or {alternative})')
    return source


def _bin_or_source(value: Any, parts: int, where: str, c: _Context) -> dict:
    """An experiment's `bin`: a bin in mm ({'bin': spec}) or the id of an earlier bin_static
    experiment whose best bin is used ({'bin_from': id}); {} when there is none. `parts` must
    fit in it (in every bin of the source)."""
    volume = c.geometry.volume
    if value is None:
        return {}
    if isinstance(value, str):
        source = _earlier(f'{where}.bin', value, c, BIN_STATIC, 'a bin [x, y, z] in mm')
        for i, b in enumerate(source.bins):
            check_fits(f'{where}.parts ({value}.bins_mm[{i}])', parts, volume, b)
        return {'bin_from': value}
    spec = _bin(value, f'{where}.bin', c)
    check_fits(f'{where}.parts', parts, volume, spec)
    return {'bin': spec}


def _sensitivity(e: experiment_keys.SensitivityKeys, where: str, c: _Context) -> list[Experiment]:
    """A sensitivity experiment and, before it, its repeats of the experiments it names, one
    per scenario (scenarios.py); a repeat takes its bin or range from the same scenario's
    repeat of its source when that is repeated too, else from the source itself."""
    for i, exp_id in enumerate(e.of):
        if c.earlier.get(exp_id) is None or c.earlier[exp_id].type == SENSITIVITY:
            raise InvalidArgument(f'{where}.of[{i}]', exp_id, 'names no earlier experiment '
                                  '(of a type other than sensitivity)')
    if len(set(e.of)) != len(e.of):
        raise InvalidArgument(f'{where}.of', list(e.of), 'names an experiment twice')
    for i, exp_id in enumerate(e.of):
        if c.earlier[exp_id].gripper or c.earlier[exp_id].station:
            raise InvalidArgument(f'{where}.of[{i}]', exp_id, 'runs with a gripper of the '
                                  "file's grippers or a regrasp station; a sensitivity varies "
                                  "the file's own cell")
    inputs = []
    for name, r in e.inputs.items():
        at = f'{where}.inputs.{name}'
        moved = name.removeprefix('part.')
        if name.startswith('part.') and moved in schema.MOVED_KEYS:
            raise InvalidArgument(at, name, f'has moved: vary materials.part_on_surface.{moved} '
                                  f'(the part on the bin or tray) or materials.part_on_part.'
                                  f'{moved} (on another part)')
        if name not in scenario_inputs.INPUTS:
            raise InvalidArgument(at, name, 'is not an input a sensitivity experiment varies ('
                                  + ', '.join(scenario_inputs.INPUTS) + ')')
        sweeps = [x for x in e.of if c.earlier[x].type == GRIPPER_SWEEP]
        if name.startswith('gripper.') and sweeps:
            raise InvalidArgument(at, name, f'cannot reach the gripper_sweep {sweeps[0]}, whose '
                                  'grippers are its own: vary the gripper there, or leave it '
                                  'out of `of`')
        low = scenario_inputs.check_input(name, r.low, f'{at}.low')
        high = scenario_inputs.check_input(name, r.high, f'{at}.high')
        if name == scenario_inputs.DROP_HEIGHT:
            base = drop_test_height(e.of, at, c.earlier)
        else:
            base = scenario_inputs.base_value(name, c.setup, c.geometry.mass, at)
        inputs.append(Input(name, round(base, 9), low, high, r.source.strip()))
    inputs = tuple(inputs)
    repeats = (2 * len(inputs) + e.joint + (e.grid ** len(inputs) if e.grid else 0)) * len(e.of)
    if repeats > scenario_inputs.MAX_REPEATS:
        raise InvalidArgument(f'{where}.inputs', repeats, f'scenarios x experiments repeated '
                              f'is over the limit of {scenario_inputs.MAX_REPEATS} (2 '
                              'scenarios per input, plus joint, plus grid ** inputs, times the '
                              'experiments of `of`)')
    found = scenario_inputs.scenarios(inputs, e.joint, c.setup, c.moves, c.seed, e.id, where,
                                      e.grid)
    repeats = []
    for scenario in found:
        for exp_id in e.of:
            source = c.earlier[exp_id]
            renamed = {key: f'{value}@{scenario.name}' if value in e.of else value
                       for key in ('bin_from', 'range_from')
                       if (value := getattr(source, key))}
            if (height := scenario_inputs.drop_height(scenario)) is not None:
                renamed['bin'] = replace(source.bin, drop_height=height)
            repeats.append(replace(source, id=f'{exp_id}@{scenario.name}',
                                   iterations=min(source.iterations, e.iterations),
                                   scenario=scenario, **renamed))
    return repeats + [Experiment(id=e.id, type=SENSITIVITY, iterations=e.iterations,
                                 of=tuple(e.of), inputs=inputs, scenarios=found,
                                 grid=e.grid)]


def _experiment(e: experiment_keys.ExperimentKeys, where: str, c: _Context) -> list[Experiment]:
    """The experiment read at `where` (with, for a sensitivity experiment, its repeats)."""
    if e.id in c.earlier:
        raise InvalidArgument(f'{where}.id', e.id, 'is the id of an earlier experiment')
    if e.type == SENSITIVITY:
        return _sensitivity(e, where, c)
    volume, tray = c.geometry.volume, c.tray
    out: dict[str, Any] = {'id': e.id, 'type': e.type, 'iterations': e.iterations}
    if e.type == DROP_TEST:
        return [Experiment(**out, **drop_test(e, where, c.geometry, c.bin_wall))]
    if e.type != TABLE_SWEEP:
        out['parts'] = e.parts
    if getattr(e, 'gripper', None) is not None:
        if e.gripper not in c.named:
            raise InvalidArgument(f'{where}.gripper', e.gripper, 'names no gripper of the '
                                  f"file's grippers ({', '.join(c.named) or 'none'})")
        out['gripper'], out['setup'] = e.gripper, c.named[e.gripper]
    if getattr(e, 'scenes_of', None) is not None:
        _earlier(f'{where}.scenes_of', e.scenes_of, c, e.type, 'leave scenes_of out')
        out['seeded_by'] = c.earlier[e.scenes_of].seeded_by or e.scenes_of
    if getattr(e, 'regrasp_station', False):
        mine = out.get('setup', c.setup)
        out['station'] = True
        out['setup'] = replace(mine, config=replace(mine.config, regrasp_station=True))
    if e.type == BIN_STATIC:
        out['bins'] = tuple(_bin(v, f'{where}.bins_mm[{i}]', c) for i, v in enumerate(e.bins_mm))
        for i, b in enumerate(out['bins']):
            check_fits(f'{where}.parts (bins_mm[{i}])', e.parts, volume, b)
    elif e.type == BIN_EMPTYING:
        out.update(_bin_or_source(e.bin, e.parts, where, c))
    elif e.type == TABLE_SWEEP:
        out['counts'] = tuple(range(e.counts.first, e.counts.last + 1, e.counts.step))
        check_fits(f'{where}.counts.last', out['counts'][-1], volume, tray)
        out['margin'] = e.margin
        out['extend'] = e.extend
    elif e.type == GRIPPER_SWEEP:
        scene = _bin_or_source(e.bin, e.parts, where, c)
        if not scene:       # no bin: the parts lie on the tray, as in a table_sweep
            check_fits(f'{where}.parts (tray_mm)', e.parts, volume, tray)
        out.update(scene)
        out['variants'] = grippers.variants(e, where, c.gripper, c.grasps)
        out['min_valid'] = e.min_valid
    elif e.type == FEEDER_EMPTYING:
        if isinstance(e.optimal_range, str):
            source = _earlier(f'{where}.optimal_range', e.optimal_range, c, TABLE_SWEEP,
                              '[min, max]')
            out['range_from'] = e.optimal_range
            high = source.counts[-1] + source.margin
        else:
            out['optimal_range'] = e.optimal_range
            high = e.optimal_range[1]
            checked_as(check_feeder, FeederConfig(e.parts, *e.optimal_range, e.max_vibrations,
                                                  e.max_feed or 0), where)
        out['max_vibrations'] = e.max_vibrations
        out['max_feed'] = e.max_feed or 0
        check_fits(f'{where}.optimal_range (max)', high, volume, tray)
    return [Experiment(**out)]


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
    suction = is_suction(gripper)
    read_part = checked(lambda: part_section.read_part(s['part'], s['materials'], base_dir,
                                                       suction)
                        ) if s['part'] and s['materials'] else None
    part, grasps, place = read_part or (None, None, None)
    check = sections.check(s['check']) if s['check'] else None
    requirements = sections.requirements(s['requirements']) if s['requirements'] else None
    tray = checked(lambda: sections.tray(top)) if top else None
    moves = checked(lambda: sections.moves(top)) if top else None
    # The cores' own checks, under the file's names.
    if gripper is not None:
        checked(lambda: checked_as(check_gripper, gripper, 'gripper'))
    auto_grasps = grasps == part_section.AUTO
    if part is not None:
        checked(lambda: checked_as(check_place, place, 'part.place'))
    if check is not None:
        checked(lambda: checked_as(tilts, check, 'check'))
    geometry = checked(lambda: part_section.geometry(part)) if part is not None else None
    if auto_grasps:
        grasps = checked(lambda: part_section.proposed(geometry, gripper)) \
            if geometry is not None else None
    if grasps is not None:
        checked(lambda: checked_as(check_grasps, list(grasps), 'part.grasps'))
    if None not in (geometry, grasps, gripper, check) and suction:
        checked(lambda: part_section.check_cup(geometry, Setup(part, gripper, grasps, place,
                                                                check)))
    elif geometry is not None and grasps is not None:
        checked(lambda: part_section.check_fits(geometry, grasps))
    if None not in (top, geometry, tray) and top.feeder_zone_mm is not None:
        checked(lambda: sections.zone_holds(top.feeder_zone_mm.size, geometry))
    context = None
    if None not in (top, geometry, tray, moves, requirements, gripper, grasps, check):
        context = _Context(geometry, tray, MM * top.bin_wall_mm, MM * top.bin_drop_mm,
                           requirements.max_dimension,
                           Setup(part, gripper, grasps, place, check), moves, top.seed)
        context.named = checked(lambda: grippers.named(top.grippers, context.setup,
                                                       geometry)) or {}
    raw = data.get('experiments')
    for i, item in enumerate(raw if isinstance(raw, list) and len(raw) <= MAX_EXPERIMENTS
                             else []):
        where = f'experiments[{i}]'
        keys = read(experiment_keys.experiment_model(item), item, where)
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
        part_volume=geometry.volume,
        material_account=part_section.material_account(s['materials']))


def load(path: str) -> ExperimentFile:
    """Read and check the experiment file at `path`."""
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
    return parse(text, path)


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
