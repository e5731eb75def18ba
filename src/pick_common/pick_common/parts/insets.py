"""How a mesh part's convex pieces are inset so that the physics collides the part's surface:
Bullet collides a hull grown by its collision margin, and pybullet gives every hull of a
compound a fixed margin (below), so each hull is inset by it; a piece too thin for that stays
swollen by the rest (hull_swelling), which the part's account reports.

Pure: numpy, scipy and trimesh; no simulator (the world builds its shapes from inset_hull).
"""

import numpy as np
from scipy.optimize import linprog
from scipy.spatial import HalfspaceIntersection
import trimesh

from .geometry import PartGeometry
from .primitives import Hull

# Bullet collides a convex hull grown by its collision margin, and pybullet gives every hull
# of a compound 0.001 of its length unit (URDF and shape importers' fixed default;
# changeDynamics' collisionMargin sets only the compound's own, measured: a hull's bounds do
# not move). The world simulates in centimetres (ENGINE_UNIT; pick_sim_world's engine.py says
# why), where that margin is 0.01 mm; in metres it was 1 mm, a fifth of a 5 mm part. Each hull
# is inset by the margin, so that hull + margin is the part's surface again, its edges rounded
# by the margin; a piece thinner than twice the margin can be inset only by INSET_SHARE of the
# largest ball inside it and stays swollen by the rest (hull_swelling).
ENGINE_UNIT = 0.01              # m per length unit of the world's engine, by default
HULL_MARGIN = 1e-3 * ENGINE_UNIT    # m, pybullet's margin of a compound's convex hull
INSET_SHARE = 0.45              # of a piece's inner diameter: the most it is inset


def hull_inset(vertices: np.ndarray, faces: np.ndarray, margin: float = HULL_MARGIN) -> float:
    """How far a hull is inset, m: `margin`, or INSET_SHARE of the diameter of the largest
    ball inside it when that is less."""
    return _inset(vertices, faces, margin)[3]


def hull_swelling(part: PartGeometry, margin: float = HULL_MARGIN) -> float:
    """How far the physics' surface of a part lies outside its geometry at most, m, with hulls
    grown by `margin`: 0 when every hull is inset by the whole margin (and for boxes and
    cylinders, whose margins Bullet keeps inside their extents)."""
    return max((margin - hull_inset(p.vertices, p.faces, margin) for p in part.primitives
                if isinstance(p, Hull)), default=0.0)


def _planes(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The hull's face planes: unit outward normals (F, 3) and offsets (F,), n.x <= d inside;
    faces of no area left out."""
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    cross = mesh.triangles_cross
    area = np.linalg.norm(cross, axis=1)
    keep = area > 1e-12 * max(area.max(), 1e-300)
    normals = cross[keep] / area[keep, None]
    if mesh.volume < 0:          # faces wound inwards
        normals = -normals
    return normals, np.einsum('ij,ij->i', normals, mesh.triangles[keep, 0])


def _inset(vertices: np.ndarray, faces: np.ndarray, margin: float
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """The hull's face planes (normals, offsets: _planes), the centre of the largest ball
    inside it (its Chebyshev centre: a linear programme over the planes) and how far the hull
    is inset (hull_inset), from one pass over its faces."""
    normals, offsets = _planes(vertices, faces)
    # maximise r: n.c + r <= d for every face
    rows = np.column_stack([normals, np.ones(len(normals))])
    ball = linprog(c=[0.0, 0.0, 0.0, -1.0], A_ub=rows, b_ub=offsets,
                   bounds=[(None, None)] * 3 + [(0.0, None)], method='highs').x
    return normals, offsets, ball[:3], min(margin, INSET_SHARE * 2.0 * float(ball[3]))


def inset_hull(vertices: np.ndarray, faces: np.ndarray, margin: float = HULL_MARGIN
               ) -> np.ndarray:
    """The vertices of the convex hull whose faces lie hull_inset inside those of the hull
    (vertices (K, 3), triangles faces), so that Bullet's hull grown by `margin` is the hull
    (short of hull_swelling)."""
    normals, offsets, centre, margin = _inset(vertices, faces, margin)
    inside = HalfspaceIntersection(np.column_stack([normals, -(offsets - margin)]), centre)
    return inside.intersections
