"""Frozen definitions of the placement and the check settings, and their validation in one
place (shared by the node, the services and the tests); `Setup` packs them with the part spec,
the gripper (one of the kinds of grippers.py) and its grasps (grasps.py): the one input a
check is built from.

Units: metres and radians. Axes are in the part frame.
"""

from dataclasses import dataclass
import math

import numpy as np
from pick_common.errors import InvalidArgument, Limit
from pick_common.parts.spec import geometry_key, PartSpec

from .grasps import CAPACITOR_GRASPS, unit
from .grippers import GripperKind, JAW_OPENING, Jaws

MAX_TILTS = 361
# The range of each setting, by the validity node's parameter name (a grasp's jaw_opening is
# grasps.<name>.jaw_opening there; a gripper's keys and limits are its kind's: grippers.py).
# m and rad.
LIMITS = {
    'jaw_opening': JAW_OPENING,
    'place.seat_offset': Limit(-1.0, 1.0),
    'check.tolerance': Limit(0.0, math.pi / 2, low_open=True),
    'check.tilt_min': Limit(-math.pi / 2, math.pi / 2),
    'check.tilt_max': Limit(-math.pi / 2, math.pi / 2),    # and at least tilt_min
    'check.tilt_step': Limit(math.radians(0.1), math.pi),
    'check.approach_cone': Limit(0.0, math.pi / 2, low_open=True),
    'check.rim_tolerance': Limit(0.0, 1.0),
    'check.station_margin': Limit(0.0, 10.0),
}


@dataclass(frozen=True)
class PlaceSpec:
    """How the part is placed: place_axis (part frame) points down into the placing surface;
    the surface is the plane through seat_offset * place_axis, perpendicular to it, m (the
    part's seating plane, e.g. the bottom of a capacitor's body)."""

    place_axis: tuple[float, float, float] = (0.0, 0.0, -1.0)
    seat_offset: float = 0.0055


@dataclass(frozen=True)
class CheckConfig:
    """tolerance: largest angle between a grasp's up axis and world +Z, rad.

    The gripper closes along the part's closing axis as the part lies; the wrist turns about
    that axis from tilt_min to tilt_max in steps of tilt_step, rad, where tilt 0 is the most
    vertical approach (the gripper's axis in the vertical plane through the closing axis).
    A tilt whose gripper axis is more than approach_cone from world +Z is not tried.
    rim_tolerance: a part whose centre lies more than this above the container's rim is not
    in the container (nor is one beside its walls or below its floor), m.
    regrasp_station: a part no tilt can place as it was picked may be put down on a flat
    station and picked again (regrasp.py); station_margin: the d / h its placement there
    must keep.
    """

    tolerance: float = math.radians(45.0)
    tilt_min: float = math.radians(-45.0)
    tilt_max: float = math.radians(45.0)
    tilt_step: float = math.radians(5.0)
    approach_cone: float = math.radians(45.0)
    rim_tolerance: float = 0.02
    regrasp_station: bool = False
    station_margin: float = 0.1


@dataclass(frozen=True)
class Setup:
    """Everything a check runs with besides the scene, packed once where it is read (the
    experiment file, the node's parameters, a check_parts request): the part's spec (the
    validator builds its geometry), the gripper, its grasp poses, how the part is placed and
    the check's settings. Checked when a Validator is built from it."""

    part: PartSpec = PartSpec()
    gripper: GripperKind = Jaws()
    grasps: tuple = CAPACITOR_GRASPS     # of the gripper's kind (its `written` grasps)
    place: PlaceSpec = PlaceSpec()
    config: CheckConfig = CheckConfig()

    def key(self) -> tuple:
        """What a validator built from this setup depends on, hashable: the part's geometry
        (not its mass or friction) and the rest as they are."""
        return geometry_key(self.part), self.gripper, self.grasps, self.place, self.config


def check_place(place: PlaceSpec) -> tuple[np.ndarray, float]:
    axis = unit('place.place_axis', place.place_axis)
    return axis, LIMITS['place.seat_offset'].check('place.seat_offset', place.seat_offset)


def tilts(cfg: CheckConfig) -> np.ndarray:
    """Check the settings; the tilt angles to try, rad, from tilt_min to tilt_max inclusive."""
    LIMITS['check.tolerance'].check('check.tolerance', cfg.tolerance)
    LIMITS['check.approach_cone'].check('check.approach_cone', cfg.approach_cone)
    LIMITS['check.rim_tolerance'].check('check.rim_tolerance', cfg.rim_tolerance)
    LIMITS['check.station_margin'].check('check.station_margin', cfg.station_margin)
    low = LIMITS['check.tilt_min'].check('check.tilt_min', cfg.tilt_min)
    high = LIMITS['check.tilt_max'].check('check.tilt_max', cfg.tilt_max, low=low)
    step = LIMITS['check.tilt_step'].check('check.tilt_step', cfg.tilt_step)
    count = int(math.floor((high - low) / step + 1e-9)) + 1
    if count > MAX_TILTS:
        raise InvalidArgument('check.tilt_step', step, f'gives {count} tilts from tilt_min to '
                              f'tilt_max (limit {MAX_TILTS})')
    return low + step * np.arange(count)
