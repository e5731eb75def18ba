"""The container and neighbour stages of a check (3 and 4), over every (part, tilt) pair that
placeability left open: exact bounds decide what they can, FCL the rest (a k-d tree of the
parts' bounding spheres is the neighbours' broadphase). Each stage returns which pairs its
gripper hit; `validity.Validator.check` decides what that means for a part (its stage and
reason) and drops the pairs hit before the next stage.
"""

from collections.abc import Sequence
import itertools
import math

import fcl
import numpy as np
from pick_common import containers
from pick_common.containers import ContainerSpec
from scipy.spatial import cKDTree

from .check_geometry import CheckGeometry
from .geometry import bounds, BoxShape, collide, HullShape, place, Shape


class Pairs:
    """Every (part, tilt) pair still open after placeability: its part's row (`row`), tilt
    (`k`) and grasp (`g`), with the gripper's shapes placed in the container frame and their
    exact bounds."""

    def __init__(self, geometry: CheckGeometry, kept: dict[int, np.ndarray],
                 grasp_of: dict[int, int], frames: dict[int, np.ndarray],
                 rotations: np.ndarray, positions: np.ndarray) -> None:
        """kept: row -> (T,) bool, the tilts open; grasp_of: row -> its grasp; frames: row ->
        (T, 3, 3) the gripper's rotations; rotations (n, 3, 3), positions (n, 3): the parts'."""
        self.geometry = geometry
        rows, ks = [], []
        for row, mask in kept.items():
            k = np.flatnonzero(mask)
            rows.append(np.full(len(k), row))
            ks.append(k)
        self.row = np.concatenate(rows) if rows else np.zeros(0, dtype=int)
        self.k = np.concatenate(ks) if ks else np.zeros(0, dtype=int)
        self.g = np.array([grasp_of[r] for r in self.row], dtype=int)
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
            origin = positions[self.row[sel]] + r @ geometry.grasps[g].point
            self.grasp_point[sel] = origin
            for s, shape in enumerate(geometry.gripper_shapes[g]):
                rot, center = place(shape, frame, origin)
                self.rot[sel, s], self.center[sel, s] = rot, center
                self.lo[sel, s], self.hi[sel, s] = bounds(shape, rot, center)

    def __len__(self) -> int:
        return len(self.row)

    def _object(self, q: int, s: int) -> fcl.CollisionObject:
        obj = self.geometry.gripper_objects[self.g[q]][s]
        obj.setTransform(fcl.Transform(self.rot[q, s], self.center[q, s]))
        return obj

    def drop(self, hit: np.ndarray) -> None:
        """Leave out the pairs `hit` (a stage's answer, over the pairs as they are)."""
        keep = ~hit
        for name in ('row', 'k', 'g', 'rot', 'center', 'lo', 'hi', 'grasp_point'):
            setattr(self, name, getattr(self, name)[keep])

    def container(self, container: ContainerSpec) -> tuple[np.ndarray, int]:
        """Stage 3: (which pairs' gripper hits the container's walls or floor (len(self),)
        bool, the FCL queries issued). A convex shape and an axis-aligned wall box: apart when
        their bounds are; certainly touching when the shape's bounds lie within the box's on
        two axes (its projection on the third overlaps, so some point of it is inside). FCL
        decides the rest."""
        queries = 0
        hit = np.zeros(len(self), dtype=bool)
        for half, center in containers.wall_boxes(container):
            wc, wh = np.array(center), np.array(half)
            wall = fcl.CollisionObject(fcl.Box(*(2 * wh)), fcl.Transform(np.eye(3), wc))
            for s in range(self.lo.shape[1]):
                lo, hi = self.lo[:, s], self.hi[:, s]
                apart = ((lo > wc + wh) | (hi < wc - wh)).any(axis=1)
                inside = ((lo >= wc - wh) & (hi <= wc + wh)).sum(axis=1) >= 2
                hit |= ~apart & inside
                for q in np.flatnonzero(~apart & ~inside & ~hit):
                    queries += 1
                    hit[q] = collide(self._object(q, s), wall)
        return hit, queries

    def neighbours(self, ids: Sequence[int], rotations: np.ndarray, positions: np.ndarray
                   ) -> tuple[np.ndarray, dict[int, set[int]], int]:
        """Stage 4: (which pairs' gripper hits another part (len(self),) bool, the ids of the
        parts hit per row, the FCL queries issued). Broadphase: a k-d tree over the parts'
        bounding spheres, queried at once with the bounding sphere of every gripper shape at
        every pair; then exact bounds; FCL decides the pairs that overlap, and a pair stops at
        its first hit."""
        v = self.geometry
        stopped = np.zeros(len(self), dtype=bool)
        if not len(self.row):
            return stopped, {}, 0
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
                    stopped[q] = True
                    hits.setdefault(int(self.row[q]), set()).add(ids[j])
                    break
        return stopped, hits, queries


def _radius(shape: Shape) -> float:
    """Radius of a sphere about the shape's center that encloses it, m."""
    if isinstance(shape, HullShape):
        return float(np.linalg.norm(shape.vertices, axis=1).max())
    if isinstance(shape, BoxShape):
        return float(np.linalg.norm(shape.half))
    return float(math.hypot(shape.radius, shape.half_length))
