"""Reading a part's CAD file (STL, OBJ, PLY, GLB, or STEP through cascadio) into one checked
triangle mesh in metres: the file's units (stated by STEP and glTF, given by the file's key
`units` or `mesh_scale` for the others), and the checks that catch a wrong unit or a broken
file before anything collides it."""

import os

import numpy as np
import trimesh

from ..errors import MeshError
from .spec import LIMITS, states_units, UNITS

MAX_MESH_FACES = 500_000
# How far across a mesh part may be, m: below half a millimetre or above 300 mm a file's units
# are wrong far more likely than the part is that small or large (a mm file read as metres is
# 1000 times too big, a metre file scaled as mm 1000 times too small).
MESH_EXTENT = (0.0005, 0.3)


def fitting_units(extent: float) -> list[str]:
    """The units (of UNITS) in which a mesh `extent` across, in the file's own numbers, is a
    part of sane size (MESH_EXTENT)."""
    return [u for u, s in UNITS.items() if MESH_EXTENT[0] <= extent * s <= MESH_EXTENT[1]]


def load_mesh(path: str, scale: float) -> trimesh.Trimesh:
    """Read a mesh file (STL, OBJ, PLY, GLB, or STEP through cascadio) and check it, in metres:
    scale applies to the file's numbers; a file that states its units (STEP, glTF) is read in
    metres and takes scale 1.

    Raises MeshError for a missing file, an unreadable or empty mesh, out-of-range face indices,
    non-finite vertices, a mesh with no volume, or one whose size is outside MESH_EXTENT (with
    the units that would fit).
    """
    scale = LIMITS['part.scale'].check('part.scale', scale)
    if not path:
        raise MeshError('part.mesh_path', path, 'is empty: a mesh part needs a file')
    if not os.path.isfile(path):
        raise MeshError('part.mesh_path', path, 'does not exist or is not a file')
    if states_units(path) and scale != 1.0:
        raise MeshError('part.scale', scale, f'must be 1 for {os.path.basename(path)}: the '
                        'file states its units, and it is read in metres')
    try:
        loaded = trimesh.load(path, force='mesh', process=False)
    except Exception as exc:  # trimesh raises many types for a bad file
        raise MeshError('part.mesh_path', path, f'could not be read as a mesh: {exc}') from None
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) == 0:
        raise MeshError('part.mesh_path', path, 'holds no triangles')
    if states_units(path) and loaded.units not in (None, 'm', 'meters'):
        loaded.convert_units('meters')
    vertices = np.asarray(loaded.vertices, dtype=np.float64)
    faces = np.asarray(loaded.faces)
    if len(faces) > MAX_MESH_FACES:
        raise MeshError('part.mesh_path', path,
                        f'has {len(faces)} faces (limit {MAX_MESH_FACES}): simplify it')
    if not np.isfinite(vertices).all():
        raise MeshError('part.mesh_path', path, 'has non-finite vertex coordinates')
    if faces.min() < 0 or faces.max() >= len(vertices):
        raise MeshError('part.mesh_path', path,
                        f'has face indices outside [0, {len(vertices) - 1}]')
    mesh = trimesh.Trimesh(vertices * scale, faces, process=True)
    if mesh.is_watertight and mesh.volume < 0:      # a closed mesh turned inside out
        mesh.invert()
    extent = float(mesh.extents.max()) if len(mesh.vertices) else 0.0
    if not MESH_EXTENT[0] <= extent <= MESH_EXTENT[1]:
        raw = extent / scale
        fits = fitting_units(raw)
        hint = ('no unit makes it a part of that size' if not fits or states_units(path) else
                ', '.join(f'in {u} (scale {UNITS[u]:g}) it is {raw * UNITS[u] * 1000:.4g} mm'
                          for u in fits))
        raise MeshError('part.mesh_path', path,
                        f'is {extent * 1000:g} mm across at scale {scale:g}; a part must be '
                        f'{MESH_EXTENT[0] * 1000:g} to {MESH_EXTENT[1] * 1000:g} mm across: '
                        f'{hint}')
    return mesh
