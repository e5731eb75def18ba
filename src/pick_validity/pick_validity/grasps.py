"""The grasps of each gripper kind, as written (in a file, a request, a parameter) and as
checked (unit axes, the kind's own fields): a jaws' grasp closes on the part with an opening,
a suction grasp is where the cup's centre touches the part. Which kind reads which grasp is
the kinds' (grippers.py); these are the records only, shared by the modules that measure a
grasp (grasp_fit, suction, grasp_proposals) and the kinds themselves.

Units: metres. Axes are in the part frame.
"""

from dataclasses import dataclass, field
import math

import numpy as np
from pick_common.errors import check_vector, InvalidArgument

PARALLEL_LIMIT = math.radians(5.0)   # closing and up axes closer than this are "parallel"


@dataclass(frozen=True)
class GraspPose:
    """A user-defined grasp pose of parallel jaws (paper figure 4), in the part frame.

    up_axis must point along world +Z; closing_axis lies along the jaws' closing direction;
    jaw_opening is U, m; grasp_point is the point the jaws close on (the gripper frame's
    origin), m.
    """

    name: str
    up_axis: tuple[float, float, float]
    closing_axis: tuple[float, float, float]
    jaw_opening: float
    grasp_point: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def as_yaml(self, width: float) -> str:
        """The grasp as an entry of an experiment file's part.grasps (mm), with the width
        the jaws close on, m."""
        return (f'{{name: {self.name}, up_axis: {_vector(self.up_axis)}, closing_axis: '
                f'{_vector(self.closing_axis)}, jaw_opening_mm: {self.jaw_opening * 1000:.2f}, '
                f'grasp_point_mm: {_mm(self.grasp_point)}}}   # closes on {width * 1000:.2f} mm')


@dataclass(frozen=True)
class SuctionGrasp:
    """A suction grasp, in the part frame: up_axis must point along world +Z; grasp_point,
    m, is the point on the part's surface where the cup's centre touches, the cup approaching
    along minus up_axis."""

    name: str
    up_axis: tuple[float, float, float]
    grasp_point: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def as_yaml(self, deviation: float) -> str:
        """The grasp as an entry of an experiment file's part.grasps (mm), with the largest
        deviation of the cup's rim from a plane, m."""
        return (f'{{name: {self.name}, up_axis: {_vector(self.up_axis)}, grasp_point_mm: '
                f'{_mm(self.grasp_point)}}}   # seals within {deviation * 1000:.2f} mm of a plane')


# The default grasp poses, for a radial capacitor (body along part +Z, leads along -Z) lying on
# its side (a radial axis up: four poses cover every roll within 45 deg) or standing. Jaws 11 mm
# wide: the 5 mm body + 2 x (1 mm clearance + 2 mm finger).
CAPACITOR_GRASPS = (
    GraspPose('side_px', (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), 0.011),
    GraspPose('side_nx', (-1.0, 0.0, 0.0), (0.0, 1.0, 0.0), 0.011),
    GraspPose('side_py', (0.0, 1.0, 0.0), (1.0, 0.0, 0.0), 0.011),
    GraspPose('side_ny', (0.0, -1.0, 0.0), (1.0, 0.0, 0.0), 0.011),
    GraspPose('upright', (0.0, 0.0, 1.0), (1.0, 0.0, 0.0), 0.011),
)


@dataclass(frozen=True)
class Grasp:
    """A checked jaws' grasp: unit up axis, unit closing axis orthogonal to it, the jaws'
    opening U, m, and the point they close on."""

    name: str
    up: np.ndarray = field(repr=False)
    closing: np.ndarray = field(repr=False)
    jaw_opening: float
    point: np.ndarray = field(repr=False)


@dataclass(frozen=True)
class CupGrasp:
    """A checked suction grasp: unit up axis (the cup's axis, pointing away from the part),
    the point where the cup's centre touches, and `closing`, a fixed axis at right angles to
    up (the gripper frame's x; the cup is round, so it only names the frame)."""

    name: str
    up: np.ndarray = field(repr=False)
    closing: np.ndarray = field(repr=False)
    point: np.ndarray = field(repr=False)


def _vector(v) -> str:
    return '[' + ', '.join(f'{x:.4g}' for x in v) + ']'


def _mm(point) -> str:
    return '[' + ', '.join(f'{v * 1000:.2f}' for v in point) + ']'


def unit(field_name: str, values) -> np.ndarray:
    v = np.array(check_vector(field_name, values, 3))
    norm = float(np.linalg.norm(v))
    if norm < 1e-9:
        raise InvalidArgument(field_name, tuple(values), 'is a zero vector')
    return v / norm


def grasp_point(where: str, point) -> np.ndarray:
    return np.array(check_vector(f'{where}.grasp_point', point, 3, low=-1.0, high=1.0))
