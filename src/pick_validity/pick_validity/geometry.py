"""Shapes for the checks: part primitives and the simplified gripper, their exact bounds, and
their FCL collision objects.

A `Shape` is a `BoxShape`, a `CylinderShape` (axis along its local z) or a `HullShape`, placed
in a parent frame; a consumer tells them apart by type. Its FCL geometry is built once and
shared; a query sets the object's transform.
Rotations are (..., 3, 3) float64 arrays whose columns are the child axes; quaternions xyzw.
"""

from dataclasses import dataclass
import math

import fcl
import numpy as np
from pick_common.parts.geometry import PartGeometry
from pick_common.parts.primitives import Box, Cylinder
from scipy.spatial import Delaunay
import trimesh


@dataclass(frozen=True, eq=False)
class Shape:
    """rotation (3, 3) and center (3,) in the parent frame, m; its FCL geometry."""

    rotation: np.ndarray
    center: np.ndarray
    geometry: fcl.CollisionGeometry

    def fcl_object(self) -> fcl.CollisionObject:
        """A new collision object on the shared geometry (one per query site, reused)."""
        return fcl.CollisionObject(self.geometry, fcl.Transform())


@dataclass(frozen=True, eq=False)
class BoxShape(Shape):
    half: np.ndarray            # half extents (3,), m


@dataclass(frozen=True, eq=False)
class CylinderShape(Shape):
    radius: float               # m
    half_length: float          # m, along the shape's z


@dataclass(frozen=True, eq=False)
class HullShape(Shape):
    vertices: np.ndarray        # (M, 3) in the shape frame, m


def quaternions_to_matrices(q: np.ndarray) -> np.ndarray:
    """(N, 4) xyzw unit quaternions to (N, 3, 3) rotation matrices."""
    x, y, z, w = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    m = np.empty((len(q), 3, 3))
    m[:, 0, 0] = 1 - 2 * (y * y + z * z)
    m[:, 0, 1] = 2 * (x * y - z * w)
    m[:, 0, 2] = 2 * (x * z + y * w)
    m[:, 1, 0] = 2 * (x * y + z * w)
    m[:, 1, 1] = 1 - 2 * (x * x + z * z)
    m[:, 1, 2] = 2 * (y * z - x * w)
    m[:, 2, 0] = 2 * (x * z - y * w)
    m[:, 2, 1] = 2 * (y * z + x * w)
    m[:, 2, 2] = 1 - 2 * (x * x + y * y)
    return m


def matrix_to_quaternion(m: np.ndarray) -> np.ndarray:
    """(3, 3) rotation matrix to an xyzw quaternion."""
    wxyz = trimesh.transformations.quaternion_from_matrix(m)
    return np.array([wxyz[1], wxyz[2], wxyz[3], wxyz[0]])


def rotations_about_x(angles: np.ndarray) -> np.ndarray:
    """(K,) angles, rad, to (K, 3, 3) rotations about x."""
    c, s = np.cos(angles), np.sin(angles)
    m = np.zeros((len(angles), 3, 3))
    m[:, 0, 0] = 1.0
    m[:, 1, 1], m[:, 1, 2] = c, -s
    m[:, 2, 1], m[:, 2, 2] = s, c
    return m


def turn_onto(vector: np.ndarray, target: np.ndarray) -> np.ndarray:
    """The shortest rotation (3, 3) taking unit `vector` to unit `target`."""
    v, t = vector / np.linalg.norm(vector), target / np.linalg.norm(target)
    axis, c = np.cross(v, t), float(v @ t)
    if np.linalg.norm(axis) < 1e-9:
        if c > 0:
            return np.eye(3)
        other = np.array([1.0, 0, 0]) if abs(v[0]) < 0.9 else np.array([0, 1.0, 0])
        axis = np.cross(v, other)
    axis /= np.linalg.norm(axis)
    angle = np.arctan2(np.linalg.norm(np.cross(v, t)), c)
    return trimesh.transformations.rotation_matrix(angle, axis)[:3, :3]


def _convex(vertices: np.ndarray, faces: np.ndarray) -> fcl.Convex:
    """FCL's convex shape from a hull's vertices (M, 3) and triangles (F, 3)."""
    polygons = np.hstack([np.full((len(faces), 1), 3), faces]).ravel()
    return fcl.Convex(vertices, len(faces), polygons)


def part_shapes(part: PartGeometry) -> tuple[Shape, ...]:
    """The part's collision primitives as shapes in the part frame."""
    shapes = []
    for p in part.primitives:
        rotation = quaternions_to_matrices(np.array([p.orientation]))[0]
        center = np.array(p.position, dtype=np.float64)
        if isinstance(p, Box):
            half = np.array(p.half, dtype=np.float64)
            shapes.append(BoxShape(rotation, center, fcl.Box(*(2 * half)), half))
        elif isinstance(p, Cylinder):
            shapes.append(CylinderShape(rotation, center, fcl.Cylinder(p.radius, p.length),
                                        p.radius, p.length / 2))
        else:
            shapes.append(HullShape(rotation, center, _convex(p.vertices, p.faces),
                                    p.vertices))
    return tuple(shapes)


def contains(shape: Shape, point: np.ndarray) -> bool:
    """Is the point (3,), in the parent frame, inside or on the shape?"""
    local = shape.rotation.T @ (np.asarray(point, dtype=np.float64) - shape.center)
    if isinstance(shape, BoxShape):
        return bool((np.abs(local) <= shape.half + 1e-12).all())
    if isinstance(shape, CylinderShape):
        return bool(math.hypot(local[0], local[1]) <= shape.radius + 1e-12
                    and abs(local[2]) <= shape.half_length + 1e-12)
    return bool(Delaunay(shape.vertices).find_simplex(local) >= 0)


def place(shape: Shape, rotation: np.ndarray, translation: np.ndarray) -> tuple[np.ndarray,
                                                                               np.ndarray]:
    """The shape's rotation (N, 3, 3) and center (N, 3) in a frame where its parent frame has
    rotation (N, 3, 3) and translation (N, 3)."""
    return rotation @ shape.rotation, translation + rotation @ shape.center


def half_extents(shape: Shape, rotation: np.ndarray) -> np.ndarray:
    """Exact half extents (N, 3) of a box's or cylinder's axis-aligned bounds about its center,
    for rotations (N, 3, 3). Hulls: see `bounds`."""
    if isinstance(shape, BoxShape):
        return np.abs(rotation) @ shape.half
    radius, half_length = shape.radius, shape.half_length
    w = rotation[:, :, 2]
    return np.abs(w) * half_length + radius * np.sqrt(np.clip(1.0 - w * w, 0.0, 1.0))


def bounds(shape: Shape, rotation: np.ndarray, center: np.ndarray) -> tuple[np.ndarray,
                                                                           np.ndarray]:
    """Exact axis-aligned bounds (low (N, 3), high (N, 3)) of the shape at rotation and center
    (its own pose, as from `place`)."""
    if isinstance(shape, HullShape):
        points = np.einsum('nij,mj->nmi', rotation, shape.vertices) + center[:, None, :]
        return points.min(axis=1), points.max(axis=1)
    half = half_extents(shape, rotation)
    return center - half, center + half


def support(shape: Shape, rotation: np.ndarray, center: np.ndarray,
            direction: np.ndarray) -> np.ndarray:
    """max over the shape of direction . x, (N,), for unit direction (3,)."""
    local = np.einsum('nji,j->ni', rotation, direction)   # direction in the shape frame
    if isinstance(shape, HullShape):
        return (shape.vertices @ local.T).max(axis=0) + center @ direction
    if isinstance(shape, BoxShape):
        return center @ direction + np.abs(local) @ shape.half
    radius, half_length = shape.radius, shape.half_length
    along = local[:, 2]
    return (center @ direction + np.abs(along) * half_length
            + radius * np.sqrt(np.clip(1.0 - along * along, 0.0, 1.0)))


_REQUEST = fcl.CollisionRequest()   # yes/no only: one contact, no contact details


def collide(a: fcl.CollisionObject, b: fcl.CollisionObject) -> bool:
    """One FCL narrowphase query: do the two objects, at their transforms, intersect?"""
    return fcl.collide(a, b, _REQUEST, fcl.CollisionResult()) > 0
