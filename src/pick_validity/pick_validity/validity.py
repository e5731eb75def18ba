"""The staged validity check (paper section 4.1, figure 3), with python-fcl.

Per part, in order, stopping at the first stage that fails:
1. candidacy: a grasp pose's up axis within `tolerance` of world +Z (the nearest is chosen);
2. placeability: tilts of the wrist about the closing axis at which the gripper, rigidly holding
   the part in its place orientation, stays clear of the placing surface;
3. container: of those, tilts at which the gripper clears the container's walls and floor;
4. neighbours: of those, tilts at which the gripper clears every other part (skipped for the
   static bin analysis). A part with a tilt left is valid.

The gripper frame is fixed relative to the part for a grasp and tilt (origin at the grasp point,
z along the up axis, x along the closing axis, then rotated by the tilt about x), so placeability
depends on the grasp and tilt only: `Validator` computes it once. Container and neighbour stages
decide what exact bounds can decide and ask FCL the rest; `naive_check` asks FCL everything, with
no broadphase and no caching, and must give identical results.

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
    STAGE_VALID = range(6)
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
    """The results of one check, in the order of the targets, with counts per stage."""

    results: list[PartResult]
    neighbour_check: bool
    queries: int = 0            # FCL narrowphase queries issued
    wall_time: float = 0.0      # s
    counts: dict[str, int] = field(default_factory=dict)

    def __post_init__(self) -> None:
        stages = [r.stage for r in self.results]
        self.counts = {
            'checked': len(stages),
            'candidates': sum(s > STAGE_CANDIDACY for s in stages),
            'placeable': sum(s > STAGE_PLACEABILITY for s in stages),
            'container_free': sum(s > STAGE_CONTAINER for s in stages),
            'valid': sum(s == STAGE_VALID for s in stages)}


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

    Build once and reuse: part and gripper geometry and the placeability of every grasp and
    tilt are computed here, never per part.
    """

    def __init__(self, part: PartGeometry, gripper: Gripper, grasps: Sequence[GraspPose],
                 place_spec: PlaceSpec, config: CheckConfig | None = None) -> None:
        self.config = config or CheckConfig()
        self.part = part
        self.gripper = check_gripper(gripper)
        self.grasps = check_grasps(list(grasps))
        self.place_axis, self.seat_offset = check_place(place_spec)
        self.tilts = tilts(self.config)
        self.part_shapes = part_shapes(part)
        self.gripper_shapes = [gripper_shapes(self.gripper, g.jaw_opening) for g in self.grasps]
        self.frames = [self._frames(g) for g in self.grasps]
        self.placeable = [self._placeable(k) for k in range(len(self.grasps))]
        self._gripper_objects = [[s.fcl_object() for s in shapes]
                                 for shapes in self.gripper_shapes]

    def _frames(self, grasp: Grasp) -> np.ndarray:
        """Gripper rotations in the part frame, (T, 3, 3), one per tilt."""
        return grasp_basis(grasp) @ rotations_about_x(self.tilts)

    def _placeable(self, k: int) -> np.ndarray:
        """(T,) bool: the gripper stays on its side of the seating plane at each tilt."""
        rotations = self.frames[k]
        origin = np.broadcast_to(self.grasps[k].point, (len(self.tilts), 3))
        clear = np.ones(len(self.tilts), dtype=bool)
        for shape in self.gripper_shapes[k]:
            r, c = place(shape, rotations, origin)
            clear &= support(shape, r, c, self.place_axis) < self.seat_offset
        return clear

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

        # 1. candidacy, vectorised over targets and grasps.
        ups = np.stack([g.up for g in self.grasps])                     # (G, 3)
        z = np.einsum('njk,gk->ngj', rotations[rows], ups)[:, :, 2]     # (n, G)
        angles = np.arccos(np.clip(z, -1.0, 1.0))
        best = angles.argmin(axis=1)
        kept: dict[int, np.ndarray] = {}
        for n, row in enumerate(rows):
            g, angle = int(best[n]), float(angles[n, best[n]])
            result = PartResult(ids[row], STAGE_CANDIDACY, '', g, angle,
                                jaw_opening=self.grasps[g].jaw_opening)
            results[row] = result
            if angle > self.config.tolerance:
                result.grasp_index = -1
                result.reason = (f'no grasp pose within {_deg(self.config.tolerance)} of +Z: '
                                 f'the nearest, {self.grasps[g].name!r}, is at {_deg(angle)}')
                continue
            # 2. placeability: precomputed per grasp and tilt.
            if not self.placeable[g].any():
                result.stage = STAGE_PLACEABILITY
                result.reason = (f'grasp {self.grasps[g].name!r}: the gripper hits the placing '
                                 f'surface at every tilt')
                continue
            kept[row] = self.placeable[g].copy()

        # 3. container, 4. neighbours: vectorised over every (part, tilt) pair left.
        pairs = _Pairs(self, kept, results, rotations, positions)
        queries += pairs.container(container)
        if neighbour_check:
            queries += pairs.neighbours(ids, rotations, positions)
        for row, mask in kept.items():
            if mask.any():
                self._finish_valid(results[row], mask, rotations[row], positions[row])
        return Report([results[row] for row in rows], neighbour_check, queries,
                      time.perf_counter() - start)

    def _gripper_in_world(self, rotation, position, g, k_idx):
        """Gripper rotations (K, 3, 3) and origins (K, 3) in the container frame."""
        rot = rotation @ self.frames[g][k_idx]
        origin = np.broadcast_to(position + rotation @ self.grasps[g].point, (len(k_idx), 3))
        return rot, origin

    def _finish_valid(self, result: PartResult, mask: np.ndarray, rotation, position) -> None:
        g = result.grasp_index
        valid = np.flatnonzero(mask)
        result.stage = STAGE_VALID
        result.valid_tilts = tuple(float(self.tilts[k]) for k in valid)
        k = valid[np.abs(self.tilts[valid]).argmin()]
        rot, origin = self._gripper_in_world(rotation, position, g, np.array([k]))
        result.gripper_pose = np.concatenate([origin[0], matrix_to_quaternion(rot[0])])
        result.reason = (f'valid with grasp {self.grasps[g].name!r} at {len(valid)} of '
                         f'{len(self.tilts)} tilts')


class _Pairs:
    """Every (part, tilt) pair still open after placeability, with the gripper's shapes placed
    in the container frame, their exact bounds, and the masks of `kept` to update."""

    def __init__(self, v: Validator, kept: dict[int, np.ndarray],
                 results: dict[int, PartResult], rotations: np.ndarray,
                 positions: np.ndarray) -> None:
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
            frame = r @ v.frames[g][self.k[sel]]
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


def grasp_basis(grasp: Grasp) -> np.ndarray:
    """The gripper's rotation in the part frame at tilt 0: x along the closing axis, z along
    the up axis, (3, 3)."""
    return np.column_stack([grasp.closing, np.cross(grasp.up, grasp.closing), grasp.up])


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
    """The reference: every part, every tilt, every other part, FCL for every decision, no
    broadphase, no bounds, no caching. Same results as `Validator.check`, far slower."""
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
        angles = [math.acos(max(-1.0, min(1.0, float((rotations[row] @ g.up)[2]))))
                  for g in v.grasps]
        g = int(np.argmin(angles))
        result = PartResult(ids[row], STAGE_CANDIDACY, '', g, angles[g],
                            jaw_opening=v.grasps[g].jaw_opening)
        results.append(result)
        if angles[g] > v.config.tolerance:
            result.grasp_index = -1
            continue
        shapes = gripper_shapes(v.gripper, v.grasps[g].jaw_opening)
        objects = [s.fcl_object() for s in shapes]
        base = grasp_basis(v.grasps[g])
        kept = []
        for k, tilt in enumerate(v.tilts):
            frame = base @ rotations_about_x(np.array([tilt]))[0]
            clear = True
            for s, obj in zip(shapes, objects, strict=True):
                obj.setTransform(fcl.Transform(frame @ s.rotation,
                                               v.grasps[g].point + frame @ s.center))
                queries += 1
                clear &= not collide(obj, surface)
            if clear:
                kept.append(k)
        if not kept:
            result.stage = STAGE_PLACEABILITY
            continue

        def placed(k, s, row=row, base=base, g=g):
            frame = rotations[row] @ base @ rotations_about_x(np.array([v.tilts[k]]))[0]
            origin = positions[row] + rotations[row] @ v.grasps[g].point
            return fcl.Transform(frame @ s.rotation, origin + frame @ s.center)

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
