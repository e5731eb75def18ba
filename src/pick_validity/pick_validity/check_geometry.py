"""What every check of one setup shares, built once: the part, the gripper, the grasps and how
each holds the part (its fit, how deep its fingertips reach, the round body it may turn about),
the wrist tilts, the placing surface, and the shapes and FCL objects of part and gripper. One
frozen value that the fast check (validity.Validator), its stages over (part, tilt) pairs
(pairs.py) and the reference (naive.naive_check) all take.

Units: metres, radians; the part frame, or the gripper frame for the gripper's shapes.
"""

from dataclasses import dataclass

import fcl
import numpy as np
from pick_common.errors import InvalidArgument
from pick_common.parts.geometry import build_part, PartGeometry

from .config import (
    check_grasps,
    check_gripper,
    check_place,
    CheckConfig,
    Grasp,
    Gripper,
    is_suction,
    Setup,
    SuctionCup,
    tilts,
)
from .geometry import (
    contains,
    CylinderShape,
    gripper_shapes,
    part_shapes,
    rotations_about_x,
    Shape,
    suction_shapes,
)
from .grasp_fit import body_bottom, check_grasps_fit, GraspFit, round_axis
from .regrasp import Placement, placements
from .suction import Holding, holding, Seal, seal


@dataclass(frozen=True, eq=False)
class CheckGeometry:
    """part: the part's geometry; config: the check's settings; gripper; grasps, with
    grasp_fits (what each one's jaws close on), finger_depths (m below its grasp point) and
    free_axes (G, 3) (the axis of the round body a grasp closes across, about which it may
    turn; zeros for a grasp fixed to the part); tilts (T,) rad and tilt_rotations (T, 3, 3)
    about the gripper's x; place_axis (3,) and seat_offset, m (the placing surface in the part
    frame); part_shapes; per grasp, the gripper's shapes (jaws, body) and their FCL objects
    (one per shape, reused by a query that sets its transform)."""
    part: PartGeometry
    config: CheckConfig
    gripper: Gripper
    grasps: tuple[Grasp, ...]
    grasp_fits: tuple[GraspFit, ...]
    tilts: np.ndarray
    tilt_rotations: np.ndarray
    place_axis: np.ndarray
    seat_offset: float
    part_shapes: tuple[Shape, ...]
    finger_depths: tuple[float, ...]
    gripper_shapes: tuple[tuple[Shape, Shape], ...]
    gripper_objects: tuple[tuple[fcl.CollisionObject, ...], ...]
    free_axes: np.ndarray
    # a suction cup's: per grasp, its seal and holding (suction.seal, suction.holding); and
    # per grasp whether the check may use it (a suction grasp that seals and holds; every
    # jaws' grasp)
    seals: tuple[Seal, ...] = ()
    holds: tuple[Holding, ...] = ()
    usable: np.ndarray | None = None
    # with a regrasp station (config.regrasp_station): the placements the part rests on
    # there, and from which of them a grasp picks it and places it as required (set by the
    # Validator, which owns the stages); None without a station
    placements: tuple[Placement, ...] = ()
    station_ok: np.ndarray | None = None

    @property
    def suction(self) -> bool:
        return is_suction(self.gripper)


def build_geometry(setup: Setup, part: PartGeometry | None = None) -> CheckGeometry:
    """The geometry of a setup's checks. `part`: the geometry of setup.part when the caller
    has built it already (the world's); built here otherwise. Raises InvalidArgument for a bad
    setup or a grasp whose jaws cannot close on the part (grasp_fit)."""
    part = part if part is not None else build_part(setup.part)
    gripper = check_gripper(setup.gripper)
    grasps = tuple(check_grasps(list(setup.grasps), gripper))
    if is_suction(gripper):
        return _suction_geometry(setup, part, gripper, grasps)
    fits = check_grasps_fit(part, setup.grasps)
    place_axis, seat_offset = check_place(setup.place)
    angles = tilts(setup.config)
    shapes = part_shapes(part)
    depths = tuple(_finger_depth(part, gripper, g) for g in grasps)
    jaws = tuple(gripper_shapes(gripper, g.jaw_opening, depth)
                 for g, depth in zip(grasps, depths, strict=True))
    return CheckGeometry(
        placements=_placements(part, setup.config),
        part=part, config=setup.config, gripper=gripper, grasps=grasps, grasp_fits=fits,
        tilts=angles, tilt_rotations=rotations_about_x(angles), place_axis=place_axis,
        seat_offset=seat_offset, part_shapes=shapes, finger_depths=depths,
        gripper_shapes=jaws,
        gripper_objects=tuple(tuple(s.fcl_object() for s in pair) for pair in jaws),
        free_axes=np.stack([_free_axis(part, shapes, g) for g in grasps]))


def _placements(part: PartGeometry, config: CheckConfig) -> tuple[Placement, ...]:
    return placements(part, config.station_margin) if config.regrasp_station else ()


def _finger_depth(part: PartGeometry, gripper: Gripper, grasp: Grasp) -> float:
    """How far below the grasp point the fingertips go, m: to `finger_clearance` above the
    bottom of the body the jaws close on (grasp_fit.body_bottom), between the grasp point
    and V below it."""
    bottom = body_bottom(part, grasp.point, grasp.closing, grasp.up, gripper.jaw_depth,
                         gripper.jaw_height + gripper.finger_clearance)
    return min(gripper.jaw_height, max(0.0, bottom - gripper.finger_clearance))


def _free_axis(part: PartGeometry, shapes: tuple[Shape, ...], grasp: Grasp) -> np.ndarray:
    """The axis of a cylinder of the part that holds the grasp point on its axis and that the
    closing axis crosses at a right angle or runs along (the jaws on its ends), or zeros. A
    built-in model's cylinders are its primitives; a mesh's are found from its surface
    (`grasp_fit.round_axis`)."""
    if part.spec.model == 'mesh':
        return round_axis(part, grasp.point, grasp.closing, grasp.up)
    for shape in shapes:
        axis = shape.rotation[:, 2]
        off = grasp.point - shape.center
        along = abs(float(axis @ grasp.closing))      # across the body, or on its two ends
        if (isinstance(shape, CylinderShape) and contains(shape, grasp.point)
                and (along < 1e-6 or along > 1 - 1e-9)
                and np.linalg.norm(off - (off @ axis) * axis) < 1e-9):
            return axis.copy()
    return np.zeros(3)


def _suction_geometry(setup: Setup, part: PartGeometry, cup: SuctionCup,
                      grasps: tuple[Grasp, ...]) -> CheckGeometry:
    """A suction cup's: one approach per grasp, along minus its up axis (the cup is round, so
    no wrist tilt: `tilts` is [0]); the cup and body as the gripper's shapes; each grasp's
    seal and holding. Raises InvalidArgument when no grasp both seals and holds, naming
    each grasp's reason."""
    tilts(setup.config)                                     # the settings are checked all the same
    place_axis, seat_offset = check_place(setup.place)
    seals = tuple(seal(part, cup, g) for g in grasps)
    holds = tuple(holding(part, cup, g) for g in grasps)
    usable = np.array([s.ok and h.ok for s, h in zip(seals, holds, strict=True)])
    if not usable.any():
        why = '; '.join(f'{g.name!r}: ' + (s.reason or f'holds with a margin of only '
                                              f'{h.margin:.2f}')
                        for g, s, h in zip(grasps, seals, holds, strict=True))
        raise InvalidArgument('grasps', [g.name for g in grasps],
                              f'hold no grasp the cup can use: {why}')
    cups = tuple(suction_shapes(cup) for _ in grasps)
    zero = np.zeros(1)
    return CheckGeometry(
        placements=_placements(part, setup.config),
        part=part, config=setup.config, gripper=cup, grasps=grasps, grasp_fits=(),
        tilts=zero, tilt_rotations=rotations_about_x(zero), place_axis=place_axis,
        seat_offset=seat_offset, part_shapes=part_shapes(part),
        finger_depths=tuple(0.0 for _ in grasps), gripper_shapes=cups,
        gripper_objects=tuple(tuple(s.fcl_object() for s in pair) for pair in cups),
        free_axes=np.zeros((len(grasps), 3)), seals=seals, holds=holds, usable=usable)
