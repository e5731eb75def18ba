"""The grippers of a file besides its own: `grippers`, each named, with its grasps, for the
experiments that name it (`named`); and a gripper_sweep's grippers, every combination of the
jaws' sizes it gives and of its grasp sets (`variants`); each checked by the core's rules
under the file's keys."""

import itertools
import math

from pick_common.errors import check_number, InvalidArgument
from pick_common.parts.geometry import PartGeometry
from pick_validity.config import (
    CAPACITOR_GRASPS,
    check_grasps,
    check_gripper,
    GraspPose,
    Gripper,
    is_suction,
    Setup,
    SuctionCup,
)

from . import experiment_keys, schema, sections
from . import part as part_section
from .errors import checked as checked_as
from .errors import read as read_keys
from .model import GripperVariant, MAX_VARIANTS, MM
from .schema import GRIPPER_KEYS
from .values import short


def variants(e: experiment_keys.GripperSweepKeys, where: str, gripper: Gripper | SuctionCup,
             grasps: tuple[GraspPose, ...]) -> tuple[GripperVariant, ...]:
    """gripper_sweep's grid: every combination of its grippers (the file's gripper standing in
    for keys not given) and grasp sets (default: every grasp, named 'all'), in the order
    given, body diameter varying slowest. The jaws' sizes only: a suction cup is refused.
    `gripper` and `grasps`: the file's."""
    if is_suction(gripper):
        raise InvalidArgument(where, 'gripper_sweep', "varies the parallel jaws' sizes, and "
                              'the gripper is a suction cup (gripper.type: suction): compare a '
                              "cup's sizes with a sensitivity of gripper.body_diameter_mm or "
                              'files of their own')
    axes = []
    for key, attr in GRIPPER_KEYS:
        given = getattr(e.grippers, key)
        values = given if given is not None else (check_number(
            f'{where}.grippers.{key}', getattr(gripper, attr) / MM, low=0.0),)
        axes.append([(attr, v * MM) for v in values])
    names = [g.name for g in grasps]
    sets = []
    for name, members in (e.grasp_sets or {'all': names}).items():
        at = f'{where}.grasp_sets.{name}'
        if not isinstance(members, list) or not members:
            raise InvalidArgument(at, short(members), 'must be a non-empty list of grasp '
                                  f'names (part.grasps: {", ".join(names)})')
        for i, member in enumerate(members):
            if member not in names:
                raise InvalidArgument(f'{at}[{i}]', short(member), 'is not the name of a '
                                      f'grasp of part.grasps ({", ".join(names)})')
        if len(set(members)) != len(members):
            raise InvalidArgument(at, members, 'names a grasp twice')
        sets.append((str(name), tuple(g for g in grasps if g.name in members)))
    total = math.prod(len(a) for a in axes) * len(sets)
    if total > MAX_VARIANTS:
        raise InvalidArgument(f'{where}.grippers', total, f'grippers x grasp sets is over the '
                              f'limit of {MAX_VARIANTS} combinations per experiment')
    out = []
    for combination in itertools.product(*axes):
        g = Gripper(**dict(combination))
        checked_as(check_gripper, g, f'{where}.grippers (' + ', '.join(
            f'{key} {getattr(g, attr) / MM:g}' for key, attr in GRIPPER_KEYS) + ')')
        out += [GripperVariant(g, name, members) for name, members in sets]
    return tuple(out)


def named(value, setup: Setup, geometry: PartGeometry) -> dict[str, Setup]:
    """The file's `grippers` (`value` as written; None for none): per name, the file's setup
    with that gripper and its grasps, each checked as the file's own are. Raises
    InvalidArgument (or InvalidFile) under `grippers.<name>`."""
    if value is None:
        return {}
    if not isinstance(value, dict) or not value:
        raise InvalidArgument('grippers', short(value), 'must map a name to a gripper and its '
                              'grasps: {name: {type, ..., grasps}}')
    out = {}
    for name, entry in value.items():
        where = f'grippers.{name}'
        if not isinstance(name, str) or not name.isidentifier():
            raise InvalidArgument('grippers', short(name), 'names a gripper with other than '
                                  'letters, digits and _')
        keys, errors = read_keys(schema.NamedGripper, entry, where)
        if errors:
            raise errors[0]
        gripper = sections.gripper(keys)
        checked_as(check_gripper, gripper, where)
        suction = is_suction(gripper)
        try:
            if keys.grasps == part_section.AUTO:
                grasps = part_section.proposed(geometry, gripper)
            elif keys.grasps is None:
                if suction:
                    raise InvalidArgument('part.grasps', None, "is required with a suction "
                                          "cup: give each grasp's up_axis and grasp_point_mm, "
                                          'or auto')
                grasps = CAPACITOR_GRASPS
            else:
                grasps = tuple(part_section.grasp_entry(g, i, suction)
                               for i, g in enumerate(keys.grasps))
            check_grasps(grasps, gripper)
            mine = Setup(setup.part, gripper, grasps, setup.place, setup.config)
            if suction:
                part_section.check_cup(geometry, mine)
            else:
                part_section.check_fits(geometry, grasps)
        except InvalidArgument as exc:       # the part's keys, under this gripper's
            field = exc.field.replace('part.grasps', f'{where}.grasps', 1)
            if not field.startswith(where):
                field = f'{where}.{field}'
            raise InvalidArgument(field, exc.value, exc.rule) from None
        out[name] = mine
    return out
