"""The container and neighbour stages of a check (3 and 4), over every (part, tilt) pair that
placeability left open: exact bounds decide what they can, FCL the rest (a k-d tree of the
parts' bounding spheres is the neighbours' broadphase). Used by `validity.Validator.check`.
"""

from collections.abc import Sequence
import itertools
import math
from typing import TYPE_CHECKING

import fcl
import numpy as np
from pick_common import containers
from pick_common.containers import ContainerSpec
from scipy.spatial import cKDTree

from .geometry import bounds, collide, place, Shape
from .results import PartResult, STAGE_CANDIDACY, STAGE_CONTAINER, STAGE_NEIGHBOUR

if TYPE_CHECKING:
    from .validity import Validator


class Pairs:
    """Every (part, tilt) pair still open after placeability, with the gripper's shapes placed
    in the container frame, their exact bounds, and the masks of `kept` to update."""

    def __init__(self, v: 'Validator', kept: dict[int, np.ndarray],
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
        obj = self.v.gripper_objects[self.g[q]][s]
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
