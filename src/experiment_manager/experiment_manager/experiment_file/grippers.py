"""A gripper_sweep's grippers: every combination of the jaws' sizes it gives and of its grasp
sets, each checked by the core's rule under the file's keys."""

import itertools
import math

from pick_common.errors import check_number, InvalidArgument
from pick_validity.config import check_gripper, GraspPose, Gripper, is_suction, SuctionCup

from . import experiment_keys
from .errors import checked as checked_as
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
