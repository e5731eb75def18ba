"""The experiment file as written: its keys, their types, ranges and defaults, in the file's
own units (mm, degrees, g and hours where the key says so), as pydantic models.

Each section and each experiment is a model that refuses unknown keys; its values are the
types of `values`, checked by the cores' own rules. What relates sections (a bin within
requirements.max_dimension_mm, parts that fit, an experiment named by another) is checked by
the loader (`loading`), and pydantic's errors become the workspace's in `errors`.
"""

from collections.abc import Mapping
from functools import partial
from typing import Annotated, Any

from pick_common.containers import BIN, DROP_HEIGHT, TRAY, TRAY_DEFAULT_SIZE
from pick_common.parts import materials
from pick_common.parts.models import BUILTIN_MODELS
from pick_common.parts.spec import UNITS
from pick_common.specs import (
    DEFAULT_CYCLE,
    DIRECTIONS,
    MAX_MOVES,
    MAX_PARTS_PER_INSTANCE,
    MAX_SEED,
    MOVES,
)
from pick_validity.config import CheckConfig, Gripper
from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, model_validator, WrapValidator

from .model import (
    ADAPTIVE,
    BIN_EMPTYING,
    BIN_STATIC,
    Cell,
    DEG,
    DROP_TEST,
    FEEDER_EMPTYING,
    FIXED,
    GRIPPER_SWEEP,
    MAX_BINS,
    MAX_EXPERIMENTS,
    MAX_ITERATIONS,
    MAX_VARIANTS,
    MM,
    Sampling,
    SEARCH_ORDERS,
    SENSITIVITY,
    TABLE_SWEEP,
    TYPES,
)
from .values import (
    fail,
    grasp_list,
    Identifier,
    Int,
    integer,
    list_of,
    mapping,
    Number,
    number,
    PositiveSize,
    short,
    Text,
    Vector,
    vector,
)


class Section(BaseModel):
    """A mapping of the file: unknown keys are errors; defaults are checked as values are."""

    model_config = ConfigDict(extra='forbid', frozen=True, validate_default=True)


# ------------------------------------------------------------------------------- part
class Place(Section):
    axis: Vector(3) = (0.0, 0.0, -1.0)                  # part axis pointing into the PCB
    seat_offset_mm: Number(-1000.0, 1000.0) = 5.5      # part origin to the placing surface


class GraspEntry(Section):
    name: Text() | None = None                         # default grasp_<index>
    up_axis: Vector(3)
    closing_axis: Vector(3)
    jaw_opening_mm: Number(0.0, low_open=True)
    grasp_point_mm: Vector(3) = (0.0, 0.0, 0.0)


class Part(Section):
    model: Text(*sorted(BUILTIN_MODELS), 'mesh') = 'radial_capacitor'
    mesh: Text() = ''
    mass_g: Number(0.0, 10_000.0) = 0.0
    dimensions_mm: Annotated[dict[str, Number(0.0, low_open=True)],
                             BeforeValidator(mapping)] = {}
    pins_per_row: Int(1, 64) | None = None
    units: Text(*UNITS) | None = None                 # a mesh file's length unit
    mesh_scale: Number(0.0, 1000.0, low_open=True) | None = None   # or its scale to metres
    place: Place = Place()
    # the grasp poses, or 'auto': those proposed from the part's geometry (grasp_proposals)
    # (a WrapValidator, so that a list's errors are not joined by 'auto' as a union's are)
    grasps: Annotated[list[GraspEntry] | None, WrapValidator(grasp_list)] = \
        Field(default=None, validate_default=False)


    @model_validator(mode='before')
    @classmethod
    def _moved(cls, data: Any) -> Any:
        for key in MOVED_KEYS:
            if isinstance(data, Mapping) and key in data:
                fail(f'has moved: a material belongs to a pair of surfaces; give '
                     f'materials.part_on_surface.{key} (the part on the bin or tray) and '
                     f'materials.part_on_part.{key} (on another part)', data[key], f'.{key}')
        return data


MOVED_KEYS = ('lateral_friction', 'rolling_friction_mm', 'spinning_friction_mm',
              'restitution')


# ------------------------------------------------------------------------- materials
def _contact(default: materials.Contact) -> type[Section]:
    """A pair's section (materials.Contact in the file's units), `default`'s values."""
    class Pair(Section):
        lateral_friction: Number(0.0, materials.MAX_COMBINED) = default.lateral_friction
        rolling_friction_mm: Number(0.0, 100.0) = default.rolling_friction / MM
        spinning_friction_mm: Number(0.0, 100.0) = default.spinning_friction / MM
        restitution: Number(0.0, 1.0) = default.restitution
        source: Text() = ''                     # where the values come from (measured, ...)
    return Pair


class MaterialsSection(Section):
    """The part's contact materials as pairs (pick_common.parts.materials)."""

    part_on_surface: _contact(materials.PART_ON_SURFACE) = {}
    part_on_part: _contact(materials.PART_ON_PART) = {}


# ------------------------------------------------------------------ gripper and check
# The gripper's keys in the file and the Gripper fields they set.
GRIPPER_KEYS = (('body_diameter_mm', 'body_diameter'), ('body_length_mm', 'body_length'),
                ('jaw_height_mm', 'jaw_height'), ('jaw_depth_mm', 'jaw_depth'),
                ('finger_clearance_mm', 'finger_clearance'))


class GripperSection(Section):
    """The simplified gripper, mm (its rules are the core's: pick_validity.config)."""

    body_diameter_mm: Number() = Gripper.body_diameter / MM
    body_length_mm: Number() = Gripper.body_length / MM
    jaw_height_mm: Number() = Gripper.jaw_height / MM
    jaw_depth_mm: Number() = Gripper.jaw_depth / MM
    finger_clearance_mm: Number() = Gripper.finger_clearance / MM


class CheckSection(Section):
    tolerance_deg: Number() = CheckConfig.tolerance / DEG
    tilt_min_deg: Number() = CheckConfig.tilt_min / DEG
    tilt_max_deg: Number() = CheckConfig.tilt_max / DEG
    tilt_step_deg: Number() = CheckConfig.tilt_step / DEG
    approach_cone_deg: Number() = CheckConfig.approach_cone / DEG
    rim_tolerance_mm: Number() = CheckConfig.rim_tolerance / MM
    search_order: Text(*SEARCH_ORDERS) = 'top_first'


class RequirementsSection(Section):
    parts_per_hour: Number(0.0, 1e6, low_open=True) = 60.0
    refill_interval_h: Number(0.0, 1000.0, low_open=True) = 4.0
    max_dimension_mm: Number(0.0, 2000.0, low_open=True) = 300.0
    max_spilled_parts: Int(0, 100_000) = 0
    success_rate: Number(0.0, 1.0, low_open=True) = 0.9


class CellSection(Section):
    pick_s: Number(0.0, 3600.0, low_open=True) = Cell.pick_time
    image_s: Number(0.0, 3600.0) = Cell.image_time


class SamplingSection(Section):
    mode: Text(FIXED, ADAPTIVE) = FIXED
    batch: Int(1, MAX_ITERATIONS) = Sampling.batch


# ----------------------------------------------------------------------------- moves
def _named_move(value: Any) -> Any:
    return {'move': value} if isinstance(value, str) else value


class Move(Section):
    """One feeder move: a named move of pick_common.specs.MOVES, fields set over it."""

    move: Text(*MOVES) = 'flip'
    amplitude_mm: Vector(3) | None = None
    frequency_hz: Number() | None = None
    duration_s: Number() | None = None
    direction: Text(*DIRECTIONS) | None = None


# --------------------------------------------------------------------------- the file
class FileKeys(Section):
    """The file's top level; each section is read by its own model (SECTIONS), each
    experiment by its type's (EXPERIMENTS)."""

    id: Identifier
    seed: Int(0, MAX_SEED) = 0
    output_dir: Text() = 'results'
    part: Any = None
    materials: Any = None
    gripper: Any = None
    check: Any = None
    requirements: Any = None
    sampling: Any = None
    cell: Any = None
    tray_mm: PositiveSize = tuple(s / MM for s in TRAY_DEFAULT_SIZE)
    moves: Annotated[list[Annotated[Move, BeforeValidator(_named_move)]], BeforeValidator(
        partial(list_of, low=1, high=MAX_MOVES, what=f'1 to {MAX_MOVES} moves'))] = list(
            DEFAULT_CYCLE)
    bin_wall_mm: Number(0.5, 100.0) = 3.0
    # how high over the floor parts arrive from: a bin's pour, the tray's hopper lip
    bin_drop_mm: Number(0.0, 1000.0) = DROP_HEIGHT[BIN] / MM
    hopper_lip_mm: Number(0.0, 1000.0) = DROP_HEIGHT[TRAY] / MM
    experiments: Annotated[list[Any], BeforeValidator(partial(
        list_of, low=1, high=MAX_EXPERIMENTS, what=f'1..{MAX_EXPERIMENTS} experiments'))]


SECTIONS: dict[str, type[Section]] = {
    'part': Part, 'materials': MaterialsSection, 'gripper': GripperSection, 'check': CheckSection,
    'requirements': RequirementsSection, 'sampling': SamplingSection, 'cell': CellSection}


# ------------------------------------------------------------------------ experiments
def _bin_or_id(value: Any) -> Any:
    """An earlier bin_static's id, or a bin [x, y, z] in mm."""
    if isinstance(value, str):
        return value
    return vector(value, 3, 0.0, None, True)


def _range_or_id(value: Any) -> Any:
    """An earlier table_sweep's id, or [min, max] parts on the table."""
    if isinstance(value, str):
        return value
    if not isinstance(value, list | tuple) or len(value) != 2:
        fail('must be [min, max] parts on the table, or a table_sweep id', short(value))
    low, high = (integer(v, 1, MAX_PARTS_PER_INSTANCE) for v in value)
    if low > high:
        fail('has min > max', list(value))
    return low, high


def _grid_values(value: Any) -> tuple[float, ...]:
    values = value if isinstance(value, list) else [value]
    if not values or len(values) > MAX_VARIANTS:
        fail(f'must be a number or a list of 1 to {MAX_VARIANTS} numbers (mm)', short(value))
    return tuple(number(v, 0.0, None, False, f'[{i}]' if isinstance(value, list) else '')
                 for i, v in enumerate(values))


def _grasp_sets(value: Any) -> Any:
    if value is not None and (not isinstance(value, Mapping) or not value):
        fail('must map a name to a list of grasp names of part.grasps', short(value))
    return value


BinOrId = Annotated[str | tuple[float, ...], BeforeValidator(_bin_or_id)]
GridValues = Annotated[tuple[float, ...] | None, BeforeValidator(
    lambda v: None if v is None else _grid_values(v))]
Parts = Int(1, MAX_PARTS_PER_INSTANCE)


class ExperimentKeys(Section):
    """What every experiment has."""

    id: Identifier
    type: Text(*TYPES)
    iterations: Int(1, MAX_ITERATIONS)


class BinStaticKeys(ExperimentKeys):
    parts: Parts
    bins_mm: Annotated[list[PositiveSize], BeforeValidator(partial(
        list_of, low=1, high=MAX_BINS, what=f'1..{MAX_BINS} bins [x, y, z] in mm'))]


class BinEmptyingKeys(ExperimentKeys):
    parts: Parts
    bin: BinOrId


class Counts(Section):
    first: Parts = 1
    last: Parts = 100
    step: Parts = 1

    @model_validator(mode='after')
    def _ordered(self) -> 'Counts':
        if self.last < self.first:
            fail(f'must be within [{self.first}, {MAX_PARTS_PER_INSTANCE}]', self.last,
                  '.last')
        return self


class TableSweepKeys(ExperimentKeys):
    counts: Counts = Counts()
    margin: Int(0, 1000) = 5
    # while the fit still rises at the last count, sweep on at more counts (plan.extended)
    extend: Annotated[bool, BeforeValidator(lambda v: v if isinstance(v, bool) else fail(
        'must be true or false', short(v)))] = True


class FeederEmptyingKeys(ExperimentKeys):
    parts: Parts
    optimal_range: Annotated[str | tuple[int, int], BeforeValidator(_range_or_id)]
    max_vibrations: Int(1, 1_000_000) = 500


class GripperGrid(Section):
    """gripper_sweep's grid: each gripper key a number or a list of numbers, mm; a key left
    out is the file's gripper's."""

    body_diameter_mm: GridValues = None
    body_length_mm: GridValues = None
    jaw_height_mm: GridValues = None
    jaw_depth_mm: GridValues = None
    finger_clearance_mm: GridValues = None


class GripperSweepKeys(ExperimentKeys):
    parts: Parts
    bin: BinOrId | None = None
    grippers: GripperGrid = GripperGrid()
    grasp_sets: Annotated[dict[str, Any] | None, BeforeValidator(_grasp_sets)] = None
    min_valid: Number(0.0, MAX_PARTS_PER_INSTANCE) = 1.0


class DropTestKeys(ExperimentKeys):
    """iterations: the drops, one part each, from height_mm over the plate, onto a plate of
    the container's surface (its material: materials.part_on_surface); measured: the counts of
    the user's own drop test by aspect name (run --check names the aspects)."""

    height_mm: Number(0.0, 1000.0) = 100.0
    measured: Annotated[dict[str, Int(0, 1_000_000)], BeforeValidator(mapping)] = {}


class InputRange(Section):
    """One uncertain input of a sensitivity experiment: the range to try, in the key's units,
    and where the range comes from (a datasheet, a measurement, a colleague's guess: said)."""

    low: Number()
    high: Number()
    source: Annotated[str, BeforeValidator(
        lambda v: v if isinstance(v, str) and v.strip() else fail(
            'must say where the range comes from (a datasheet, a measurement, a guess)',
            short(v)))]

    @model_validator(mode='after')
    def _ordered(self) -> 'InputRange':
        if not self.low < self.high:
            fail(f'must be above low ({self.low:g})', self.high, '.high')
        return self


def _inputs(value: Any) -> Any:
    if not isinstance(value, Mapping) or not value:
        fail('must map an input (part.lateral_friction, gripper.jaw_depth_mm, '
             'moves.amplitude_scale, ...) to {low, high, source}', short(value))
    return value


class SensitivityKeys(ExperimentKeys):
    """iterations: each repeat's most (the repeated experiment's own count if lower)."""

    of: Annotated[list[Identifier], BeforeValidator(partial(
        list_of, low=1, high=MAX_EXPERIMENTS, what='1 or more ids of earlier experiments'))]
    inputs: Annotated[dict[str, InputRange], BeforeValidator(_inputs)]
    joint: Int(0, 64) = 0
    grid: Int(0, 9) = 0


EXPERIMENTS: dict[str, type[ExperimentKeys]] = {
    BIN_STATIC: BinStaticKeys, BIN_EMPTYING: BinEmptyingKeys, TABLE_SWEEP: TableSweepKeys,
    FEEDER_EMPTYING: FeederEmptyingKeys, GRIPPER_SWEEP: GripperSweepKeys,
    DROP_TEST: DropTestKeys, SENSITIVITY: SensitivityKeys}


def experiment_model(item: Any) -> type[Section]:
    """The model an experiment is read with: its type's, or (for an unknown or missing type)
    one that names the type's error and its id's and iterations' but no key as unknown."""
    kind = item.get('type') if isinstance(item, Mapping) else None
    if isinstance(kind, str) and kind in EXPERIMENTS:
        return EXPERIMENTS[kind]
    return _AnyExperiment


class _AnyExperiment(ExperimentKeys):
    model_config = ConfigDict(extra='ignore', frozen=True, validate_default=True)
