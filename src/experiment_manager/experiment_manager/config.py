"""The experiment file: its schema, read and checked in one place before anything runs.

A YAML file describes the part, the gripper, the containers, the requirements and a list of
experiments. Lengths are in mm and angles in degrees only where the key says so (`size_mm`,
`tolerance_deg`); everything is converted to SI here. Unknown keys are errors, named with the
nearest known key. Every error is an `InvalidArgument` naming the field by its path in the file
(`experiments[1].bins_mm[0][2]`), the value and the rule; a file is checked section by section
and experiment by experiment, and all the errors found come at once (`InvalidFile`). The
annotated example is `config/default_experiment.yaml`.
"""

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
import difflib
import itertools
import math
import os
from typing import Any

from feeder_controller.policy import check_feeder, FeederConfig
from pick_common.containers import check_container, check_fits, ContainerSpec, TRAY_DEFAULT_SIZE
from pick_common.errors import check_int, check_number, InvalidArgument
from pick_common.parts import build_part, BUILTIN_MODELS, PartSpec
from pick_common.specs import (
    check_vibration,
    DIRECTIONS,
    MAX_MOVES,
    MAX_PARTS_PER_INSTANCE,
    MAX_SEED,
    MOVES,
    Vibration,
)
from pick_validity.config import (
    CAPACITOR_GRASPS,
    check_grasps,
    check_gripper,
    check_place,
    CheckConfig,
    GraspPose,
    Gripper,
    PlaceSpec,
    tilts,
)
import yaml

BIN_STATIC, BIN_EMPTYING, TABLE_SWEEP, FEEDER_EMPTYING, GRIPPER_SWEEP = (
    'bin_static', 'bin_emptying', 'table_sweep', 'feeder_emptying', 'gripper_sweep')
TYPES = (BIN_STATIC, BIN_EMPTYING, TABLE_SWEEP, FEEDER_EMPTYING, GRIPPER_SWEEP)
SEARCH_ORDERS = ('top_first', 'random', 'id')
FIXED, ADAPTIVE = 'fixed', 'adaptive'
SAMPLING_MODES = (FIXED, ADAPTIVE)
MAX_ITERATIONS = 10_000
MAX_BINS = 100
MAX_EXPERIMENTS = 50
MAX_VARIANTS = 64         # grippers x grasp sets of one gripper_sweep
MAX_FILE_BYTES = 1_000_000
ID_CHARS = set('abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-')


@dataclass(frozen=True)
class Requirements:
    """The production requirement: parts of this type per hour, hours between refills of a bin
    or the feeder, the largest bin length in any dimension, m, the parts a feeder run may
    spill over the tray's walls (a cell catches none by default: a spilled part is lost), and
    the share of bins and of feeder runs that must succeed (empty, within the spill limit),
    which a verdict needs at 95 % confidence (verdicts.py). 0.9: the highest share that the
    paper's fixed counts can show when every iteration succeeds (40 bins: 95 % interval from
    0.912; 50 runs: from 0.929; 36 iterations are the fewest that reach 0.9)."""

    parts_per_hour: float = 60.0
    refill_interval: float = 4.0 * 3600.0      # s
    max_dimension: float = 0.3                 # m
    max_spilled: int = 0                       # parts per feeder run
    success_rate: float = 0.9                  # share of bins / feeder runs

    @property
    def capacity(self) -> int:
        """Parts a bin or feeder must hold to last one refill interval."""
        return math.ceil(self.parts_per_hour * self.refill_interval / 3600.0)


@dataclass(frozen=True)
class Cell:
    """The picking cell's own times, for its throughput (metrics.feeder_emptying): the robot's
    pick-and-place cycle per part, s, and the vision system's image per check (after every
    pick and every vibration), s. The table's time comes from the simulation: each feed's and
    vibration's simulated duration until the parts rest. 4 s per pick: the fast end of the 4
    to 10 s a hand insertion of a wired part takes (docs/decisions.md); 0 s per image: not
    counted unless set. Set both to the cell's measured figures."""

    pick_time: float = 4.0      # s
    image_time: float = 0.0     # s


@dataclass(frozen=True)
class Sampling:
    """How many iterations an experiment runs. fixed: its `iterations` (per bin or count), as
    the paper's counts. adaptive: batches of `batch` iterations per group until its decision
    is settled (sampling.py), at most its `iterations`."""

    mode: str = FIXED
    batch: int = 5

    @property
    def adaptive(self) -> bool:
        return self.mode == ADAPTIVE


@dataclass(frozen=True)
class GripperVariant:
    """One gripper and grasp set of a gripper_sweep: the gripper, the name of the grasp set
    (a key of the experiment's `grasp_sets`) and its grasps, in part.grasps order."""

    gripper: Gripper
    grasp_set: str
    grasps: tuple[GraspPose, ...]

    @property
    def size(self) -> tuple[float, float, float, float]:
        """What "smaller" means when grippers are compared: the body's diameter first (what
        must fit between neighbours), then the jaws' depth and height, then the body's length."""
        g = self.gripper
        return g.body_diameter, g.jaw_depth, g.jaw_height, g.body_length


@dataclass(frozen=True)
class Experiment:
    """One experiment of the file.

    bins: bin_static's candidate bins. bin: bin_emptying's bin, or None when `bin_from` names
    the bin_static experiment whose best bin is used (gripper_sweep: the same, and neither
    means the tray). counts: table_sweep's parts on the tray. optimal_range:
    feeder_emptying's [min*, max*], or None when `range_from` names the table_sweep whose
    optimum is used. variants: gripper_sweep's grippers and grasp sets, checked on the same
    scenes; min_valid: the valid parts per check a gripper must give (its 95 % interval's low
    end at least this).
    """

    id: str
    type: str
    iterations: int
    parts: int = 0
    bins: tuple[ContainerSpec, ...] = ()
    bin: ContainerSpec | None = None
    bin_from: str = ''
    counts: tuple[int, ...] = ()
    margin: int = 5
    optimal_range: tuple[int, int] | None = None
    range_from: str = ''
    max_vibrations: int = 500
    variants: tuple[GripperVariant, ...] = ()
    min_valid: float = 1.0


@dataclass(frozen=True)
class ExperimentFile:
    """Everything a run needs, in SI units. `path` is the file read; `text` its content."""

    id: str
    seed: int
    output_dir: str
    part: PartSpec
    gripper: Gripper
    grasps: tuple[GraspPose, ...]
    place: PlaceSpec
    check: CheckConfig
    search_order: str
    tray: ContainerSpec
    moves: tuple[Vibration, ...]
    bin_wall: float
    requirements: Requirements
    experiments: tuple[Experiment, ...]
    sampling: Sampling = Sampling()
    cell: Cell = Cell()
    path: str = ''
    text: str = field(default='', repr=False)

    def experiment(self, experiment_id: str) -> Experiment:
        return next(e for e in self.experiments if e.id == experiment_id)


class InvalidFile(InvalidArgument):
    """Every error found in an experiment file: one per section or experiment at most (a
    section's later checks may depend on its first error's value). `errors` lists them;
    field, value and rule are the first's, and the message lists all."""

    def __init__(self, errors: list[InvalidArgument]) -> None:
        first = errors[0]
        super().__init__(first.field, first.value, first.rule)
        self.errors = list(errors)
        if len(errors) > 1:
            self.args = (f'{len(errors)} errors:\n' + '\n'.join(f'  {e}' for e in errors),)


def _nearest(key: str, candidates) -> str | None:
    """The candidate closest to `key`, when one is close enough to be what was meant."""
    match = difflib.get_close_matches(str(key), [str(c) for c in candidates], n=1, cutoff=0.6)
    return match[0] if match else None


class _Map:
    """A mapping of the file under a path; takes its keys one by one and rejects the rest."""

    def __init__(self, value: Any, path: str) -> None:
        if not isinstance(value, Mapping):
            raise InvalidArgument(path or 'file', _short(value), 'must be a mapping of keys')
        self.value, self.path, self.taken = value, path, set()

    def where(self, key: str) -> str:
        return f'{self.path}.{key}' if self.path else key

    def get(self, key: str, default: Any = None, required: bool = False) -> Any:
        self.taken.add(key)
        if key not in self.value:
            if required:
                # A misspelt required key reads as the typo it is, not only as a missing key.
                typo = _nearest(key, self.value)
                if typo is not None:
                    raise InvalidArgument(self.where(typo), _short(self.value[typo]),
                                          f'is not a known key here (did you mean {key}? it '
                                          'is required)')
                raise InvalidArgument(self.where(key), None, 'is required')
            return default
        return self.value[key]

    def number(self, key: str, default: float | None, low: float | None = None,
               high: float | None = None, low_open: bool = False, scale: float = 1.0) -> float:
        value = self.get(key, default, required=default is None)
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise InvalidArgument(self.where(key), value, 'is not a number')
        return scale * check_number(self.where(key), value, low=low, high=high,
                                    low_open=low_open)

    def integer(self, key: str, default: int | None, low: int, high: int) -> int:
        value = self.get(key, default, required=default is None)
        return check_int(self.where(key), value, low=low, high=high)

    def text(self, key: str, default: str | None, choices: tuple[str, ...] = ()) -> str:
        value = self.get(key, default, required=default is None)
        if not isinstance(value, str):
            raise InvalidArgument(self.where(key), _short(value), 'is not a string')
        if choices and value not in choices:
            raise InvalidArgument(self.where(key), value, f'must be one of {", ".join(choices)}')
        return value

    def vector(self, key: str, default: Any, length: int, low: float | None = None,
               high: float | None = None, low_open: bool = False,
               scale: float = 1.0) -> tuple[float, ...]:
        return _vector(self.get(key, default, required=default is None), self.where(key),
                       length, low, high, low_open, scale)

    def sub(self, key: str) -> '_Map':
        return _Map(self.get(key, {}), self.where(key))

    def done(self) -> None:
        """Reject every key that was not taken."""
        unknown = sorted(str(k) for k in self.value if k not in self.taken)
        if not unknown:
            return
        allowed = ', '.join(sorted(self.taken))
        errors = []
        for key in unknown:
            near = _nearest(key, self.taken)
            errors.append(InvalidArgument(
                self.where(key), _short(self.value[key])
                if not isinstance(self.value[key], Mapping) else '{...}',
                'is not a known key here' + (f' (did you mean {near}?)' if near else '')
                + f' (known: {allowed})'))
        raise errors[0] if len(errors) == 1 else InvalidFile(errors)


def _short(value: Any) -> Any:
    text = repr(value)
    return value if len(text) < 60 else text[:57] + '...'


def _vector(value: Any, where: str, length: int, low: float | None = None,
            high: float | None = None, low_open: bool = False,
            scale: float = 1.0) -> tuple[float, ...]:
    if not isinstance(value, list | tuple) or len(value) != length:
        raise InvalidArgument(where, _short(value), f'must be a list of {length} numbers')
    out = []
    for i, v in enumerate(value):
        if isinstance(v, bool) or not isinstance(v, int | float):
            raise InvalidArgument(f'{where}[{i}]', _short(v), 'is not a number')
        out.append(scale * check_number(f'{where}[{i}]', v, low=low, high=high,
                                        low_open=low_open))
    return tuple(out)


def _id(m: _Map, key: str, default: str | None = None) -> str:
    value = m.text(key, default)
    if not value or len(value) > 64 or not set(value) <= ID_CHARS:
        raise InvalidArgument(m.where(key), value, 'must be 1..64 letters, digits, _ or -')
    return value


MM, G, DEG = 1e-3, 1e-3, math.pi / 180.0


def _part(m: _Map, base_dir: str) -> tuple[PartSpec, tuple[GraspPose, ...], PlaceSpec]:
    model = m.text('model', 'radial_capacitor', (*sorted(BUILTIN_MODELS), 'mesh'))
    mesh = m.text('mesh', '')
    mass = m.number('mass_g', 0.0, low=0.0, high=10_000.0, scale=G)
    if model == 'mesh':
        if mass == 0.0:
            raise InvalidArgument(m.where('mass_g'), 0, 'is required (> 0) for a mesh part')
        if not mesh:
            raise InvalidArgument(m.where('mesh'), mesh, 'is required when model is mesh')
        mesh = os.path.normpath(os.path.join(base_dir, os.path.expanduser(mesh)))
        if not os.path.isfile(mesh):
            raise InvalidArgument(m.where('mesh'), mesh, 'does not exist or is not a file')
    elif mesh:
        raise InvalidArgument(m.where('mesh'), mesh, f'is only read when model is mesh '
                              f'(model is {model})')
    dims = m.sub('dimensions_mm')
    dimensions = {str(k): dims.number(str(k), 0.0, low=0.0, low_open=True, scale=MM)
                  for k in list(dims.value)}
    dims.done()
    if 'pins_per_row' in dimensions:
        raise InvalidArgument(dims.where('pins_per_row'), dims.value['pins_per_row'],
                              'is a count, not a length: give it as part.pins_per_row')
    if 'pins_per_row' in m.value:
        dimensions['pins_per_row'] = m.integer('pins_per_row', 0, 1, 64)

    spec = PartSpec(
        model=model, dimensions=dimensions, mass=mass or None,
        lateral_friction=m.number('lateral_friction', 0.5, low=0.0, high=10.0),
        rolling_friction=m.number('rolling_friction_mm', PartSpec.rolling_friction / MM,
                                  low=0.0, high=100.0, scale=MM),
        spinning_friction=m.number('spinning_friction_mm', PartSpec.spinning_friction / MM,
                                   low=0.0, high=100.0, scale=MM),
        restitution=m.number('restitution', 0.0, low=0.0, high=1.0),
        mesh_path=mesh, scale=m.number('mesh_scale', 1.0, low=0.0, high=1000.0, low_open=True))
    place_map = m.sub('place')
    place = PlaceSpec(place_axis=place_map.vector('axis', [0.0, 0.0, -1.0], 3),
                      seat_offset=place_map.number('seat_offset_mm', 5.5, low=-1000.0,
                                                   high=1000.0, scale=MM))
    place_map.done()
    raw = m.get('grasps', None)
    if raw is None:
        grasps = CAPACITOR_GRASPS
    else:
        if not isinstance(raw, list) or not raw:
            raise InvalidArgument(m.where('grasps'), _short(raw), 'must be a non-empty list')
        grasps = []
        for i, item in enumerate(raw):
            g = _Map(item, f'{m.where("grasps")}[{i}]')
            grasps.append(GraspPose(
                name=g.text('name', f'grasp_{i}'),
                up_axis=g.vector('up_axis', None, 3),
                closing_axis=g.vector('closing_axis', None, 3),
                jaw_opening=g.number('jaw_opening_mm', None, low=0.0, low_open=True, scale=MM),
                grasp_point=g.vector('grasp_point_mm', [0.0, 0.0, 0.0], 3, scale=MM)))
            g.done()
        names = [g.name for g in grasps]
        if len(set(names)) != len(names):
            raise InvalidArgument(m.where('grasps'), names, 'has a grasp name twice')
    m.done()
    return spec, tuple(grasps), place


def _bins(m: _Map, key: str, wall: float, limit: float) -> tuple[ContainerSpec, ...]:
    raw = m.get(key, None, required=True)
    where = m.where(key)
    if not isinstance(raw, list) or not 1 <= len(raw) <= MAX_BINS:
        raise InvalidArgument(where, _short(raw), f'must be a list of 1..{MAX_BINS} bins '
                              '[x, y, z] in mm')
    return tuple(_bin(v, f'{where}[{i}]', wall, limit) for i, v in enumerate(raw))


def _bin(value: Any, where: str, wall: float, limit: float) -> ContainerSpec:
    size = _vector(value, where, 3, low=0.0, low_open=True, scale=MM)
    for i, s in enumerate(size):
        if s > limit + 1e-12:
            raise InvalidArgument(f'{where}[{i}]', round(s / MM, 6),
                                  f'mm is over the size limit requirements.max_dimension_mm '
                                  f'= {limit / MM:g}')
    spec = ContainerSpec(inner_size=size, wall_thickness=wall)
    _checked(check_container, spec, where)
    return spec


def _checked(check: Callable, value: Any, where: str) -> Any:
    """Run a core check, naming the field in the file that held the value."""
    try:
        return check(value)
    except InvalidArgument as exc:
        raise InvalidArgument(f'{where} ({exc.field})', exc.value, exc.rule) from None


def _earlier(m: _Map, key: str, exp_id: str, earlier: dict[str, Experiment], kind: str,
             alternative: str) -> Experiment:
    """The earlier experiment of type `kind` that `key` names by id."""
    source = earlier.get(exp_id)
    if source is None or source.type != kind:
        raise InvalidArgument(m.where(key), exp_id, f'names no earlier {kind} experiment (give '
                              f'its id, or {alternative})')
    return source


def _experiment(m: _Map, f: dict, earlier: dict[str, Experiment]) -> Experiment:
    exp_id = _id(m, 'id')
    if exp_id in earlier:
        raise InvalidArgument(m.where('id'), exp_id, 'is the id of an earlier experiment')
    kind = m.text('type', None, TYPES)
    iterations = m.integer('iterations', None, 1, MAX_ITERATIONS)
    part, tray, wall, limit = f['part_geometry'], f['tray'], f['bin_wall'], f['max_dimension']
    out: dict[str, Any] = {'id': exp_id, 'type': kind, 'iterations': iterations}
    if kind in (BIN_STATIC, BIN_EMPTYING, FEEDER_EMPTYING, GRIPPER_SWEEP):
        out['parts'] = m.integer('parts', None, 1, MAX_PARTS_PER_INSTANCE)
    if kind == BIN_STATIC:
        out['bins'] = _bins(m, 'bins_mm', wall, limit)
        for i, b in enumerate(out['bins']):
            check_fits(m.where('parts') + f' (bins_mm[{i}])', out['parts'], part.volume, b)
    elif kind == BIN_EMPTYING:
        out.update(_bin_or_source(m, out['parts'], f, earlier, required=True))
    elif kind == TABLE_SWEEP:
        counts = m.sub('counts')
        first = counts.integer('first', 1, 1, MAX_PARTS_PER_INSTANCE)
        last = counts.integer('last', 100, first, MAX_PARTS_PER_INSTANCE)
        step = counts.integer('step', 1, 1, MAX_PARTS_PER_INSTANCE)
        counts.done()
        out['counts'] = tuple(range(first, last + 1, step))
        check_fits(m.where('counts.last'), out['counts'][-1], part.volume, tray)
        out['margin'] = m.integer('margin', 5, 0, 1000)
    elif kind == GRIPPER_SWEEP:
        scene = _bin_or_source(m, out['parts'], f, earlier, required=False)
        if not scene:       # no bin: the parts lie on the tray, as in a table_sweep
            check_fits(m.where('parts') + ' (tray_mm)', out['parts'], part.volume, tray)
        out.update(scene)
        out['variants'] = _variants(m, f['gripper'], f['grasps'])
        out['min_valid'] = m.number('min_valid', 1.0, low=0.0, high=MAX_PARTS_PER_INSTANCE)
    if kind == FEEDER_EMPTYING:
        raw = m.get('optimal_range', None, required=True)
        if isinstance(raw, str):
            source = _earlier(m, 'optimal_range', raw, earlier, TABLE_SWEEP, '[min, max]')
            out['range_from'] = raw
            high = source.counts[-1] + source.margin
        else:
            if not isinstance(raw, list | tuple) or len(raw) != 2:
                raise InvalidArgument(m.where('optimal_range'), _short(raw),
                                      'must be [min, max] parts on the table, or a table_sweep id')
            low = check_int(m.where('optimal_range') + '[0]', raw[0], low=1,
                            high=MAX_PARTS_PER_INSTANCE)
            high = check_int(m.where('optimal_range') + '[1]', raw[1], low=1,
                             high=MAX_PARTS_PER_INSTANCE)
            if low > high:
                raise InvalidArgument(m.where('optimal_range'), list(raw),
                                      'has min > max')
            out['optimal_range'] = (low, high)
        out['max_vibrations'] = m.integer('max_vibrations', 500, 1, 1_000_000)
        if out.get('optimal_range'):
            _checked(check_feeder, FeederConfig(out['parts'], *out['optimal_range'],
                                                out['max_vibrations']), m.path)
        check_fits(m.where('optimal_range') + ' (max)', high, part.volume, tray)
    m.done()
    return Experiment(**out)


def _bin_or_source(m: _Map, parts: int, f: dict, earlier: dict[str, Experiment],
                   required: bool) -> dict:
    """The experiment's `bin`: a bin [x, y, z] in mm ({'bin': spec}) or the id of an earlier
    bin_static experiment whose best bin is used ({'bin_from': id}); {} when it is absent and
    not required. `parts` must fit in it (in every bin of the source)."""
    raw = m.get('bin', None, required=required)
    if raw is None:
        return {}
    volume = f['part_geometry'].volume
    if isinstance(raw, str):
        source = _earlier(m, 'bin', raw, earlier, BIN_STATIC, 'a bin [x, y, z] in mm')
        for i, b in enumerate(source.bins):
            check_fits(m.where('parts') + f' ({raw}.bins_mm[{i}])', parts, volume, b)
        return {'bin_from': raw}
    spec = _bin(raw, m.where('bin'), f['bin_wall'], f['max_dimension'])
    check_fits(m.where('parts'), parts, volume, spec)
    return {'bin': spec}


GRIPPER_KEYS = (('body_diameter_mm', 'body_diameter'), ('body_length_mm', 'body_length'),
                ('jaw_height_mm', 'jaw_height'), ('jaw_depth_mm', 'jaw_depth'),
                ('finger_clearance_mm', 'finger_clearance'))


def _gripper(m: _Map, base: Gripper) -> Gripper:
    """The `gripper` section: each of GRIPPER_KEYS, in mm, defaulting to `base`'s."""
    return Gripper(**{attr: m.number(key, getattr(base, attr) / MM, scale=MM)
                      for key, attr in GRIPPER_KEYS})


def _variants(m: _Map, gripper: Gripper, grasps: tuple[GraspPose, ...]
              ) -> tuple[GripperVariant, ...]:
    """gripper_sweep's grid: `grippers` maps gripper keys (as in the gripper section) to a
    number or a list of numbers, the file's gripper standing in for keys not given;
    `grasp_sets` maps a name to a list of grasp names of part.grasps (default: all of them,
    named 'all'). Every combination, in the order given, body diameter varying slowest."""
    grid = m.sub('grippers')
    axes = []
    for key, attr in GRIPPER_KEYS:
        where = grid.where(key)
        raw = grid.get(key, getattr(gripper, attr) / MM)
        values = raw if isinstance(raw, list) else [raw]
        if not values or len(values) > MAX_VARIANTS:
            raise InvalidArgument(where, _short(raw), f'must be a number or a list of 1 to '
                                  f'{MAX_VARIANTS} numbers (mm)')
        for i, v in enumerate(values):
            if isinstance(v, bool) or not isinstance(v, int | float):
                raise InvalidArgument(f'{where}[{i}]' if isinstance(raw, list) else where,
                                      _short(v), 'is not a number')
        axes.append([(attr, check_number(where, v, low=0.0) * MM) for v in values])
    grid.done()
    names = [g.name for g in grasps]
    raw_sets = m.get('grasp_sets', {'all': names})
    if not isinstance(raw_sets, Mapping) or not raw_sets:
        raise InvalidArgument(m.where('grasp_sets'), _short(raw_sets),
                              'must map a name to a list of grasp names of part.grasps')
    sets = []
    for name, members in raw_sets.items():
        where = f'{m.where("grasp_sets")}.{name}'
        if not isinstance(members, list) or not members:
            raise InvalidArgument(where, _short(members), 'must be a non-empty list of grasp '
                                  f'names (part.grasps: {", ".join(names)})')
        for i, member in enumerate(members):
            if member not in names:
                raise InvalidArgument(f'{where}[{i}]', _short(member), 'is not the name of a '
                                      f'grasp of part.grasps ({", ".join(names)})')
        if len(set(members)) != len(members):
            raise InvalidArgument(where, members, 'names a grasp twice')
        sets.append((str(name), tuple(g for g in grasps if g.name in members)))
    total = math.prod(len(a) for a in axes) * len(sets)
    if total > MAX_VARIANTS:
        raise InvalidArgument(m.where('grippers'), total, f'grippers x grasp sets is over the '
                              f'limit of {MAX_VARIANTS} combinations per experiment')
    out = []
    for combination in itertools.product(*axes):
        g = Gripper(**dict(combination))
        _checked(check_gripper, g, m.where('grippers') + ' (' + ', '.join(
            f'{key} {getattr(g, attr) / MM:g}' for key, attr in GRIPPER_KEYS) + ')')
        out += [GripperVariant(g, name, members) for name, members in sets]
    return tuple(out)


def _moves(m: _Map) -> tuple[Vibration, ...]:
    """The feeder's moves per vibration cycle: a list of MOVES names, or mappings with an
    optional `move` (the name it starts from, default spread) and any of amplitude_mm,
    frequency_hz, duration_s, direction."""
    key = 'moves'
    items = m.get(key, ['spread'])
    if not isinstance(items, list) or not items or len(items) > MAX_MOVES:
        raise InvalidArgument(m.where(key), _short(items),
                              f'must be a list of 1 to {MAX_MOVES} moves')
    out = []
    for i, item in enumerate(items):
        where = f'{m.where(key)}[{i}]'
        if isinstance(item, str):
            item = {'move': item}
        v = _Map(item, where)
        base = MOVES[v.text('move', 'spread', tuple(MOVES))]
        move = Vibration(
            amplitude=v.vector('amplitude_mm', [a / MM for a in base.amplitude], 3, scale=MM),
            frequency=v.number('frequency_hz', base.frequency),
            duration=v.number('duration_s', base.duration),
            direction=v.text('direction', base.direction, DIRECTIONS))
        v.done()
        out.append(_checked(check_vibration, move, where))
    return tuple(out)


def _check(c: _Map) -> tuple[CheckConfig, str]:
    dc = CheckConfig()
    check = CheckConfig(tolerance=c.number('tolerance_deg', dc.tolerance / DEG, scale=DEG),
                        tilt_min=c.number('tilt_min_deg', dc.tilt_min / DEG, scale=DEG),
                        tilt_max=c.number('tilt_max_deg', dc.tilt_max / DEG, scale=DEG),
                        tilt_step=c.number('tilt_step_deg', dc.tilt_step / DEG, scale=DEG),
                        approach_cone=c.number('approach_cone_deg', dc.approach_cone / DEG,
                                               scale=DEG),
                        rim_tolerance=c.number('rim_tolerance_mm', dc.rim_tolerance / MM,
                                               scale=MM))
    return check, c.text('search_order', 'top_first', SEARCH_ORDERS)


def _requirements(r: _Map) -> Requirements:
    return Requirements(
        parts_per_hour=r.number('parts_per_hour', 60.0, low=0.0, high=1e6, low_open=True),
        refill_interval=r.number('refill_interval_h', 4.0, low=0.0, high=1000.0,
                                 low_open=True, scale=3600.0),
        max_dimension=r.number('max_dimension_mm', 300.0, low=0.0, high=2000.0,
                               low_open=True, scale=MM),
        max_spilled=r.integer('max_spilled_parts', 0, low=0, high=100_000),
        success_rate=r.number('success_rate', 0.9, low=0.0, high=1.0, low_open=True))


def _cell(c: _Map) -> Cell:
    return Cell(pick_time=c.number('pick_s', Cell.pick_time, low=0.0, high=3600.0,
                                   low_open=True),
                image_time=c.number('image_s', Cell.image_time, low=0.0, high=3600.0))


def _sampling(s: _Map) -> Sampling:
    return Sampling(mode=s.text('mode', FIXED, SAMPLING_MODES),
                    batch=s.integer('batch', Sampling.batch, 1, MAX_ITERATIONS))


def _tray(m: _Map) -> ContainerSpec:
    tray = ContainerSpec.tray(m.vector('tray_mm', [s / MM for s in TRAY_DEFAULT_SIZE], 3,
                                       low=0.0, low_open=True, scale=MM))
    _checked(check_container, tray, 'tray_mm')
    return tray


def _geometry(part: PartSpec):
    try:
        return build_part(part)
    except InvalidArgument as exc:
        raise InvalidArgument(f'part ({exc.field})', exc.value, exc.rule) from None


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
    m = _Map(data, '')
    base_dir = os.path.dirname(os.path.abspath(path)) if path else os.getcwd()
    errors: list[InvalidArgument] = []

    def checked(step: Callable[[], Any]) -> Any:
        """One section read and checked; its error kept, and the next section read."""
        try:
            return step()
        except InvalidFile as exc:
            errors.extend(exc.errors)
        except InvalidArgument as exc:
            errors.append(exc)
        return None

    file_id = checked(lambda: _id(m, 'id'))
    seed = checked(lambda: m.integer('seed', 0, 0, MAX_SEED))
    output_dir = checked(lambda: m.text('output_dir', 'results'))
    part_grasps_place = checked(lambda: _part(m.sub('part'), base_dir))
    part, grasps, place = part_grasps_place or (None, None, None)

    def section(key: str, read: Callable[[_Map], Any]) -> Any:
        """A section's value (None when it has an error), its unknown keys refused apart."""
        sub = checked(lambda: m.sub(key))
        if sub is None:
            return None
        value = checked(lambda: read(sub))
        checked(sub.done)
        return value

    gripper = section('gripper', lambda g: _gripper(g, Gripper()))
    check, search_order = section('check', _check) or (None, None)
    requirements = section('requirements', _requirements)
    sampling = section('sampling', _sampling)
    cell = section('cell', _cell)
    tray = checked(lambda: _tray(m))
    moves = checked(lambda: _moves(m))
    bin_wall = checked(lambda: m.number('bin_wall_mm', 3.0, low=0.5, high=100.0, scale=MM))
    raw = checked(lambda: m.get('experiments', None, required=True))
    # The core's own checks, under the file's names.
    if gripper is not None:
        checked(lambda: _checked(check_gripper, gripper, 'gripper'))
    if part_grasps_place is not None:
        checked(lambda: _checked(check_grasps, list(grasps), 'part.grasps'))
        checked(lambda: _checked(check_place, place, 'part.place'))
    if check is not None:
        checked(lambda: _checked(tilts, check, 'check'))
    geometry = checked(lambda: _geometry(part)) if part is not None else None
    experiments: dict[str, Experiment] = {}
    if 'experiments' not in m.value:
        pass                # the missing key's error is kept
    elif not isinstance(raw, list) or not 1 <= len(raw) <= MAX_EXPERIMENTS:
        errors.append(InvalidArgument('experiments', _short(raw),
                                      f'must be a list of 1..{MAX_EXPERIMENTS} experiments'))
    elif None not in (geometry, tray, bin_wall, requirements, gripper, grasps):
        context = {'part_geometry': geometry, 'tray': tray, 'bin_wall': bin_wall,
                   'max_dimension': requirements.max_dimension, 'gripper': gripper,
                   'grasps': grasps}
        for i, item in enumerate(raw):
            e = checked(lambda item=item, i=i: _experiment(_Map(item, f'experiments[{i}]'),
                                                           context, experiments))
            if e is not None:
                experiments[e.id] = e
    checked(m.done)
    # one error per field: a misspelt required key is found missing and then unknown
    fields: set[str] = set()
    errors = [e for e in errors if not (e.field in fields or fields.add(e.field))]
    if errors:
        raise errors[0] if len(errors) == 1 else InvalidFile(errors)
    return ExperimentFile(
        id=file_id, seed=seed, output_dir=output_dir, part=part, gripper=gripper, grasps=grasps,
        place=place, check=check, search_order=search_order, tray=tray, moves=moves,
        bin_wall=bin_wall, requirements=requirements, experiments=tuple(experiments.values()),
        sampling=sampling, cell=cell,
        path=os.path.abspath(path) if path else '', text=text)


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
