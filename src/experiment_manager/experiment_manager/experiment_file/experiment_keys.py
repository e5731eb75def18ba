"""The experiments of the file as written: each type's keys, their types, ranges and defaults,
in the file's own units, as pydantic models (the sections' are in `schema`)."""

from collections.abc import Mapping
from functools import partial
from typing import Annotated, Any

from pick_common.specs import MAX_PARTS_PER_INSTANCE
from pydantic import BeforeValidator, create_model, model_validator

from .model import (
    MAX_BINS,
    MAX_EXPERIMENTS,
    MAX_ITERATIONS,
    MAX_VARIANTS,
    TYPES,
)
from .schema import GRIPPER_FILE_KEYS, Section
from .values import (
    fail,
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
    vector,
)


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


class OnGripper(ExperimentKeys):
    """An experiment of the cell's picking: run with the file's gripper, or with one of the
    file's `grippers` named here."""

    gripper: Identifier | None = None
    # a part no tilt can place as picked is put down on a flat station and picked again
    regrasp_station: bool = False
    # an earlier experiment of the same type whose seeds this one runs on: the same scenes,
    # another gripper or a station
    scenes_of: Identifier | None = None


class BinStaticKeys(OnGripper):
    parts: Parts
    bins_mm: Annotated[list[PositiveSize], BeforeValidator(partial(
        list_of, low=1, high=MAX_BINS, what=f'1..{MAX_BINS} bins [x, y, z] in mm'))]


class BinEmptyingKeys(OnGripper):
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


class TableSweepKeys(OnGripper):
    counts: Counts = Counts()
    margin: Int(0, 1000) = 5
    # while the fit still rises at the last count, sweep on at more counts (plan.extended)
    extend: Annotated[bool, BeforeValidator(lambda v: v if isinstance(v, bool) else fail(
        'must be true or false', short(v)))] = True


class FeederEmptyingKeys(OnGripper):
    parts: Parts
    optimal_range: Annotated[str | tuple[int, int], BeforeValidator(_range_or_id)]
    max_vibrations: Int(1, 1_000_000) = 500
    max_feed: Int(1, MAX_PARTS_PER_INSTANCE) | None = None    # a feed's dose; None: no limit


# gripper_sweep's grid: each key of the file's gripper's kind a number or a list of numbers,
# in the key's unit; a key left out is the file's gripper's (every kind's keys are read here;
# a key of another kind than the file's gripper is refused by grippers.variants).
GripperGrid = create_model('GripperGrid', __base__=Section, __module__=__name__,
                           **{key: (GridValues, None) for key in GRIPPER_FILE_KEYS})


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
