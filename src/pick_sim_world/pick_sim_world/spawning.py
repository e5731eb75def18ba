"""Where dropped and fed parts appear: the drop region of a container and non-overlapping spawn
poses above the parts already there.

Pure: numpy only. Poses are (N, 7) float64, xyz in metres then an xyzw unit quaternion, in the
instance frame (origin at the centre of the container's inner floor, +Z up).
"""

import math

import numpy as np
from pick_common import containers
from pick_common.containers import check_fits, ContainerSpec
from pick_common.errors import check_int, InvalidArgument
from pick_common.parts.geometry import PartGeometry
from pick_common.specs import MAX_PARTS_PER_INSTANCE
from pick_common.states import rotate

from .config import GRAVITY

SPAWN_GAP = 0.0005              # m of clearance between spawn spheres
ZONES = ('container', 'feeder')


def random_quaternions(rng: np.random.Generator, n: int) -> np.ndarray:
    """n uniformly distributed unit quaternions, (n, 4) xyzw."""
    q = rng.normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def drop_region(spec: ContainerSpec, zone: str,
                instance: int = 0) -> tuple[float, float, float, float]:
    """Centre x, y and half extents x, y of where parts spawn in `zone` ('container': the whole
    inner floor; 'feeder': the tray's feeder zone), in the instance frame, m."""
    if zone == 'container':
        return 0.0, 0.0, spec.inner_size[0] / 2, spec.inner_size[1] / 2
    if zone == 'feeder':
        if spec.kind != containers.TRAY:
            raise InvalidArgument('zone', zone, f'needs a tray; instance {instance} has a '
                                  f'{spec.kind}, which has no feeder')
        (cx, cy), (sx, sy) = spec.feeder_zone_center, spec.feeder_zone_size
        return cx, cy, sx / 2, sy / 2
    raise InvalidArgument('zone', zone, f'must be {" or ".join(ZONES)}')


def grid(part: PartGeometry, region: tuple[float, float, float, float],
         zone: str = 'container') -> tuple[int, int]:
    """Cells along x and y of one spawn layer over `region`: cells as wide as the part's
    bounding sphere. Raises InvalidArgument when the region is narrower than one cell."""
    _, _, hx, hy = region
    r = part.radius + SPAWN_GAP
    span_x, span_y = 2.0 * (hx - r), 2.0 * (hy - r)
    if span_x < 0 or span_y < 0:
        raise InvalidArgument(
            'container.inner_size' if zone == 'container' else 'container.feeder_zone_size',
            (2 * hx, 2 * hy), f'is smaller than the part ({2 * r:.4g} m across in any '
            'orientation): parts cannot be dropped into it')
    return int(span_x // (2.0 * r)) + 1, int(span_y // (2.0 * r)) + 1


def layer_interval(part: PartGeometry, fall: float = 0.0) -> float:
    """Simulated time between two spawn layers of a drop, s: the free fall of `fall` (m, the
    arrival height over the floor) and one layer's height (a bounding-sphere diameter), plus a
    fifth of it again, so that each layer has landed before the next one appears."""
    return 1.2 * math.sqrt(2.0 * (fall + 2.0 * (part.radius + SPAWN_GAP)) / GRAVITY)


def check_count(count: int, held: dict[int, int], part: PartGeometry,
                container: ContainerSpec) -> int:
    """`count` parts more for each instance k that holds `held[k]`: within the per-instance
    limit and fitting the container (containers.check_fits). Raises InvalidArgument naming
    what the number is when parts are there already."""
    count = check_int('count', count, low=1, high=MAX_PARTS_PER_INSTANCE)
    for k, there in held.items():
        total = count + there
        if total > MAX_PARTS_PER_INSTANCE:
            raise InvalidArgument('count', count, f'would put {total} parts in instance {k}'
                                  f' (limit {MAX_PARTS_PER_INSTANCE})')
        check_fits('count' if not there else f'count + the {there} parts in instance {k}',
                   total, part.volume, container)
    return count


def pile_top(part: PartGeometry, region: tuple[float, float, float, float],
             centres: np.ndarray) -> float:
    """The height, m, above which new parts spawn over `region` (centre x, y and half extents
    x, y): the highest of the parts already there (`centres` (N, 3), their spheres' centres)
    that lie within two part radii of it, plus a radius; 0 over an empty region."""
    if not len(centres):
        return 0.0
    cx, cy, hx, hy = region
    reach = 2.0 * part.radius
    over = ((np.abs(centres[:, 0] - cx) <= hx + reach)
            & (np.abs(centres[:, 1] - cy) <= hy + reach))
    return max(0.0, float(centres[over, 2].max()) + part.radius) if over.any() else 0.0


def layer(rng: np.random.Generator, part: PartGeometry, spec: ContainerSpec, zone: str,
          centres: np.ndarray, count: int) -> np.ndarray:
    """The poses (count, 7) of a drop's next spawn layer(s) over `zone` of a container whose
    parts have bounding-sphere centres `centres` (N, 3): from the container's drop height, or
    just above the parts over the region where higher (pile_top; spawn_poses)."""
    region = drop_region(spec, zone)
    top = max(pile_top(part, region, centres), containers.drop_height(spec))
    return spawn_poses(rng, part, region, top, count, zone)


def spawn_poses(rng: np.random.Generator, part: PartGeometry,
                region: tuple[float, float, float, float], top: float, count: int,
                zone: str = 'container') -> np.ndarray:
    """Random, non-overlapping spawn poses (count, 7) in the instance frame.

    Parts spawn in layers of a grid of cells as wide as the part's bounding sphere, from `top`
    (m, the arrival height over the floor, or the highest point of the parts already there
    where that is higher) up, each with a uniformly
    random orientation. The grid is shifted at random within its slack and each layer takes a
    random subset of cells. No two spawn spheres overlap, so nothing is blown apart (the
    paper's first problem).
    """
    cx, cy, hx, hy = region
    r = part.radius + SPAWN_GAP
    cell = 2.0 * r
    span_x, span_y = 2.0 * (hx - r), 2.0 * (hy - r)
    nx, ny = grid(part, region, zone)
    per_layer = nx * ny
    centers = np.empty((count, 3))
    for start in range(0, count, per_layer):
        layer = start // per_layer
        n = min(per_layer, count - start)
        shift_x = rng.uniform(0.0, span_x - (nx - 1) * cell)
        shift_y = rng.uniform(0.0, span_y - (ny - 1) * cell)
        cells = rng.permutation(per_layer)[:n]
        ix, iy = np.divmod(cells, ny)
        centers[start:start + n, 0] = cx - hx + r + shift_x + ix * cell
        centers[start:start + n, 1] = cy - hy + r + shift_y + iy * cell
        centers[start:start + n, 2] = top + r + layer * cell
    quats = random_quaternions(rng, count)
    # The spawn sphere is centred on the compound's bounding-box centre, not the origin.
    origins = centers - rotate(quats, part.center)
    return np.hstack([origins, quats])
