"""The gripper kinds, one type each: the simplified parallel jaws of the paper's figure 8
(`Jaws`) and a single suction cup on a body (`SuctionCup`: the paper's further work, "other
kinds of grippers, such as vacuum"). `GripperKind` is their union, told apart by `kind` (the
experiment file's `gripper.type`) and found by it in `KINDS`; nothing outside this package
asks which kind a gripper is. Each kind owns:
- `KEYS`: its keys, one table (`Key`): the field (SI, the validity node's parameter
  `gripper.<field>`, the message's field), the experiment file's key and unit, the limit, what
  it is and where its default comes from;
- its grasps: `written`, the record a file or a request gives (grasps.GraspPose or
  grasps.SuctionGrasp), and `check_grasp`, the checked one (grasps.Grasp or grasps.CupGrasp);
  `width`, how wide it is at a grasp (a result's jaw_opening);
- `shapes`: its collision shapes at a grasp, in the gripper frame;
- `grip`: what every check of a setup shares of it (`Grip`: the wrist tilts it tries, what
  each grasp's jaws close on, the round body a grasp may turn about, which grasps it may use);
- `approach`: the gripper's axis over a part as it lies, before any wrist tilt;
- `propose`: the grasps `part.grasps: auto` takes;
- `size`: what "smaller" means when grippers of the kind are compared (a gripper_sweep);
- its lines on a part sheet (`account`, `figures`, `figures_line`, `pick_caption`,
  `pick_marks`, `proposal_rule`, `proposed_widths`).
Adding a kind is a module here with its class and the class's entry in `KINDS`
(docs/extending.md lists the rest).

Units: metres, pascals, m/s^2; the part frame, or the gripper frame for its shapes.
"""

from dataclasses import fields

from pick_common.errors import InvalidArgument

from ..grasps import CupGrasp, Grasp
from .base import ASSUMED, Grip, Key, Kind, UNITS
from .jaws import JAW_OPENING, Jaws
from .suction_cup import SuctionCup, VACUUM_SOURCE

__all__ = ['ASSUMED', 'check_grasps', 'Grip', 'GripperKind', 'JAW_OPENING', 'Jaws', 'Key',
           'Kind', 'kind_of_key', 'KINDS', 'MAX_GRASPS', 'SuctionCup', 'UNITS',
           'VACUUM_SOURCE']

MAX_GRASPS = 32
GripperKind = Jaws | SuctionCup
KINDS: dict[str, type[GripperKind]] = {k.kind: k for k in (Jaws, SuctionCup)}


def kind_of_key(file_key: str) -> type[GripperKind] | None:
    """The first kind (in KINDS' order) with this file key, or None."""
    return next((k for k in KINDS.values() if any(key.file_key == file_key for key in k.KEYS)),
                None)


def not_its_key(file_key: str, gripper) -> str:
    """The one wording that refuses a file key `gripper`'s kind (a kind or one of it) does
    not have, wherever the key is given (the gripper section, a sweep's grid, a
    sensitivity's input): whose key it is, and the gripper's kind."""
    owner = kind_of_key(file_key)
    return (f'is a key of {owner.description}' if owner else 'is no gripper key') + (
        f', and the gripper is {gripper.description} (gripper.type: {gripper.kind})')


def check_grasps(grasps, gripper: GripperKind) -> tuple[Grasp, ...] | tuple[CupGrasp, ...]:
    """Check every grasp pose as the gripper's kind reads it. A grasp of another kind is
    refused, saying what the gripper's kind wants."""
    if not 1 <= len(grasps) <= MAX_GRASPS:
        raise InvalidArgument('grasps', len(grasps), f'must hold 1..{MAX_GRASPS} grasp poses')
    out = []
    for i, g in enumerate(grasps):
        # Named as the node's parameters are (grasps.<name>.up_axis) when the grasp has a name.
        where = f'grasps.{g.name}' if g.name else f'grasps[{i}]'
        if not isinstance(g, gripper.written):
            written = next(k for k in KINDS.values() if isinstance(g, k.written))
            raise InvalidArgument(
                where, g.name, f'is a {written.kind} grasp, and the gripper is '
                f'{gripper.description}: ' + _grasp_keys(gripper))
        out.append(gripper.check_grasp(g, where, g.name or f'grasp_{i}'))
    return tuple(out)


def _grasp_keys(gripper: GripperKind) -> str:
    keys = [f.name for f in fields(gripper.written) if f.name not in ('name', 'grasp_point')]
    return f'give {" and ".join(keys)} (and grasp_point), or another gripper type'
