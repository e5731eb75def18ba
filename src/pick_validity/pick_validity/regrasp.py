"""A regrasp station: a flat surface beside the bin where a part the gripper cannot place as it
picked it is put down on a stable face and picked again (the paper's further work: "placing
them on an intermediate surface and regrasping them").

A placement is a face of the part's convex hull it can rest on: the mass centre projects into
the face's support polygon, with a stability margin d / h of at least `check.station_margin`
(d the distance from the projected mass centre to the polygon's nearest edge, h the mass
centre's height above the face: the tilt d / h (as a tangent) a part tips over at, the
quasi-static rule of stable placements that Wan and Harada's regrasp planners use; the 0.1
default is the margin the issue proposing the station names, not a value we found in a
paper). Which placements a grasp can then pick from and place as required is decided by the
validator, which owns the stages (`Validator.station_ok`).

Pure: no rclpy, no simulator. Units: m; the part frame.
"""

from dataclasses import dataclass

import numpy as np
from pick_common.parts.geometry import PartGeometry
from scipy.spatial import ConvexHull, QhullError

from .grasps import perpendicular

PLANE_TOLERANCE = 1e-7      # m: hull vertices this near a face's plane touch the station


@dataclass(frozen=True)
class Placement:
    """The part resting on the station on a hull face: `normal` the face's outward unit
    normal (it points down into the station), `offset` the face's plane (normal . x =
    offset), `ratio` d / h (module docstring)."""

    normal: np.ndarray
    offset: float
    ratio: float


def placements(part: PartGeometry, margin: float) -> tuple[Placement, ...]:
    """The hull faces the part rests on with d / h of at least `margin`, steadiest first."""
    hull = part.visual.convex_hull
    vertices = np.asarray(hull.vertices)
    centre = part.mass_centre
    found = []
    for n in np.unique(np.round(hull.face_normals, 6), axis=0):
        n = n / np.linalg.norm(n)
        offset = float((vertices @ n).max())
        height = offset - float(centre @ n)
        touching = vertices[vertices @ n >= offset - PLANE_TOLERANCE]
        if height <= 0 or len(touching) < 3:
            continue
        e1 = perpendicular(n)
        e2 = np.cross(n, e1)
        flat = np.column_stack([touching @ e1, touching @ e2])
        try:
            polygon = ConvexHull(flat)
        except QhullError:                  # the touching points lie on a line: an edge
            continue
        c = np.array([centre @ e1, centre @ e2])
        # Qhull's facet equations: a . p + b <= 0 inside; -(a . c + b) is c's distance inside
        distance = float(-(polygon.equations[:, :2] @ c + polygon.equations[:, 2]).max())
        ratio = distance / height
        if ratio >= margin:
            found.append(Placement(n, offset, ratio))
    return tuple(sorted(found, key=lambda p: -p.ratio))
