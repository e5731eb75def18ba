"""The collision shapes a part is made of, in the part frame: a box, a cylinder (its axis along
its local z) or a convex hull, each placed by a position (3,) m and an orientation (4,) xyzw.
What the physics and the validity checks collide; a consumer tells them apart by type."""

from dataclasses import dataclass

import numpy as np

IDENTITY = (0.0, 0.0, 0.0, 1.0)
ORIGIN = (0.0, 0.0, 0.0)


@dataclass(frozen=True, eq=False)
class Box:
    """half: half extents along x, y, z, m."""
    half: tuple[float, float, float]
    position: tuple[float, float, float] = ORIGIN
    orientation: tuple[float, float, float, float] = IDENTITY


@dataclass(frozen=True, eq=False)
class Cylinder:
    """radius and length, m; the axis along the cylinder's local z, centred on its position."""
    radius: float
    length: float
    position: tuple[float, float, float] = ORIGIN
    orientation: tuple[float, float, float, float] = IDENTITY


@dataclass(frozen=True, eq=False)
class Hull:
    """A convex hull computed once: vertices (K, 3) float64 m and triangles faces (F, 3) int64,
    in its own frame."""
    vertices: np.ndarray
    faces: np.ndarray
    position: tuple[float, float, float] = ORIGIN
    orientation: tuple[float, float, float, float] = IDENTITY


Primitive = Box | Cylinder | Hull


def box(half, position=ORIGIN) -> Box:
    """A box of half extents `half` (3,) m at `position` (3,) m, as floats."""
    return Box(tuple(float(h) for h in half), tuple(float(p) for p in position))


def cylinder(radius: float, length: float, position=ORIGIN) -> Cylinder:
    """A cylinder along z at `position` (3,) m, as floats."""
    return Cylinder(float(radius), float(length), tuple(float(p) for p in position))
