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
from pick_common.parts.aspects import RestingFace
from pick_common.parts.geometry import build_part, PartGeometry

from .config import check_place, CheckConfig, Setup, tilts
from .geometry import part_shapes, rotations_about_x, Shape
from .grasp_fit import GraspFit
from .grasps import CupGrasp, Grasp
from .grippers import check_grasps, GripperKind
from .regrasp import placements
from .suction import Holding, Seal


@dataclass(frozen=True, eq=False)
class CheckGeometry:
    """part: the part's geometry; config: the check's settings; gripper, of any kind
    (grippers.py); grasps, checked by its kind, with grasp_fits (what each one's jaws close
    on; a cup's: none), finger_depths (m below its grasp point) and free_axes (G, 3) (the axis
    of the round body a grasp closes across, about which it may turn; zeros for a grasp fixed
    to the part); tilts (T,) rad and tilt_rotations (T, 3, 3) about the gripper's x (the
    gripper's kind decides them: a cup has one); place_axis (3,) and seat_offset, m (the
    placing surface in the part frame); part_shapes; per grasp, the gripper's shapes and their
    FCL objects (one per shape, reused by a query that sets its transform); usable (G,) bool:
    the grasps the check may use (a cup's that seals and holds; every jaws' grasp), and a
    cup's seals and holds per grasp."""
    part: PartGeometry
    config: CheckConfig
    gripper: GripperKind
    grasps: tuple[Grasp, ...] | tuple[CupGrasp, ...]
    grasp_fits: tuple[GraspFit, ...]
    tilts: np.ndarray
    tilt_rotations: np.ndarray
    place_axis: np.ndarray
    seat_offset: float
    part_shapes: tuple[Shape, ...]
    finger_depths: tuple[float, ...]
    gripper_shapes: tuple[tuple[Shape, ...], ...]
    gripper_objects: tuple[tuple[fcl.CollisionObject, ...], ...]
    free_axes: np.ndarray
    usable: np.ndarray
    seals: tuple[Seal, ...] = ()
    holds: tuple[Holding, ...] = ()
    # with a regrasp station (config.regrasp_station): the placements the part rests on
    # there, and from which of them a grasp picks it and places it as required (set by the
    # Validator, which owns the stages); None without a station
    placements: tuple[RestingFace, ...] = ()
    station_ok: np.ndarray | None = None


def build_geometry(setup: Setup, part: PartGeometry | None = None) -> CheckGeometry:
    """The geometry of a setup's checks. `part`: the geometry of setup.part when the caller
    has built it already (the world's); built here otherwise. Raises InvalidArgument for a bad
    setup, or a grasp the gripper cannot use (a jaws' that cannot close on the part:
    grasp_fit; no cup's that seals and holds)."""
    part = part if part is not None else build_part(setup.part)
    gripper = setup.gripper.check()
    grasps = check_grasps(list(setup.grasps), gripper)
    angles = tilts(setup.config)
    place_axis, seat_offset = check_place(setup.place)
    shapes = part_shapes(part)
    grip = gripper.grip(part, tuple(setup.grasps), grasps, angles, shapes)
    return CheckGeometry(
        placements=placements(part, setup.config.station_margin)
        if setup.config.regrasp_station else (),
        part=part, config=setup.config, gripper=gripper, grasps=grasps, grasp_fits=grip.fits,
        tilts=grip.tilts, tilt_rotations=rotations_about_x(grip.tilts), place_axis=place_axis,
        seat_offset=seat_offset, part_shapes=shapes, finger_depths=grip.finger_depths,
        gripper_shapes=grip.shapes,
        gripper_objects=tuple(tuple(s.fcl_object() for s in pair) for pair in grip.shapes),
        free_axes=grip.free_axes, usable=grip.usable, seals=grip.seals, holds=grip.holds)
