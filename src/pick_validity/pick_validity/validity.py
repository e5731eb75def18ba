"""The staged validity check (paper section 4.1, figure 3), with python-fcl.

Per part, in order, stopping at the first stage that fails:
0. location: a part whose centre is not in the container (beside it, under its floor, or
   more than `rim_tolerance` above its rim) is answered OUTSIDE and not checked;
1. candidacy: a grasp pose's up axis within `tolerance` of world +Z (the nearest is chosen),
   with at least one wrist tilt whose approach lies within `approach_cone` of world +Z;
2. placeability (figure 6): tilts at which the gripper, holding the part as it picked it,
   stays clear of the placing surface once the pair is turned to the part's place orientation;
3. container: of those, tilts at which the gripper clears the container's walls and floor;
4. neighbours: of those, tilts at which the gripper clears every other part (skipped for the
   static bin analysis). A part with a tilt left is valid.

The gripper closes along the grasp's closing axis as the part lies (x), and its axis (z) is
the most vertical one perpendicular to it, turned by the wrist tilt about x; its origin is at
the grasp point. Jaws that close across a round body (the grasp point on the axis of a cylinder
of the part, the closing axis across that axis) grip it at any angle about the axis, as a cell
does, whose camera cannot see a cylinder's roll: the grasp is turned about the axis to bring
its up axis nearest world +Z before the stages (`Validator.free_axes`); a capacitor lying on
its side is then approached from above whatever its roll. So the part-in-gripper pose, and
with it placeability, depends on how the part lies: the same grasp of a part tilted one way
can be placed and tilted the other way not.
Container and neighbour stages decide what exact bounds can decide and ask FCL the rest;
`naive_check` asks FCL everything, with no broadphase and no caching, and must give identical
results.

Poses are (N, 7) float64, xyz m + xyzw unit quaternion, in the container frame (origin at the
centre of the inner floor, +Z up).
"""

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
import itertools
import math
import time

import fcl
import numpy as np
from pick_common import containers
from pick_common.containers import ContainerSpec
from pick_common.errors import InvalidArgument, UnknownPart
from pick_common.parts import PartGeometry
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from .config import (
    check_grasps,
    check_gripper,
    check_place,
    CheckConfig,
    Grasp,
    GraspPose,
    Gripper,
    PlaceSpec,
    tilts,
)
from .geometry import (
    bounds,
    collide,
    contains,
    CYLINDER,
    grasped_extent,
    gripper_shapes,
    matrix_to_quaternion,
    part_shapes,
    place,
    quaternions_to_matrices,
    rotations_about_x,
    Shape,
    support,
)

# The stage a check stopped at (the one that failed), or VALID; values as in PartValidity.msg.
STAGE_NONE, STAGE_CANDIDACY, STAGE_PLACEABILITY, STAGE_CONTAINER, STAGE_NEIGHBOUR, \
    STAGE_VALID, STAGE_OUTSIDE = range(7)
# The stages a part in the container passed, in order (OUTSIDE is not among them: its part
# was not checked).
ORDER = (STAGE_CANDIDACY, STAGE_PLACEABILITY, STAGE_CONTAINER, STAGE_NEIGHBOUR, STAGE_VALID)
CENTRE_TOLERANCE = 0.001      # m beyond the inner walls and floor a part's centre may lie
TIE = 1e-6                    # rad: grasps whose up axes are this near in angle tie (acos near 0
#                               is only good to about 1e-8 rad)
QUATERNION_TOLERANCE = 1e-3   # |norm - 1| accepted (and normalised); larger is refused
MAX_PARTS = 20000
MAX_POSITION = 10.0           # m from the instance frame; a container is at most 2 m wide


@dataclass
class PartResult:
    """One part's check. gripper_pose: (7,) xyz + xyzw in the container frame at the valid tilt
    nearest 0, None unless valid. Angles in rad, jaw_opening in m."""

    part_id: int
    stage: int
    reason: str
    grasp_index: int = -1
    candidacy_angle: float = math.nan
    gripper_pose: np.ndarray | None = None
    jaw_opening: float = 0.0
    valid_tilts: tuple[float, ...] = ()

    @property
    def valid(self) -> bool:
        return self.stage == STAGE_VALID

    def key(self) -> tuple:
        """What two checks must agree on."""
        return self.part_id, self.stage, self.grasp_index, self.valid_tilts


@dataclass
class Report:
    """The results of one check, in the order of the targets, with counts per stage (a part
    outside the container counts as checked and in none of the stages)."""

    results: list[PartResult]
    neighbour_check: bool
    queries: int = 0            # FCL narrowphase queries issued
    wall_time: float = 0.0      # s
    counts: dict[str, int] = field(default_factory=dict)

    def __post_init__(self) -> None:
        passed = [ORDER.index(r.stage) if r.stage in ORDER else -1 for r in self.results]
        self.counts = {
            'checked': len(passed),
            'outside': sum(r.stage == STAGE_OUTSIDE for r in self.results),
            'candidates': sum(p > 0 for p in passed),
            'placeable': sum(p > 1 for p in passed),
            'container_free': sum(p > 2 for p in passed),
            'valid': sum(p == 4 for p in passed)}


def check_poses(ids: Sequence[int], poses: np.ndarray) -> np.ndarray:
    """Refuse NaN/inf and non-unit quaternions (beyond float noise, which is normalised) and
    duplicate ids; return the poses with unit quaternions. A NaN must never reach FCL: it
    reports no collision for a NaN transform."""
    poses = np.asarray(poses, dtype=np.float64)
    if poses.ndim != 2 or poses.shape[1] != 7 or len(poses) != len(ids):
        raise InvalidArgument('parts', poses.shape, f'must be ({len(ids)}, 7) poses')
    if not len(ids):
        raise InvalidArgument('parts', [], 'is empty: send every part of the container')
    if len(ids) > MAX_PARTS:
        raise InvalidArgument('parts', len(ids), f'holds more than {MAX_PARTS} parts')
    bad = np.flatnonzero(~np.isfinite(poses).all(axis=1))
    if len(bad):
        i = int(bad[0])
        raise InvalidArgument(f'parts[{i}] (id {ids[i]}).pose', poses[i].tolist(),
                              'must be finite (no NaN or inf)')
    bad = np.flatnonzero((np.abs(poses[:, :3]) > MAX_POSITION).any(axis=1))
    if len(bad):     # found by fuzzing: 1e154 overflowed in the neighbour search
        i = int(bad[0])
        raise InvalidArgument(f'parts[{i}] (id {ids[i]}).pose.position', poses[i, :3].tolist(),
                              f'must be within {MAX_POSITION:g} m of the instance frame')
    norms = np.linalg.norm(poses[:, 3:], axis=1)
    bad = np.flatnonzero(np.abs(norms - 1.0) > QUATERNION_TOLERANCE)
    if len(bad):
        i = int(bad[0])
        raise InvalidArgument(f'parts[{i}] (id {ids[i]}).pose.orientation', poses[i, 3:].tolist(),
                              f'has norm {norms[i]:.6g}; must be a unit quaternion (within '
                              f'{QUATERNION_TOLERANCE:g}, which is normalised)')
    if len(set(ids)) != len(ids):
        seen = set()
        dup = next(i for i in ids if i in seen or seen.add(i))
        raise InvalidArgument('parts', dup, 'id appears twice')
    out = poses.copy()
    out[:, 3:] /= norms[:, None]
    return out


def _targets(ids: Sequence[int], targets: Iterable[int] | None) -> list[int]:
    index = {pid: i for i, pid in enumerate(ids)}
    if targets is None:
        return list(range(len(ids)))
    rows = []
    for pid in targets:
        if pid not in index:
            raise UnknownPart(f'target_ids: {pid} is not among the parts sent')
        rows.append(index[pid])
    return rows


def _deg(rad: float) -> str:
    return f'{math.degrees(rad):.1f} deg'


class Validator:
    """The checks for one part model, gripper, set of grasps, placement and settings.

    Build once and reuse: part and gripper geometry, and how deep each grasp's fingers reach,
    are computed here, never per part.
    """

    def __init__(self, part: PartGeometry, gripper: Gripper, grasps: Sequence[GraspPose],
                 place_spec: PlaceSpec, config: CheckConfig | None = None) -> None:
        self.config = config or CheckConfig()
        self.part = part
        self.gripper = check_gripper(gripper)
        self.grasps = check_grasps(list(grasps))
        self.place_axis, self.seat_offset = check_place(place_spec)
        self.tilts = tilts(self.config)
        self._rotations = rotations_about_x(self.tilts)
        self.part_shapes = part_shapes(part)
        self.finger_depths = tuple(self._finger_depth(g) for g in self.grasps)
        self.gripper_shapes = [gripper_shapes(self.gripper, g.jaw_opening, depth)
                               for g, depth in zip(self.grasps, self.finger_depths, strict=True)]
        self._gripper_objects = [[s.fcl_object() for s in shapes]
                                 for shapes in self.gripper_shapes]
        # per grasp: the axis (part frame) of the round body its jaws close across, about which
        # it may turn; zero for a grasp that is fixed to the part
        self.free_axes = np.stack([self._free_axis(g) for g in self.grasps])

    def _free_axis(self, grasp: Grasp) -> np.ndarray:
        """The axis of a cylinder of the part that holds the grasp point on its axis and that
        the closing axis crosses at a right angle, or zeros."""
        for shape in self.part_shapes:
            axis = shape.rotation[:, 2]
            off = grasp.point - shape.center
            if (shape.kind == CYLINDER and contains(shape, grasp.point)
                    and abs(float(axis @ grasp.closing)) < 1e-6
                    and np.linalg.norm(off - (off @ axis) * axis) < 1e-9):
                return axis.copy()
        return np.zeros(3)

    def turned(self, rotations: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """For parts at rotations (n, 3, 3): each grasp's angle from world +Z (n, G) once
        turned about its free axis to the most vertical, and that turn (n, G), rad (0 for a
        fixed grasp). With w the world +Z in the part frame and u the up axis, a turn t about
        the unit axis a gives the up axis a height of A cos t + B sin t + C, where
        A = w.u - (a.u)(a.w), B = w.(a x u), C = (a.u)(a.w): largest at t = atan2(B, A)."""
        ups = np.stack([g.up for g in self.grasps])                     # (G, 3)
        w = rotations[:, 2, :]                                          # (n, 3)
        a = self.free_axes
        au = np.einsum('gk,gk->g', a, ups)
        aw = w @ a.T                                                    # (n, G)
        big_a = w @ ups.T - au * aw
        big_b = w @ np.cross(a, ups).T
        free = np.linalg.norm(a, axis=1) > 0
        turn = np.where(free, np.arctan2(big_b, big_a), 0.0)
        height = np.where(free, np.hypot(big_a, big_b) + au * aw, w @ ups.T)
        return np.arccos(np.clip(height, -1.0, 1.0)), turn

    def approach_frames(self, rotations: np.ndarray, grasp_index: np.ndarray,
                        turns: np.ndarray | None = None) -> np.ndarray:
        """The gripper's rotations (n, T, 3, 3) for parts at rotations (n, 3, 3) held with the
        grasps `grasp_index` (n,), each grasp turned about its free axis as the check turns it
        (gripper_frames of the turned part). turns: `turned`'s, when the caller has them."""
        if turns is None:
            _, turns = self.turned(rotations)
        turn = turns[np.arange(len(rotations)), grasp_index]
        return self.gripper_frames(self._grip_rotations(rotations, grasp_index, turn),
                                   grasp_index)

    def _grip_rotations(self, rotations: np.ndarray, grasp_index: np.ndarray,
                        turn: np.ndarray) -> np.ndarray:
        """The part rotations (n, 3, 3) as the gripper takes them: turned by `turn` (n,) about
        the free axis of each part's grasp (Rodrigues)."""
        a = self.free_axes[grasp_index]                                 # (n, 3)
        k = np.zeros((len(a), 3, 3))
        k[:, 0, 1], k[:, 0, 2], k[:, 1, 2] = -a[:, 2], a[:, 1], -a[:, 0]
        k -= np.swapaxes(k, 1, 2)
        s, c = np.sin(turn)[:, None, None], np.cos(turn)[:, None, None]
        return rotations @ (np.eye(3) + s * k + (1.0 - c) * (k @ k))

    def _finger_depth(self, grasp: Grasp) -> float:
        """How far below the grasp point the fingertips go, m: to `finger_clearance` above
        the grasped part's bottom, between the grasp point and V below it."""
        extent = grasped_extent(self.part_shapes, grasp.point, grasp.up)
        return min(self.gripper.jaw_height,
                   max(0.0, extent - self.gripper.finger_clearance))

    def gripper_frames(self, rotations: np.ndarray, grasp_index: np.ndarray) -> np.ndarray:
        """The gripper's rotations in the container frame, (n, T, 3, 3), for parts at
        rotations (n, 3, 3) held with the grasps `grasp_index` (n,), at every tilt: x along the
        part's closing axis, z the most vertical axis perpendicular to it, turned by the tilt
        about x."""
        closing = np.stack([g.closing for g in self.grasps])[grasp_index]
        up = np.stack([g.up for g in self.grasps])[grasp_index]
        x = np.einsum('nij,nj->ni', rotations, closing)
        z = np.array([0.0, 0.0, 1.0]) - x[:, 2:3] * x
        norm = np.linalg.norm(z, axis=1)
        flat = norm < 1e-9         # a vertical closing axis: no approach within any cone
        z[flat] = np.einsum('nij,nj->ni', rotations[flat], up[flat])
        z /= np.linalg.norm(z, axis=1, keepdims=True)
        base = np.stack([x, np.cross(z, x), z], axis=-1)
        return base[:, None] @ self._rotations[None]

    def _approachable(self, frames: np.ndarray) -> np.ndarray:
        """(n, T) bool: the gripper's axis lies within the approach cone of world +Z."""
        return frames[..., 2, 2] >= math.cos(self.config.approach_cone) - 1e-12

    def _placeable(self, rotations: np.ndarray, frames: np.ndarray,
                   grasp_index: np.ndarray) -> np.ndarray:
        """(n, T) bool: with the part turned to its place orientation, the gripper holding it
        as it picked it stays on the gripper's side of the seating plane. Decided in the part
        frame, where the place orientation only fixes the seating plane."""
        n, count = frames.shape[:2]
        relative = (np.swapaxes(rotations, 1, 2)[:, None] @ frames).reshape(-1, 3, 3)
        points = np.stack([g.point for g in self.grasps])[grasp_index]
        origin = np.repeat(points, count, axis=0)
        clear = np.ones(n * count, dtype=bool)
        for g in np.unique(grasp_index):
            sel = np.repeat(grasp_index == g, count)
            for shape in self.gripper_shapes[g]:
                r, c = place(shape, relative[sel], origin[sel])
                clear[sel] &= support(shape, r, c, self.place_axis) < self.seat_offset
        return clear.reshape(n, count)

    # ----------------------------------------------------------------------------- check
    def check(self, container: ContainerSpec, ids: Sequence[int], poses: np.ndarray,
              targets: Iterable[int] | None = None, neighbour_check: bool = True) -> Report:
        """Check the target parts (all when None) among `ids`/`poses` (every part in the
        container: the neighbours). Raises InvalidArgument or UnknownPart for bad input."""
        start = time.perf_counter()
        containers.check_container(container)
        ids = [int(i) for i in ids]
        poses = check_poses(ids, poses)
        rows = _targets(ids, targets)
        rotations = quaternions_to_matrices(poses[:, 3:])
        positions = poses[:, :3]
        results: dict[int, PartResult] = {}
        queries = 0

        # 0. location.
        centres = positions[rows] + rotations[rows] @ self.part.center
        located = containers.inside(container, centres, CENTRE_TOLERANCE,
                                    self.config.rim_tolerance)
        for n in np.flatnonzero(~located):
            row = rows[n]
            results[row] = PartResult(ids[row], STAGE_OUTSIDE, _outside_reason(
                container, centres[n], self.config.rim_tolerance))
        inner = [row for row, ok in zip(rows, located, strict=True) if ok]

        # 1. candidacy, vectorised over targets and grasps (turned on round bodies).
        angles, turns = self.turned(rotations[inner])                   # (n, G)
        best = nearest_grasp(angles, turns)
        frames = self.approach_frames(rotations[inner], best, turns)    # (n, T, 3, 3)
        approach = self._approachable(frames)
        placeable = self._placeable(rotations[inner], frames, best) & approach
        kept: dict[int, np.ndarray] = {}
        world_frames: dict[int, np.ndarray] = {}
        for n, row in enumerate(inner):
            g, angle = int(best[n]), float(angles[n, best[n]])
            result = PartResult(ids[row], STAGE_CANDIDACY, '', g, angle,
                                jaw_opening=self.grasps[g].jaw_opening)
            results[row] = result
            if angle > self.config.tolerance:
                result.grasp_index = -1
                result.reason = (f'no grasp pose within {_deg(self.config.tolerance)} of +Z: '
                                 f'the nearest, {self.grasps[g].name!r}, is at {_deg(angle)}')
                continue
            if not approach[n].any():
                rise = math.asin(min(1.0, abs(float(frames[n, 0, 2, 0]))))
                result.reason = (f'grasp {self.grasps[g].name!r}: no wrist tilt approaches '
                                 f'within {_deg(self.config.approach_cone)} of +Z (the '
                                 f'closing axis rises {_deg(rise)})')
                continue
            # 2. placeability of the tilts within the approach cone.
            if not placeable[n].any():
                result.stage = STAGE_PLACEABILITY
                result.reason = (f'grasp {self.grasps[g].name!r}: held as it lies, the part '
                                 f'cannot be placed: the gripper hits the placing surface at '
                                 f'each of the {int(approach[n].sum())} tilts within the '
                                 f'approach cone')
                continue
            kept[row] = placeable[n].copy()
            world_frames[row] = frames[n]

        # 3. container, 4. neighbours: vectorised over every (part, tilt) pair left.
        pairs = _Pairs(self, kept, results, world_frames, rotations, positions)
        queries += pairs.container(container)
        if neighbour_check:
            queries += pairs.neighbours(ids, rotations, positions)
        for row, mask in kept.items():
            if mask.any():
                self._finish_valid(results[row], mask, world_frames[row], rotations[row],
                                   positions[row])
        return Report([results[row] for row in rows], neighbour_check, queries,
                      time.perf_counter() - start)

    def _finish_valid(self, result: PartResult, mask: np.ndarray, frames: np.ndarray,
                      rotation: np.ndarray, position: np.ndarray) -> None:
        g = result.grasp_index
        valid = np.flatnonzero(mask)
        result.stage = STAGE_VALID
        result.valid_tilts = tuple(float(self.tilts[k]) for k in valid)
        k = valid[np.abs(self.tilts[valid]).argmin()]
        origin = position + rotation @ self.grasps[g].point
        result.gripper_pose = np.concatenate([origin, matrix_to_quaternion(frames[k])])
        result.reason = (f'valid with grasp {self.grasps[g].name!r} at {len(valid)} of '
                         f'{len(self.tilts)} tilts')


def nearest_grasp(angles: np.ndarray, turns: np.ndarray) -> np.ndarray:
    """Per part (rows of (n, G)), the grasp whose up axis is nearest +Z, and among those as
    near (within TIE, rad: on a round body lying flat, every side grasp turns to vertical)
    the one turned least; then the first."""
    if not len(angles):
        return np.zeros(0, dtype=int)
    near = angles <= angles.min(axis=1, keepdims=True) + TIE
    return np.where(near, np.abs(turns), np.inf).argmin(axis=1)


def _outside_reason(container: ContainerSpec, centre: np.ndarray, rim: float) -> str:
    x, y, z = container.inner_size
    mm = ', '.join(f'{1000 * c:.1f}' for c in centre)
    if centre[2] < -CENTRE_TOLERANCE:
        where = 'below the floor'
    elif abs(centre[0]) > x / 2 + CENTRE_TOLERANCE or abs(centre[1]) > y / 2 + CENTRE_TOLERANCE:
        where = f'beside the container (inner {1000 * x:g} x {1000 * y:g} mm)'
    else:
        where = f'more than {1000 * rim:g} mm (check.rim_tolerance) above its {1000 * z:g} mm rim'
    return f'not in the container: its centre ({mm}) mm lies {where}; not checked'


class _Pairs:
    """Every (part, tilt) pair still open after placeability, with the gripper's shapes placed
    in the container frame, their exact bounds, and the masks of `kept` to update."""

    def __init__(self, v: Validator, kept: dict[int, np.ndarray],
                 results: dict[int, PartResult], frames: dict[int, np.ndarray],
                 rotations: np.ndarray, positions: np.ndarray) -> None:
        self.v, self.kept, self.results = v, kept, results
        rows, ks = [], []
        for row, mask in kept.items():
            k = np.flatnonzero(mask)
            rows.append(np.full(len(k), row))
            ks.append(k)
        self.row = np.concatenate(rows) if rows else np.zeros(0, dtype=int)
        self.k = np.concatenate(ks) if ks else np.zeros(0, dtype=int)
        self.g = np.array([results[r].grasp_index for r in self.row], dtype=int)
        count, shapes = len(self.row), 2
        self.rot = np.empty((count, shapes, 3, 3))
        self.center = np.empty((count, shapes, 3))
        self.lo = np.empty((count, shapes, 3))
        self.hi = np.empty((count, shapes, 3))
        self.grasp_point = np.empty((count, 3))
        for g in np.unique(self.g):
            sel = np.flatnonzero(self.g == g)
            r = rotations[self.row[sel]]
            frame = np.stack([frames[row][k] for row, k in zip(self.row[sel], self.k[sel],
                                                                strict=True)])
            origin = positions[self.row[sel]] + r @ v.grasps[g].point
            self.grasp_point[sel] = origin
            for s, shape in enumerate(v.gripper_shapes[g]):
                rot, center = place(shape, frame, origin)
                self.rot[sel, s], self.center[sel, s] = rot, center
                self.lo[sel, s], self.hi[sel, s] = bounds(shape, rot, center)
        self.hit = np.zeros(count, dtype=bool)

    def _object(self, q: int, s: int) -> fcl.CollisionObject:
        obj = self.v._gripper_objects[self.g[q]][s]
        obj.setTransform(fcl.Transform(self.rot[q, s], self.center[q, s]))
        return obj

    def _close(self, stage: int, why: str) -> None:
        """Apply hits to the masks; parts with no tilt left stop at `stage`."""
        for q in np.flatnonzero(self.hit):
            self.kept[self.row[q]][self.k[q]] = False
        for row, mask in self.kept.items():
            result = self.results[row]
            if result.stage == STAGE_CANDIDACY and not mask.any():
                result.stage = stage
                result.reason = why.format(name=self.v.grasps[result.grasp_index].name,
                                           n=int((self.row == row).sum()))
        keep = ~self.hit
        for name in ('row', 'k', 'g', 'rot', 'center', 'lo', 'hi', 'grasp_point', 'hit'):
            setattr(self, name, getattr(self, name)[keep])

    def container(self, container: ContainerSpec) -> int:
        """Stage 3. A convex shape and an axis-aligned wall box: apart when their bounds are;
        certainly touching when the shape's bounds lie within the box's on two axes (its
        projection on the third overlaps, so some point of it is inside). FCL decides the
        rest. Returns the FCL queries issued."""
        queries = 0
        for half, center in containers.wall_boxes(container):
            wc, wh = np.array(center), np.array(half)
            wall = fcl.CollisionObject(fcl.Box(*(2 * wh)), fcl.Transform(np.eye(3), wc))
            for s in range(self.lo.shape[1]):
                lo, hi = self.lo[:, s], self.hi[:, s]
                apart = ((lo > wc + wh) | (hi < wc - wh)).any(axis=1)
                inside = ((lo >= wc - wh) & (hi <= wc + wh)).sum(axis=1) >= 2
                self.hit |= ~apart & inside
                for q in np.flatnonzero(~apart & ~inside & ~self.hit):
                    queries += 1
                    self.hit[q] = collide(self._object(q, s), wall)
        self._close(STAGE_CONTAINER, 'grasp {name!r}: the gripper hits the container at each '
                    'of the {n} placeable tilts')
        return queries

    def neighbours(self, ids: Sequence[int], rotations: np.ndarray,
                   positions: np.ndarray) -> int:
        """Stage 4. Broadphase: a k-d tree over the parts' bounding spheres, queried at once
        with the bounding sphere of every gripper shape at every pair; then exact bounds; FCL
        decides the pairs that overlap, and a pair stops at its first hit."""
        v = self.v
        if not len(self.row):
            return 0
        placed = [place(s, rotations, positions) for s in v.part_shapes]
        part_bounds = [bounds(s, r, c) for s, (r, c) in zip(v.part_shapes, placed, strict=True)]
        tree = cKDTree(positions + np.einsum('nij,j->ni', rotations, v.part.center))
        count, shapes = self.lo.shape[:2]
        radii = np.array([[_radius(s) for s in v.gripper_shapes[g]] for g in self.g])
        near = tree.query_ball_point(self.center.reshape(-1, 3),
                                     radii.reshape(-1) + v.part.radius)
        lengths = np.fromiter(map(len, near), dtype=int, count=len(near))
        jj = np.fromiter(itertools.chain.from_iterable(near), dtype=int, count=lengths.sum())
        qs = np.repeat(np.arange(count * shapes), lengths)
        qq, ss = np.divmod(qs, shapes)
        other_part = jj != self.row[qq]
        qq, ss, jj = qq[other_part], ss[other_part], jj[other_part]
        todo = []
        for p, (plo, phi) in enumerate(part_bounds):
            hit = ~((plo[jj] > self.hi[qq, ss]) | (phi[jj] < self.lo[qq, ss])).any(axis=1)
            todo.append(np.column_stack([qq[hit], ss[hit], jj[hit], np.full(hit.sum(), p)]))
        todo = np.concatenate(todo)
        todo = todo[np.lexsort(todo.T[::-1])]          # by pair, shape, neighbour, primitive
        starts = np.searchsorted(todo[:, 0], np.arange(count + 1)).tolist()
        todo = todo.tolist()
        objects: dict[tuple[int, int], fcl.CollisionObject] = {}
        hits: dict[int, set[int]] = {}
        queries = 0
        for q in range(count):
            shape_set = -1
            for _, s, j, p in todo[starts[q]:starts[q + 1]]:
                other = objects.get((j, p))
                if other is None:
                    other = objects[j, p] = fcl.CollisionObject(
                        v.part_shapes[p].geometry,
                        fcl.Transform(placed[p][0][j], placed[p][1][j]))
                if shape_set != s:
                    gripper = self._object(q, s)
                    shape_set = s
                queries += 1
                if collide(gripper, other):
                    self.hit[q] = True
                    hits.setdefault(int(self.row[q]), set()).add(ids[j])
                    break
        self._close(STAGE_NEIGHBOUR, 'grasp {name!r}: the gripper hits other parts at each of '
                    'the {n} remaining tilts')
        for row, found in hits.items():
            result = self.results[row]
            if result.stage == STAGE_NEIGHBOUR:
                result.reason += f' (parts {sorted(found)})'
        return queries


def _radius(shape: Shape) -> float:
    """Radius of a sphere about the shape's center that encloses it, m."""
    if shape.kind == 'hull':
        return float(np.linalg.norm(shape.vertices, axis=1).max())
    if shape.kind == 'box':
        return float(np.linalg.norm(shape.half))
    return float(math.hypot(shape.half[0], shape.half[1]))


def naive_check(validator: Validator, container: ContainerSpec, ids: Sequence[int],
                poses: np.ndarray, targets: Iterable[int] | None = None,
                neighbour_check: bool = True) -> Report:
    """The reference: every part, every tilt, every other part, FCL for every decision (the
    placing surface a half-space in the part frame), no broadphase, no bounds, no caching;
    the gripper's frame built per tilt from its definition. Same results as
    `Validator.check`, far slower."""
    start = time.perf_counter()
    v = validator
    ids = [int(i) for i in ids]
    poses = check_poses(ids, poses)
    rows = _targets(ids, targets)
    rotations = quaternions_to_matrices(poses[:, 3:])
    positions = poses[:, :3]
    walls = [fcl.CollisionObject(fcl.Box(*(2 * np.array(h))), fcl.Transform(np.eye(3),
                                                                          np.array(c)))
             for h, c in containers.wall_boxes(container)]
    surface = fcl.CollisionObject(fcl.Halfspace(-v.place_axis, -v.seat_offset),
                                  fcl.Transform())
    queries = 0
    results = []
    for row in rows:
        rotation, position = rotations[row], positions[row]
        centre = position + rotation @ v.part.center
        if not containers.inside(container, centre, CENTRE_TOLERANCE,
                                 v.config.rim_tolerance)[0]:
            results.append(PartResult(ids[row], STAGE_OUTSIDE, 'outside'))
            continue
        # each grasp as the gripper takes it: on a round body, turned about its axis by the
        # angle from the up axis to world +Z, both seen across the axis
        turns, turned = [], []
        for g, a in zip(v.grasps, v.free_axes, strict=True):
            w = rotation.T @ np.array([0.0, 0.0, 1.0])
            u_across, w_across = g.up - (g.up @ a) * a, w - (w @ a) * a
            turn = math.atan2(float(a @ np.cross(u_across, w_across)),
                              float(u_across @ w_across)) if a.any() else 0.0
            turns.append(turn)
            turned.append(rotation @ Rotation.from_rotvec(turn * a).as_matrix())
        angles = [math.acos(max(-1.0, min(1.0, float((r @ g.up)[2]))))
                  for g, r in zip(v.grasps, turned, strict=True)]
        g = min((k for k in range(len(angles)) if angles[k] <= min(angles) + TIE),
                key=lambda k: (abs(turns[k]), k))
        grasp, gripped = v.grasps[g], turned[g]
        result = PartResult(ids[row], STAGE_CANDIDACY, '', g, angles[g],
                            jaw_opening=grasp.jaw_opening)
        results.append(result)
        if angles[g] > v.config.tolerance:
            result.grasp_index = -1
            continue
        shapes = gripper_shapes(v.gripper, grasp.jaw_opening, v.finger_depths[g])
        objects = [s.fcl_object() for s in shapes]
        closing = gripped @ grasp.closing
        # the vertical made perpendicular to the closing axis, turned by each tilt about it
        axis = np.array([0.0, 0.0, 1.0]) - closing[2] * closing
        if np.linalg.norm(axis) < 1e-9:
            axis = gripped @ grasp.up
        axis /= np.linalg.norm(axis)
        side = np.cross(axis, closing)
        frames = []
        for tilt in v.tilts:
            up = math.cos(tilt) * axis - math.sin(tilt) * side
            frames.append(np.column_stack([closing, np.cross(up, closing), up]))
        approach = [k for k, f in enumerate(frames)
                    if f[2, 2] >= math.cos(v.config.approach_cone) - 1e-12]
        if not approach:
            continue
        kept = []
        for k in approach:
            relative = rotation.T @ frames[k]
            clear = True
            for s, obj in zip(shapes, objects, strict=True):
                obj.setTransform(fcl.Transform(relative @ s.rotation,
                                               grasp.point + relative @ s.center))
                queries += 1
                clear &= not collide(obj, surface)
            if clear:
                kept.append(k)
        if not kept:
            result.stage = STAGE_PLACEABILITY
            continue

        def placed(k, s, frames=frames, position=position, rotation=rotation, grasp=grasp):
            origin = position + rotation @ grasp.point
            return fcl.Transform(frames[k] @ s.rotation, origin + frames[k] @ s.center)

        free = []
        for k in kept:
            hit = False
            for s, obj in zip(shapes, objects, strict=True):
                obj.setTransform(placed(k, s))
                for wall in walls:
                    queries += 1
                    hit |= collide(obj, wall)
            if not hit:
                free.append(k)
        if not free:
            result.stage = STAGE_CONTAINER
            continue
        if neighbour_check:
            clear_tilts = []
            for k in free:
                hit = False
                for s, obj in zip(shapes, objects, strict=True):
                    obj.setTransform(placed(k, s))
                    for j in range(len(ids)):
                        if j == row:
                            continue
                        for shape in v.part_shapes:
                            other = shape.fcl_object()
                            other.setTransform(fcl.Transform(rotations[j] @ shape.rotation,
                                                             positions[j] + rotations[j]
                                                             @ shape.center))
                            queries += 1
                            hit |= collide(obj, other)
                if not hit:
                    clear_tilts.append(k)
            free = clear_tilts
            if not free:
                result.stage = STAGE_NEIGHBOUR
                continue
        result.stage = STAGE_VALID
        result.valid_tilts = tuple(float(v.tilts[k]) for k in free)
    return Report(results, neighbour_check, queries, time.perf_counter() - start)
