"""A part model as the physics and the checks use it: a `PartGeometry`, the compound of
collision primitives (primitives.py) in the part frame plus a detailed visual mesh, built from a
`PartSpec` by `build_part`. Moving bodies never use a raw triangle mesh: a CAD file becomes
convex pieces (pieces.convex_cover).

Units: metres, kilograms. Quaternions are (x, y, z, w).
"""

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import trimesh

from ..errors import InvalidArgument
from .mass import mass_properties
from .meshes import load_mesh
from .models import builtin
from .pieces import convex_cover
from .primitives import Box, Cylinder, Hull, Primitive
from .spec import check_material, PartSpec


@dataclass(frozen=True, eq=False)
class PartGeometry:
    """A part model ready for simulation and collision checks.

    primitives: the collision compound in the part frame.
    visual: the detailed mesh in the part frame, for display and volume.
    dimensions: the model parameters used, metres (built-ins) or empty (meshes).
    center: the centre of the sphere that encloses the compound, (3,) m in the part frame:
    a built-in's bounding-box centre, a mesh's mass centre (where the file's frame is, or how
    it is turned, does not move it; spawning spaces parts by this sphere).
    radius: radius of a sphere about `center` that encloses the compound, m.
    volume: volume of the visual mesh (or of the hulls when it is not watertight), m^3.
    mass_frame: a mesh part's mass centre (3,) m and principal axes (4,) xyzw, in the part
    frame, from its geometry at uniform density (`mass.mass_properties`), wherever the file
    puts its origin: the physics' mass centre. None for a built-in model, whose frame origin
    (its body's centre) is the physics' mass centre, its leads and tab left out of it.
    moments: a mesh part's principal moments of inertia (3,) kg m^2 about those axes, from the
    same solids: the physics' inertia. None for a built-in model, whose moments are Bullet's
    estimate from the bounds of its shape in its frame. Bullet's estimate for a mesh part
    depended on the file's frame and tessellation (KiCad's 5 mm capacitor: 0.0016 to 0.0044
    kg mm^2 about its principal axes from its STEP, its STL and the STL turned, whose true
    moments are 0.0016 to 0.0018).
    collision_note: how a mesh part's pieces were made, in words (pieces.convex_cover); empty
    for a built-in model.
    """

    spec: PartSpec
    dimensions: Mapping[str, float]
    mass: float
    primitives: tuple[Primitive, ...]
    visual: trimesh.Trimesh
    center: np.ndarray
    radius: float
    volume: float
    mass_frame: tuple[np.ndarray, np.ndarray] | None = None
    moments: np.ndarray | None = None
    collision_note: str = ''

    @property
    def mass_centre(self) -> np.ndarray:
        """The physics' mass centre (3,), m in the part frame: a mesh part's from its solids
        (mass_frame), a built-in's at its frame origin. The one answer every check, proposal
        and sheet takes."""
        return np.zeros(3) if self.mass_frame is None else self.mass_frame[0]


MM = 1e-3       # m


def primitive_mesh(p: Primitive) -> trimesh.Trimesh:
    """The triangle mesh of a primitive, in the part frame."""
    if isinstance(p, Box):
        mesh = trimesh.creation.box(extents=2.0 * np.asarray(p.half))
    elif isinstance(p, Cylinder):
        mesh = trimesh.creation.cylinder(radius=p.radius, height=p.length, sections=24)
    else:
        mesh = trimesh.Trimesh(p.vertices, p.faces, process=False)
    transform = trimesh.transformations.quaternion_matrix(
        [p.orientation[3], *p.orientation[:3]])
    transform[:3, 3] = p.position
    mesh.apply_transform(transform)
    return mesh


def visual_mesh(p: Primitive) -> trimesh.Trimesh:
    """A built-in's visual piece: primitive_mesh's, but a cylinder made in mm and scaled,
    closed: in metres trimesh drops the end faces of a lead's cylinder (0.25 mm across) as
    degenerate triangles, and the lead is an open tube that a line along it never meets
    (the suction cup's seal casts such lines). The collision bounds keep primitive_mesh's."""
    if not isinstance(p, Cylinder):
        return primitive_mesh(p)
    mesh = trimesh.creation.cylinder(radius=p.radius / MM, height=p.length / MM, sections=24)
    mesh.apply_scale(MM)
    transform = trimesh.transformations.quaternion_matrix(
        [p.orientation[3], *p.orientation[:3]])
    transform[:3, 3] = p.position
    return mesh.apply_transform(transform)


def _finish(spec: PartSpec, dims: Mapping[str, float], mass: float,
            collision: list[Primitive], visual: trimesh.Trimesh,
            volume: float, mass_frame=None, moments=None,
            collision_note: str = '') -> PartGeometry:
    corners = np.vstack([primitive_mesh(p).bounds for p in collision])
    low, high = corners.min(axis=0), corners.max(axis=0)
    # a mesh's sphere about its mass centre: its bounding box would move with the file's axes
    # (KiCad's TO-220 turned in its file spawned in a coarser grid, and 13 % fewer were valid)
    center = (low + high) / 2 if mass_frame is None else np.asarray(mass_frame[0], dtype=float)
    points = np.vstack([primitive_mesh(p).vertices for p in collision])
    radius = float(np.linalg.norm(points - center, axis=1).max())
    return PartGeometry(spec=spec, dimensions=dict(dims), mass=mass,
                        primitives=tuple(collision), visual=visual, center=center,
                        radius=radius, volume=float(volume), mass_frame=mass_frame,
                        moments=moments, collision_note=collision_note)


def _builtin(spec: PartSpec) -> PartGeometry:
    dims, mass, collision, visual_parts = builtin(spec)
    visual = trimesh.util.concatenate([visual_mesh(p) for p in visual_parts])
    volume = float(sum(primitive_mesh(p).volume for p in visual_parts))
    return _finish(spec, dims, mass, collision, visual, volume)


def _mesh_part(spec: PartSpec) -> PartGeometry:
    mesh = load_mesh(spec.mesh_path, spec.scale)
    if spec.mass is None:
        raise InvalidArgument('part.mass', None, 'is required for a mesh part, kg')
    mass = check_material(spec, 0.0)
    hulls, note = convex_cover(mesh, spec.mesh_path)
    collision = [Hull(np.asarray(h.vertices, dtype=np.float64), np.asarray(h.faces, dtype=np.int64))
                 for h in hulls]
    volume = mesh.volume if mesh.is_watertight else sum(h.volume for h in hulls)
    # The mass where the material is: the solid itself when it is closed, else its hulls.
    solids = [mesh] if mesh.is_watertight and mesh.volume > 0 else hulls
    centre, axes, moments = mass_properties(solids, mass)
    return _finish(spec, {}, mass, collision, mesh, volume, (centre, axes), moments, note)


def build_part(spec: PartSpec) -> PartGeometry:
    """Check a part spec and build its geometry. Raises InvalidArgument or UnknownPart."""
    if spec.model == 'mesh':
        return _mesh_part(spec)
    return _builtin(spec)
