"""A regrasp station: a flat surface beside the bin where a part the gripper cannot place as it
picked it is put down on a stable face and picked again (the paper's further work: "placing
them on an intermediate surface and regrasping them").

A placement is a face of the part's convex hull it can rest on: the mass centre projects into
the face's support polygon, with a stability margin d / h of at least `check.station_margin`
(d the distance from the projected mass centre to the polygon's nearest edge, h the mass
centre's height above the face: the tilt d / h (as a tangent) a part tips over at, the
quasi-static rule of stable placements that Wan and Harada's regrasp planners use; the 0.1
default is the margin the issue proposing the station names, not a value we found in a
paper). The faces and their margins are the part's resting faces
(pick_common.parts.aspects.resting_faces, the one owner of how a part rests); which placements
a grasp can then pick from and place as required is decided by the validator, which owns the
stages (`Validator.station_ok`).

Pure: no rclpy, no simulator. Units: m; the part frame.
"""

from pick_common.parts.aspects import resting_faces, RestingFace
from pick_common.parts.geometry import PartGeometry


def placements(part: PartGeometry, margin: float) -> tuple[RestingFace, ...]:
    """The hull faces the part rests on with d / h of at least `margin`, steadiest first
    (aspects.resting_faces, which owns the part's resting faces)."""
    return resting_faces(part.visual, part.mass_centre, margin)
