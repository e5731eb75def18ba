"""Containers: a rectangular bin or the vibrating-table tray, in the instance frame, and the
packing rule (how many parts a container may be given).

The instance frame has its origin at the centre of the inner floor, +Z up. The inner box spans
[-x/2, x/2] x [-y/2, y/2] x [0, z]; walls and floor lie outside it. Units: metres.
"""

from dataclasses import dataclass
import math

import numpy as np

from .errors import check_vector, DoesNotFit, InvalidArgument, Limit

BIN = 'bin'
TRAY = 'tray'
KINDS = (BIN, TRAY)
MIN_INNER, MAX_INNER = 0.005, 2.0     # m, per dimension
MAX_WALL, MAX_FLOOR = 0.1, 0.2        # m
TRAY_DEFAULT_SIZE = (0.195, 0.150, 0.027)
LIMITS = {    # m
    'container.wall_thickness': Limit(0.0005, MAX_WALL),
    'container.floor_thickness': Limit(0.001, MAX_FLOOR),
    'container.drop_height': Limit(0.0, 1.0),
    'container.hopper_rate': Limit(0.1, 1000.0),     # parts/s
    'container.hopper_speed': Limit(0.0, 2.0, low_open=True),     # m/s
}
# How high over the floor parts arrive from, by kind, m. Assumed: no maker's figure found for
# either. A bin is filled by pouring from a box held about 100 mm over its floor; a flexible
# feeder's hopper lip stands about 30 mm over the tray's plate.
DROP_HEIGHT = {BIN: 0.1, TRAY: 0.03}
# The hopper that feeds a tray. Its outlet lets parts out at `hopper_rate` parts/s while it runs,
# and a feed runs it for the time the shortfall sets (hopper.py); assumed, no maker gives a
# hopper's rate for a part: Asyril and Epson both have it measured on the cell (Epson
# PF_QtyAdjHopperTime: SupplyQty parts in SupplyTime ms). Parts leave the outlet moving onto the
# tray at `hopper_speed`, a vibratory track's conveying speed: assumed, within the few ft/min
# to 30 m/min IQS Directory gives for vibratory feeders ("Vibratory Feeders", chapter 1).
HOPPER_RATE = 10.0      # parts/s
HOPPER_SPEED = 0.1      # m/s
PACKING_LIMIT = 0.4     # largest fraction of a container's inner volume parts may fill


@dataclass(frozen=True)
class ContainerSpec:
    """A rectangular container.

    inner_size: inner length x, width y, wall height z, m.
    wall_thickness, floor_thickness: m. The floor is thick so that fast parts cannot tunnel.
    feeder_zone_center, feeder_zone_size: the tray's feeder drop zone on its floor (x, y), m.
    drop_height: how high over the floor parts arrive from, m: the box a bin is poured from,
    the outlet of the hopper that feeds a tray (its lip: the lowest point of a part leaving
    it); None takes the kind's DROP_HEIGHT.
    hopper_rate, hopper_speed: a tray's hopper: parts it lets out per second while it runs,
    and their speed onto the tray as they leave it, m/s; None takes HOPPER_RATE, HOPPER_SPEED.
    The outlet is the feeder zone's edge farther from the tray's centre along x (the hopper
    stands beyond it), as wide as the zone, and parts leave it moving along x toward the centre.
    """

    kind: str = BIN
    inner_size: tuple[float, float, float] = (0.3, 0.3, 0.026)
    wall_thickness: float = 0.003
    floor_thickness: float = 0.01
    feeder_zone_center: tuple[float, float] = (0.0, 0.0)
    feeder_zone_size: tuple[float, float] = (0.0, 0.0)
    drop_height: float | None = None
    hopper_rate: float | None = None
    hopper_speed: float | None = None

    @staticmethod
    def tray(inner_size: tuple[float, float, float] = TRAY_DEFAULT_SIZE) -> 'ContainerSpec':
        """The vibrating-table tray with its feeder zone at the -X end (a quarter of its length)."""
        x, y, _ = inner_size
        return ContainerSpec(kind=TRAY, inner_size=tuple(inner_size), wall_thickness=0.003,
                             floor_thickness=0.01, feeder_zone_center=(-3 * x / 8, 0.0),
                             feeder_zone_size=(x / 4, 0.8 * y))


def drop_height(spec: ContainerSpec) -> float:
    """How high over the floor parts arrive from, m (the spec's, or its kind's default)."""
    return DROP_HEIGHT[spec.kind] if spec.drop_height is None else spec.drop_height


def hopper(spec: ContainerSpec) -> tuple[float, float]:
    """A tray's hopper rate, parts/s, and exit speed, m/s (the spec's, or the defaults)."""
    return (HOPPER_RATE if spec.hopper_rate is None else spec.hopper_rate,
            HOPPER_SPEED if spec.hopper_speed is None else spec.hopper_speed)


def check_container(spec: ContainerSpec) -> ContainerSpec:
    """Check every field; raise InvalidArgument naming the first that is wrong."""
    if spec.kind not in KINDS:
        raise InvalidArgument('container.kind', spec.kind, f'must be one of {", ".join(KINDS)}')
    check_vector('container.inner_size', spec.inner_size, 3, low=MIN_INNER, high=MAX_INNER)
    LIMITS['container.wall_thickness'].check('container.wall_thickness', spec.wall_thickness)
    LIMITS['container.floor_thickness'].check('container.floor_thickness',
                                              spec.floor_thickness)
    for key in ('drop_height', 'hopper_rate', 'hopper_speed'):
        if getattr(spec, key) is not None:
            LIMITS[f'container.{key}'].check(f'container.{key}', getattr(spec, key))
    if spec.kind == TRAY:
        cx, cy = check_vector('container.feeder_zone_center', spec.feeder_zone_center, 2)
        sx, sy = check_vector('container.feeder_zone_size', spec.feeder_zone_size, 2,
                              low=0.0, low_open=True)
        x, y, _ = spec.inner_size
        if abs(cx) + sx / 2 > x / 2 + 1e-9 or abs(cy) + sy / 2 > y / 2 + 1e-9:
            raise InvalidArgument('container.feeder_zone_size', (sx, sy),
                                  f'at {cx:g}, {cy:g} reaches outside the inner floor '
                                  f'{x:g} x {y:g}')
    return spec


def check_fits(field: str, count: int, part_volume: float, spec: ContainerSpec) -> None:
    """The packing rule, for the world and the experiment file alike: `count` parts of
    `part_volume` m^3 may fill at most PACKING_LIMIT of the container's inner volume. Raises
    DoesNotFit (an InvalidArgument) naming field, the count and the most that fit otherwise."""
    inner = math.prod(spec.inner_size)
    if count * part_volume > PACKING_LIMIT * inner:
        most = int(PACKING_LIMIT * inner / part_volume)
        size = ' x '.join(f'{s * 1000:g}' for s in spec.inner_size)
        raise DoesNotFit(field, count, (
            f'parts do not fit a container of {size} mm: {part_volume * 1e9:.4g} mm^3 each, '
            f'at most {most} within the packing limit {PACKING_LIMIT:g}'), most)


def wall_boxes(spec: ContainerSpec) -> list[tuple[tuple[float, float, float],
                                                  tuple[float, float, float]]]:
    """Floor and four walls as (half extents, centre) boxes in the instance frame, m."""
    x, y, z = spec.inner_size
    t, f = spec.wall_thickness, spec.floor_thickness
    ox, oy = x / 2 + t, y / 2 + t
    boxes = [((ox, oy, f / 2), (0.0, 0.0, -f / 2))]
    for s in (-1.0, 1.0):
        boxes.append(((t / 2, oy, z / 2), (s * (x / 2 + t / 2), 0.0, z / 2)))
        boxes.append(((x / 2, t / 2, z / 2), (0.0, s * (y / 2 + t / 2), z / 2)))
    return boxes


def outer_size(spec: ContainerSpec) -> tuple[float, float, float]:
    """Outer length, width and height including walls and floor, m."""
    x, y, z = spec.inner_size
    t = spec.wall_thickness
    return (x + 2 * t, y + 2 * t, z + spec.floor_thickness)


def inside(spec: ContainerSpec, points: np.ndarray, tolerance: float = 0.001,
           above_rim: float | None = None) -> np.ndarray:
    """Which points (N, 3) in the instance frame lie within the inner box, (N,) bool.

    The box is open upwards to `above_rim` m above the walls' top (None: the wall height
    again, the world's rule): a part resting on a pile that rises above the walls is still in
    the container; tolerance (m) absorbs contact penetration.
    """
    x, y, z = spec.inner_size
    top = z + (z if above_rim is None else above_rim)
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    return ((np.abs(p[:, 0]) <= x / 2 + tolerance) & (np.abs(p[:, 1]) <= y / 2 + tolerance)
            & (p[:, 2] >= -tolerance) & (p[:, 2] <= top + tolerance))


def beside(spec: ContainerSpec, points: np.ndarray, reach: float) -> np.ndarray:
    """Which points (N, 3) in the instance frame have come down beside the container, (N,)
    bool: outside its outer footprint and within `reach` m of the cell's table it stands on
    (the plane of its underside, z = -floor_thickness) or below it. A part's centre there,
    `reach` its bounding radius, has left the container over a wall and landed."""
    x, y, _ = spec.inner_size
    t = spec.wall_thickness
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    out = (np.abs(p[:, 0]) > x / 2 + t) | (np.abs(p[:, 1]) > y / 2 + t)
    return out & (p[:, 2] < -spec.floor_thickness + reach)


def tunnelled(spec: ContainerSpec, points: np.ndarray) -> np.ndarray:
    """Which points (N, 3) in the instance frame lie in or under the floor or inside a wall,
    (N,) bool: where the centre of a solid part can only be if it passed through the container
    (a physics fault), not over a wall.

    Under the floor: within the outer footprint and below the floor's top face. In a wall:
    between a wall's inner and outer faces and below its top.
    """
    x, y, z = spec.inner_size
    t = spec.wall_thickness
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    ax, ay = np.abs(p[:, 0]), np.abs(p[:, 1])
    footprint = (ax <= x / 2 + t) & (ay <= y / 2 + t)
    in_walls = footprint & ((ax > x / 2) | (ay > y / 2)) & (p[:, 2] <= z)
    return (footprint & (p[:, 2] < 0.0)) | in_walls
