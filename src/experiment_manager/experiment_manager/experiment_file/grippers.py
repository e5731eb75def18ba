"""The grippers of a file besides its own: `grippers`, each named, with its grasps, for the
experiments that name it (`named`); and a gripper_sweep's grippers, every combination of the
sizes it gives the file's gripper and of its grasp sets (`variants`); each checked by the
core's rules under the file's keys."""

from dataclasses import replace
import itertools
import math

from pick_common.errors import check_number, InvalidArgument
from pick_common.parts.geometry import PartGeometry
from pick_validity.config import Setup
from pick_validity.grippers import GripperKind, not_its_key

from . import experiment_keys, schema, sections
from . import part as part_section
from .errors import checked as checked_as
from .errors import read as read_keys
from .model import GripperVariant, MAX_VARIANTS
from .values import short


def variants(e: experiment_keys.GripperSweepKeys, where: str, gripper: GripperKind,
             grasps: tuple) -> tuple[GripperVariant, ...]:
    """gripper_sweep's grid: every combination of its grippers (the file's gripper's kind,
    the file's gripper standing in for keys not given) and grasp sets (default: every grasp,
    named 'all'), in the order given, the kind's first key varying slowest. `gripper` and
    `grasps`: the file's."""
    for key in e.grippers.model_fields_set:
        if getattr(e.grippers, key) is not None and key not in \
                {k.file_key for k in gripper.KEYS}:
            raise InvalidArgument(f'{where}.grippers.{key}', getattr(e.grippers, key),
                                  not_its_key(key, gripper))
    axes = []
    for key in gripper.KEYS:
        given = getattr(e.grippers, key.file_key)
        values = given if given is not None else (check_number(
            f'{where}.grippers.{key.file_key}', getattr(gripper, key.field) / key.factor,
            low=0.0),)
        axes.append([(key.field, v * key.factor) for v in values])
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
        g = gripper.with_values(**dict(combination))
        checked_as(lambda x: x.check(), g, f'{where}.grippers (' + ', '.join(
            f'{key.file_key} {getattr(g, key.field) / key.factor:g}' for key in g.KEYS) + ')')
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
        gripper = checked_as(lambda g: g.check(), sections.gripper(keys), where)
        try:
            grasps = part_section.grasps_for(keys.grasps, gripper, geometry, setup,
                                             f'{where}.grasps')
        except InvalidArgument as exc:       # a core field, under this gripper's
            field = exc.field if exc.field.startswith(where) else f'{where}.{exc.field}'
            raise InvalidArgument(field, exc.value, exc.rule) from None
        out[name] = replace(setup, gripper=gripper, grasps=grasps)
    return out
