"""The experiment file as written: its keys, their types, ranges and defaults, in the file's
own units (mm, degrees, g and hours where the key says so), as pydantic models.

Each section and each experiment is a model that refuses unknown keys; its values are the
types of `values`, checked by the cores' own rules. What relates sections (a bin within
requirements.max_dimension_mm, parts that fit, an experiment named by another) is checked by
the loader (`loading`), and pydantic's errors become the workspace's in `errors`.
"""

import argparse
from collections.abc import Mapping
from functools import partial
import json
from typing import Annotated, Any

from pick_common.containers import (
    BIN,
    DROP_HEIGHT,
    HOPPER_RATE,
    HOPPER_SPEED,
    TRAY,
    TRAY_DEFAULT_SIZE,
)
from pick_common.parts import materials
from pick_common.parts.models import BUILTIN_MODELS
from pick_common.parts.spec import UNITS
from pick_common.specs import (
    DEFAULT_CYCLE,
    DIRECTIONS,
    MAX_MOVES,
    MAX_SEED,
    MOVES,
)
from pick_validity.config import CheckConfig
from pick_validity.grippers import KINDS, not_its_key
from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    create_model,
    Field,
    model_validator,
    WrapValidator,
)

from .model import (
    ADAPTIVE,
    Cell,
    DEG,
    FIXED,
    MAX_EXPERIMENTS,
    MAX_ITERATIONS,
    MM,
    Sampling,
    SEARCH_ORDERS,
)
from .values import (
    fail,
    grasp_list,
    Identifier,
    Int,
    list_of,
    mapping,
    Number,
    PositiveSize,
    short,
    Text,
    Vector,
)


class Section(BaseModel):
    """A mapping of the file: unknown keys are errors; defaults are checked as values are."""

    model_config = ConfigDict(extra='forbid', frozen=True, validate_default=True)


# ------------------------------------------------------------------------------- part
class Place(Section):
    axis: Vector(3) = (0.0, 0.0, -1.0)                  # part axis pointing into the PCB
    seat_offset_mm: Number(-1000.0, 1000.0) = 5.5      # part origin to the placing surface


class GraspEntry(Section):
    """A jaws' grasp (up_axis, closing_axis, jaw_opening_mm, grasp_point_mm) or a suction
    cup's (up_axis, grasp_point_mm: where the cup's centre touches); which, the gripper's
    type says (the loader checks)."""

    name: Text() | None = None                         # default grasp_<index>
    up_axis: Vector(3)
    closing_axis: Vector(3) | None = None
    jaw_opening_mm: Number(0.0, low_open=True) | None = None
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
        # how the values the file gives were got (materials.BASES): one word for all of
        # them, or one per key; a value the file leaves to its default keeps the default's
        basis: Annotated[dict[str, Text(*materials.BASES)],
                         BeforeValidator(_basis)] = {}

        @model_validator(mode='after')
        def _basis_of_given(self) -> 'Pair':
            for key in set(self.basis) - {'*'} - self.model_fields_set:
                fail(f'says {self.basis[key]} of a value the file does not give (the default '
                     f'{getattr(self, key):g} is {materials.DEFAULT_BASIS[FIELD_OF[key]]}); '
                     f'give {key} beside it', self.basis[key], f'.basis.{key}')
            return self
    return Pair


def _basis(value: Any) -> Any:
    """A pair's `basis`: a word stands for every value the pair gives."""
    if isinstance(value, str):
        if value not in materials.BASES:
            fail(f'must be one of {", ".join(materials.BASES)}, or a mapping of the pair\'s '
                 'keys to them', short(value))
        return {'*': value}
    for key in mapping(value):
        if key not in MOVED_KEYS:
            fail(f'is not a key of a pair: one of {", ".join(MOVED_KEYS)}', short(key),
                 f'.{key}')
    return value


# a pair's file key -> its field in materials.Contact
FIELD_OF = {key: key.removesuffix('_mm') for key in MOVED_KEYS}


class MaterialsSection(Section):
    """The part's contact materials as pairs (pick_common.parts.materials)."""

    part_on_surface: _contact(materials.PART_ON_SURFACE) = {}
    part_on_part: _contact(materials.PART_ON_PART) = {}


# ------------------------------------------------------------------ gripper and check
# Every kind's keys, once each, in KINDS' order (a key two kinds share, such as
# body_diameter_mm, is each one's, with each one's default).
GRIPPER_FILE_KEYS = tuple(dict.fromkeys(key.file_key for kind in KINDS.values()
                                        for key in kind.KEYS))


class _Gripper(Section):
    """The simplified gripper, in the file's units: parallel jaws (`type: jaws`, the default)
    or a suction cup (`type: suction`). Its keys, their units, limits and defaults are its
    kind's (pick_validity.grippers: KEYS), one table for the file, the node and the message;
    a key left out takes its kind's default."""

    type: Text(*KINDS) = 'jaws'

    @model_validator(mode='after')
    def _keys_of_its_type(self) -> '_Gripper':
        own = {key.file_key for key in KINDS[self.type].KEYS}
        for key in GRIPPER_FILE_KEYS:
            if key in self.model_fields_set and key not in own:
                fail(not_its_key(key, KINDS[self.type]), getattr(self, key), f'.{key}')
        return self


GripperSection = create_model(
    'GripperSection', __base__=_Gripper, __module__=__name__,
    **{key: (Number() | None, None) for key in GRIPPER_FILE_KEYS})


class CheckSection(Section):
    tolerance_deg: Number() = CheckConfig.tolerance / DEG
    tilt_min_deg: Number() = CheckConfig.tilt_min / DEG
    tilt_max_deg: Number() = CheckConfig.tilt_max / DEG
    tilt_step_deg: Number() = CheckConfig.tilt_step / DEG
    approach_cone_deg: Number() = CheckConfig.approach_cone / DEG
    rim_tolerance_mm: Number() = CheckConfig.rim_tolerance / MM
    station_margin: Number() = CheckConfig.station_margin      # d / h, for regrasp_station
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
    regrasp_s: Number(0.0, 3600.0) = Cell.regrasp_time


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
class FeederZone(Section):
    """Where the hopper drops parts on the tray's plate: a rectangle, mm, in the tray's frame
    (origin at the plate's centre, +X along its length)."""

    center: Vector(2)
    size: Vector(2, low=0.0, low_open=True)


class FileKeys(Section):
    """The file's top level; each section is read by its own model (SECTIONS), each
    experiment by its kind's (kinds.keys_model)."""

    id: Identifier
    seed: Int(0, MAX_SEED) = 0
    output_dir: Text() = 'results'
    part: Any = None
    materials: Any = None
    gripper: Any = None
    grippers: Any = None            # other grippers by name: {name: {gripper keys, grasps}}
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
    # the tray's hopper (containers.HOPPER_RATE, HOPPER_SPEED, both assumed): the parts it lets
    # out per second while it runs, and their speed onto the tray leaving its outlet, mm/s
    hopper_rate: Number(0.1, 1000.0) = HOPPER_RATE
    hopper_speed_mm_s: Number(0.0, 2000.0, low_open=True) = HOPPER_SPEED / MM
    # where the hopper drops on the tray, its outlet the edge farther from the tray's centre
    # along x; None: ContainerSpec.tray's (assumed)
    feeder_zone_mm: FeederZone | None = None
    experiments: Annotated[list[Any], BeforeValidator(partial(
        list_of, low=1, high=MAX_EXPERIMENTS, what=f'1..{MAX_EXPERIMENTS} experiments'))]


SECTIONS: dict[str, type[Section]] = {
    'part': Part, 'materials': MaterialsSection, 'gripper': GripperSection, 'check': CheckSection,
    'requirements': RequirementsSection, 'sampling': SamplingSection, 'cell': CellSection}


class NamedGripper(GripperSection):
    """One of the file's `grippers`: a gripper's keys and its grasps (as part.grasps: a
    list, or auto), for experiments that name it."""

    grasps: Annotated[list[GraspEntry] | None, WrapValidator(grasp_list)] = \
        Field(default=None, validate_default=False)


def json_schema_text(model: type[BaseModel]) -> str:
    """A results model's JSON Schema as the project publishes it (docs/*.schema.json)."""
    return json.dumps(model.model_json_schema(by_alias=True), indent=1, sort_keys=True) + '\n'


def schema_command(model: type[BaseModel], what: str, description: str,
                   argv: list[str] | None = None) -> int:
    """`python -m <module> --schema PATH`: write `model`'s JSON Schema to PATH ('-': standard
    output); the one command of summary.json's and a board answer's modules."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument('--schema', metavar='PATH', required=True,
                        help=f"write {what}'s JSON Schema to PATH ('-': standard output)")
    args = parser.parse_args(argv)
    if args.schema == '-':
        print(json_schema_text(model), end='')
        return 0
    with open(args.schema, 'w', encoding='utf-8') as f:
        f.write(json_schema_text(model))
    return 0
