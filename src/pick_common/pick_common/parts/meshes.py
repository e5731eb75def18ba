"""Reading a part's CAD file (STL, OBJ, PLY, GLB, or STEP through cascadio) into one checked
triangle mesh in metres: the file's units (stated by STEP and glTF, given by the file's key
`units` or `mesh_scale` for the others), and the checks that catch a wrong unit or a broken
file before anything collides it."""

from collections.abc import Callable
import os
import re
import sys
import tempfile
from typing import Any

import numpy as np
import trimesh

from ..errors import MeshError
from .spec import LIMITS, states_units, UNITS

MAX_MESH_FACES = 500_000
# How far across a mesh part may be, m: below half a millimetre or above 300 mm a file's units
# are wrong far more likely than the part is that small or large (a mm file read as metres is
# 1000 times too big, a metre file scaled as mm 1000 times too small).
MESH_EXTENT = (0.0005, 0.3)
STEP_SUFFIXES = ('.step', '.stp')


def fitting_units(extent: float) -> list[str]:
    """The units (of UNITS) in which a mesh `extent` across, in the file's own numbers, is a
    part of sane size (MESH_EXTENT)."""
    return [u for u, s in UNITS.items() if MESH_EXTENT[0] <= extent * s <= MESH_EXTENT[1]]


def _read(path: str) -> trimesh.Geometry:
    """The file as trimesh reads it; MeshError naming what is wrong with it. A STEP file is
    converted by OpenCASCADE (cascadio), which prints its own errors on the process's standard
    streams and leaves trimesh to open a converted file that is not there: its output is kept
    off the terminal, and its first complaint is given in our error."""
    if not path.lower().endswith(STEP_SUFFIXES):
        try:
            return trimesh.load(path, force='mesh', process=False)
        except Exception as exc:  # trimesh raises many types for a bad file
            raise MeshError('part.mesh_path', path,
                            f'could not be read as a mesh: {exc}') from None
    with open(path, 'rb') as f:
        head = f.read(64)
    if not head.lstrip().startswith(b'ISO-10303-21'):
        raise MeshError('part.mesh_path', path, 'is not a STEP file: it does not begin with '
                        f'ISO-10303-21; (it begins {head[:20]!r})')
    loaded, failed, said = quietly(lambda: trimesh.load(path, force='mesh', process=False))
    if failed is None:
        return loaded
    plain = re.sub(r'\x1b\[[0-9;]*m', '', said)          # the terminal's colours
    complaint = next((line.strip(' *') for line in plain.splitlines()
                      if 'ERR' in line or 'Line' in line), '').strip()
    raise MeshError('part.mesh_path', path, 'is not a readable STEP file'
                    + (f': OpenCASCADE says {complaint!r}' if complaint else
                       ' (OpenCASCADE could not convert it)')
                    + '; is it whole (a truncated or partly written file)?')


def quietly(read: Callable[[], Any]) -> tuple[Any, Exception | None, str]:
    """read() with the whole process's standard output and error (C libraries' included) kept
    in a temporary file: (its result or None, the exception it raised or None, what was
    written)."""
    sys.stdout.flush()
    sys.stderr.flush()
    result, failed = None, None
    with tempfile.TemporaryFile() as sink:
        saved = [os.dup(1), os.dup(2)]
        try:
            os.dup2(sink.fileno(), 1)
            os.dup2(sink.fileno(), 2)
            try:
                result = read()
            except Exception as exc:
                failed = exc
        finally:
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            for fd in saved:
                os.close(fd)
        sink.seek(0)
        return result, failed, sink.read().decode(errors='replace')


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
    loaded = _read(path)
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
