"""Frozen definitions of the gripper, the grasp poses, the placement and the check settings,
and their validation in one place (shared by the node, the services and the tests); `Setup`
packs them with the part spec: the one input a check is built from.

Units: metres and radians. Axes are in the part frame.
"""

from dataclasses import dataclass, field
import math

import numpy as np
from pick_common.errors import check_vector, InvalidArgument, Limit
from pick_common.parts.spec import geometry_key, PartSpec

MAX_GRASPS = 32
MAX_TILTS = 361
PARALLEL_LIMIT = math.radians(5.0)   # closing and up axes closer than this are "parallel"
# The range of each setting, by the validity node's parameter name (a grasp's jaw_opening is
# grasps.<name>.jaw_opening there). m and rad.
LIMITS = {
    'gripper.body_diameter': Limit(0.0, 1.0, low_open=True),
    'gripper.body_length': Limit(0.0, 2.0, low_open=True),
    'gripper.jaw_height': Limit(0.0, 1.0, low_open=True),
    'gripper.jaw_depth': Limit(0.0, 1.0, low_open=True),
    'gripper.finger_clearance': Limit(0.0, 1.0),
    'jaw_opening': Limit(0.0, 1.0, low_open=True),
    'place.seat_offset': Limit(-1.0, 1.0),
    'check.tolerance': Limit(0.0, math.pi / 2, low_open=True),
    'check.tilt_min': Limit(-math.pi / 2, math.pi / 2),
    'check.tilt_max': Limit(-math.pi / 2, math.pi / 2),    # and at least tilt_min
    'check.tilt_step': Limit(math.radians(0.1), math.pi),
    'check.approach_cone': Limit(0.0, math.pi / 2, low_open=True),
    'check.rim_tolerance': Limit(0.0, 1.0),
    'check.station_margin': Limit(0.0, 10.0),
    'gripper.cup_diameter': Limit(0.0, 0.5, low_open=True),
    'gripper.cup_height': Limit(0.0, 0.5, low_open=True),
    'gripper.vacuum': Limit(0.0, 101_325.0, low_open=True),     # Pa below the atmosphere
    'gripper.safety_factor': Limit(1.0, 10.0),
    'gripper.acceleration': Limit(0.0, 1000.0),
    'gripper.cup_friction': Limit(0.0, 2.0, low_open=True),
}


@dataclass(frozen=True)
class Gripper:
    """The simplified parallel-jaw gripper (paper figure 8).

    body_diameter D and body_length of the body cylinder; jaw_height V and jaw_depth W of the
    jaws' workspace cuboid (its width U is the grasp's jaw opening). m.

    finger_clearance: how far above the bottom of the grasped part the fingertips stop, m. The
    fingers close around the part as a parallel gripper's do: the jaws' cuboid reaches from the
    fingertips up, and the body sits on top of it. The grasped part's bottom is the lowest
    point, along the grasp's up axis, of the collision primitive that holds the grasp point
    (the body of a built-in part). At 0 the fingertips would be level with the floor under
    every resting part (and below it by the physics' overlap, up to 1 mm); pick programs stop
    them short of the surface. The fingertips never go above the grasp point nor deeper
    than V below it.
    """

    body_diameter: float = 0.020
    body_length: float = 0.060
    jaw_height: float = 0.015
    jaw_depth: float = 0.006
    finger_clearance: float = 0.001


@dataclass(frozen=True)
class SuctionCup:
    """A single suction cup on a body (the paper's further work: "other kinds of grippers,
    such as vacuum"). m, Pa, m/s^2.

    cup_diameter and cup_height: the cup's rim and how high its lip (or bellows) stands above
    the rim to the body; the cup approaches along minus the grasp's up axis and seals when its
    rim lies on the part all round (`suction.seal`). body_diameter and body_length: the
    cylinder above the cup. vacuum: the pressure below the atmosphere the cup holds at;
    safety_factor, acceleration (the robot's, horizontal) and cup_friction (cup on part) set
    the force the cup must hold (`suction.holding`). Defaults and their sources: VACUUM_SOURCE.
    """

    cup_diameter: float = 0.004
    cup_height: float = 0.003
    body_diameter: float = 0.010
    body_length: float = 0.060
    vacuum: float = 60_000.0
    safety_factor: float = 2.0
    acceleration: float = 10.0
    cup_friction: float = 0.5


# Where the suction cup's defaults come from.
VACUUM_SOURCE = (
    'vacuum 60 kPa: Schmalz, glossary "Holding force" (a cup\'s holding force is usually '
    'stated at 60 % vacuum); safety factor 2 and cup friction 0.5: Schmalz, "Theoretical '
    'holding force of a suction cup" (S at least 1.5 for smooth, dense workpieces, 2.0 or more '
    'for critical ones; mu 0.5 for metal, glass, stone); cup 4 x 3 mm, body 10 x 60 mm and the '
    "robot's acceleration 10 m/s^2: assumed")


@dataclass(frozen=True)
class SuctionGrasp:
    """A suction grasp, in the part frame: up_axis must point along world +Z; grasp_point,
    m, is the point on the part's surface where the cup's centre touches, the cup approaching
    along minus up_axis."""

    name: str
    up_axis: tuple[float, float, float]
    grasp_point: tuple[float, float, float] = (0.0, 0.0, 0.0)


def is_suction(gripper: 'Gripper | SuctionCup') -> bool:
    return isinstance(gripper, SuctionCup)


@dataclass(frozen=True)
class GraspPose:
    """A user-defined grasp pose (paper figure 4), in the part frame.

    up_axis must point along world +Z; closing_axis lies along the jaws' closing direction;
    jaw_opening is U, m; grasp_point is the point the jaws close on (the gripper frame's
    origin), m.
    """

    name: str
    up_axis: tuple[float, float, float]
    closing_axis: tuple[float, float, float]
    jaw_opening: float
    grasp_point: tuple[float, float, float] = (0.0, 0.0, 0.0)


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
class Setup:
    """Everything a check runs with besides the scene, packed once where it is read (the
    experiment file, the node's parameters, a check_parts request): the part's spec (the
    validator builds its geometry), the gripper, its grasp poses, how the part is placed and
    the check's settings. Checked when a Validator is built from it."""

    part: PartSpec = PartSpec()
    gripper: Gripper | SuctionCup = Gripper()
    grasps: tuple[GraspPose, ...] | tuple[SuctionGrasp, ...] = CAPACITOR_GRASPS
    place: PlaceSpec = PlaceSpec()
    config: CheckConfig = CheckConfig()

    def key(self) -> tuple:
        """What a validator built from this setup depends on, hashable: the part's geometry
        (not its mass or friction) and the rest as they are."""
        return geometry_key(self.part), self.gripper, self.grasps, self.place, self.config


@dataclass(frozen=True)
class Grasp:
    """A checked grasp pose: unit up axis, unit closing axis orthogonal to it."""

    name: str
    up: np.ndarray = field(repr=False)
    closing: np.ndarray = field(repr=False)
    jaw_opening: float
    point: np.ndarray = field(repr=False)


def _unit(field_name: str, values) -> np.ndarray:
    v = np.array(check_vector(field_name, values, 3))
    norm = float(np.linalg.norm(v))
    if norm < 1e-9:
        raise InvalidArgument(field_name, tuple(values), 'is a zero vector')
    return v / norm


JAW_FIELDS = ('body_diameter', 'body_length', 'jaw_height', 'jaw_depth', 'finger_clearance')
SUCTION_FIELDS = ('cup_diameter', 'cup_height', 'body_diameter', 'body_length', 'vacuum',
                  'safety_factor', 'acceleration', 'cup_friction')


def check_gripper(gripper: Gripper | SuctionCup) -> Gripper | SuctionCup:
    for name in SUCTION_FIELDS if is_suction(gripper) else JAW_FIELDS:
        LIMITS[f'gripper.{name}'].check(f'gripper.{name}', getattr(gripper, name))
    return gripper


def perpendicular(up: np.ndarray) -> np.ndarray:
    """A unit vector at right angles to `up`: the part axis least along it, made square."""
    axis = np.eye(3)[int(np.argmin(np.abs(up)))]
    axis = axis - (axis @ up) * up
    return axis / np.linalg.norm(axis)


def check_grasps(grasps: list[GraspPose] | tuple[GraspPose, ...] | tuple[SuctionGrasp, ...],
                 gripper: Gripper | SuctionCup | None = None) -> tuple[Grasp, ...]:
    """Check every grasp pose; orthogonalise the closing axis against the up axis. A jaws'
    grasp with a suction cup, or the reverse, is refused. A suction grasp's closing axis is a
    fixed one at right angles to its up axis (the gripper frame's x; the cup is round) and
    its jaw opening the cup's diameter."""
    if not 1 <= len(grasps) <= MAX_GRASPS:
        raise InvalidArgument('grasps', len(grasps), f'must hold 1..{MAX_GRASPS} grasp poses')
    suction = gripper is not None and is_suction(gripper)
    out = []
    for i, g in enumerate(grasps):
        # Named as the node's parameters are (grasps.<name>.up_axis) when the grasp has a name.
        where = f'grasps.{g.name}' if g.name else f'grasps[{i}]'
        if gripper is not None and isinstance(g, SuctionGrasp) != suction:
            raise InvalidArgument(
                where, g.name, f'is a {"suction" if isinstance(g, SuctionGrasp) else "jaws"} '
                f'grasp, and the gripper is {"a suction cup" if suction else "parallel jaws"}: '
                + ('give up_axis and grasp_point (no closing_axis, no jaw_opening)' if suction
                   else 'give closing_axis and jaw_opening, or a suction gripper'))
        up = _unit(f'{where}.up_axis', g.up_axis)
        if isinstance(g, SuctionGrasp):
            point = np.array(check_vector(f'{where}.grasp_point', g.grasp_point, 3,
                                          low=-1.0, high=1.0))
            opening = gripper.cup_diameter if suction else 0.0
            out.append(Grasp(g.name or f'grasp_{i}', up, perpendicular(up), opening, point))
            continue
        closing = _unit(f'{where}.closing_axis', g.closing_axis)
        angle = math.acos(min(1.0, abs(float(up @ closing))))
        if angle < PARALLEL_LIMIT:
            raise InvalidArgument(f'{where}.closing_axis', g.closing_axis,
                                  f'is parallel to up_axis {g.up_axis} (within '
                                  f'{math.degrees(PARALLEL_LIMIT):g} deg)')
        closing = closing - (closing @ up) * up
        closing /= np.linalg.norm(closing)
        opening = LIMITS['jaw_opening'].check(f'{where}.jaw_opening', g.jaw_opening)
        point = np.array(check_vector(f'{where}.grasp_point', g.grasp_point, 3,
                                      low=-1.0, high=1.0))
        out.append(Grasp(g.name or f'grasp_{i}', up, closing, opening, point))
    return tuple(out)


def check_place(place: PlaceSpec) -> tuple[np.ndarray, float]:
    axis = _unit('place.place_axis', place.place_axis)
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
