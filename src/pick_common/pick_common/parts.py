"""Part models: built-in parametric through-hole parts and user meshes.

A part model becomes a `PartGeometry`: a compound of collision primitives and convex hulls in the
part frame (what the physics and the validity checks collide) plus a detailed visual mesh.
Moving bodies never use a raw triangle mesh: a user mesh becomes convex pieces, a hull per
convex or open body and CoACD's pieces of a concave closed one (`pieces`).

Units: metres, kilograms. Quaternions are (x, y, z, w).
"""

from collections.abc import Mapping
from dataclasses import dataclass, field
import os

import numpy as np
import trimesh

from . import pieces
from .errors import check_int, check_number, InvalidArgument, Limit, MeshError, UnknownPart

# Largest part accepted: a sanity limit well above small parts, in metres.
MAX_PART_SIZE = 0.5
MIN_PART_SIZE = 1e-4
MAX_MESH_HULLS = 32
MAX_MESH_FACES = 500_000
# How far across a mesh part may be, m: below half a millimetre or above 300 mm a file's units
# are wrong far more likely than the part is that small or large (a mm file read as metres is
# 1000 times too big, a metre file scaled as mm 1000 times too small).
MESH_EXTENT = (0.0005, 0.3)
# Length units a mesh file may be in (the file's key `units`), in metres; and the formats that
# state their own units, which trimesh reads in metres (STEP through cascadio, glTF by its
# specification).
UNITS = {'mm': 1e-3, 'cm': 1e-2, 'm': 1.0, 'in': 0.0254}
STATED_UNITS = ('.step', '.stp', '.glb', '.gltf')
IDENTITY = (0.0, 0.0, 0.0, 1.0)
# The range of each material setting and the mesh scale, by field name (the world node's
# parameters of the same names state them).
LIMITS = {
    'part.mass': Limit(0.0, 10.0, low_open=True),                 # kg
    'part.lateral_friction': Limit(0.0, 10.0),                    # Coulomb coefficient
    'part.rolling_friction': Limit(0.0, 0.1),                     # m
    'part.spinning_friction': Limit(0.0, 0.1),                    # m
    'part.restitution': Limit(0.0, 1.0),
    'part.scale': Limit(0.0, 1e3, low_open=True),                 # mesh units to m
}


@dataclass(frozen=True)
class PartSpec:
    """What a user says about a part: a model name or a mesh, its size and material.

    dimensions: overrides of the built-in model's defaults, metres (see `BUILTIN_MODELS`).
    mass: kg; None takes the model's default. Friction: lateral is a Coulomb coefficient;
    rolling and spinning are resistance arms in metres (torque = arm * normal force).
    """

    model: str = 'radial_capacitor'
    dimensions: Mapping[str, float] = field(default_factory=dict)
    mass: float | None = None
    lateral_friction: float = 0.5
    rolling_friction: float = 0.0001
    spinning_friction: float = 0.0001
    restitution: float = 0.0
    mesh_path: str = ''
    scale: float = 1.0



def geometry_key(spec: PartSpec) -> tuple:
    """What a part's collision geometry depends on (not its mass or friction), hashable."""
    return spec.model, tuple(sorted(spec.dimensions.items())), spec.mesh_path, spec.scale


@dataclass(frozen=True, eq=False)
class Primitive:
    """One collision shape of a part, in the part frame.

    kind: 'box' (size = half extents x, y, z), 'cylinder' (size = radius, length; axis along
    its local z) or 'hull' (vertices (K, 3) float64 and triangles faces (F, 3) int64 of the
    convex hull, in its local frame, computed once; size unused).
    """

    kind: str
    size: tuple[float, ...]
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    orientation: tuple[float, float, float, float] = IDENTITY
    vertices: np.ndarray | None = None
    faces: np.ndarray | None = None


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
    frame, from its geometry at uniform density (`mass_properties`), wherever the file puts its
    origin: the physics' mass centre. None for a built-in model, whose frame origin (its
    body's centre) is the physics' mass centre, its leads and tab left out of it. The moments
    of inertia are Bullet's estimate from the shape's bounds in that frame, for every part:
    a thin part's true moments made the solver diverge (a 12 x 4 x 2 mm box at its solid
    moments, 8 times below Bullet's about its long axis, got NaN poses within 0.05 s at
    1/480 s; checked 2026-11-27).
    collision_note: how a mesh part's pieces were made, in words (`_convex_cover`); empty for a
    built-in model.
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
    collision_note: str = ''


# name -> (default dimensions in metres, default mass in kg, description)
BUILTIN_MODELS: dict[str, tuple[dict[str, float], float, str]] = {
    'radial_capacitor': ({
        'body_diameter': 0.005,
        'body_length': 0.011,
        'lead_diameter': 0.0005,
        'lead_length': 0.015,
        'lead_pitch': 0.002,
    }, 0.0004, 'cylindrical body along +Z, two leads along -Z spaced along X'),
    'to220': ({
        'body_width': 0.010,
        'body_thickness': 0.0045,
        'body_height': 0.009,
        'tab_height': 0.0065,
        'tab_thickness': 0.0013,
        'lead_width': 0.0008,
        'lead_thickness': 0.0005,
        'lead_length': 0.013,
        'lead_pitch': 0.00254,
    }, 0.002, 'body box, metal tab above it (+Z) at the back (-Y), three leads along -Z'),
    'dip': ({
        'body_length': 0.0094,
        'body_width': 0.00635,
        'body_height': 0.0033,
        'pins_per_row': 4.0,
        'pin_pitch': 0.00254,
        'row_spacing': 0.00762,
        'pin_length': 0.0035,
        'pin_width': 0.0005,
        'pin_thickness': 0.00025,
    }, 0.0005, 'body box, two rows of pins along -Z, rows spaced along Y, pins along X'),
}


def _box(half: tuple[float, float, float], position=(0.0, 0.0, 0.0)) -> Primitive:
    return Primitive('box', tuple(float(h) for h in half), tuple(float(p) for p in position))


def _cylinder(radius: float, length: float, position=(0.0, 0.0, 0.0)) -> Primitive:
    return Primitive('cylinder', (float(radius), float(length)),
                     tuple(float(p) for p in position))


def _primitive_mesh(p: Primitive) -> trimesh.Trimesh:
    """The triangle mesh of a primitive, in the part frame."""
    if p.kind == 'box':
        mesh = trimesh.creation.box(extents=2.0 * np.asarray(p.size))
    elif p.kind == 'cylinder':
        mesh = trimesh.creation.cylinder(radius=p.size[0], height=p.size[1], sections=24)
    else:
        mesh = trimesh.Trimesh(p.vertices, p.faces, process=False)
    transform = trimesh.transformations.quaternion_matrix(
        [p.orientation[3], *p.orientation[:3]])
    transform[:3, 3] = p.position
    mesh.apply_transform(transform)
    return mesh


def _radial_capacitor(d: Mapping[str, float]):
    body_r, body_l = d['body_diameter'] / 2, d['body_length']
    lead_r, lead_l, pitch = d['lead_diameter'] / 2, d['lead_length'], d['lead_pitch']
    if pitch / 2 + lead_r > body_r:
        raise InvalidArgument('part.dimensions.lead_pitch', pitch,
                              f'puts the leads outside the body (max {2 * (body_r - lead_r):g})')
    lead_z = -(body_l + lead_l) / 2
    visual = [_cylinder(body_r, body_l),
              _cylinder(lead_r, lead_l, (pitch / 2, 0, lead_z)),
              _cylinder(lead_r, lead_l, (-pitch / 2, 0, lead_z))]
    # The two leads collide as their convex hull (a thin plate): one shape instead of two,
    # and no thin gap for another part's lead to jitter in.
    collision = [visual[0], _box((pitch / 2 + lead_r, lead_r, lead_l / 2), (0, 0, lead_z))]
    return collision, visual


def _to220(d: Mapping[str, float]):
    w, t, h = d['body_width'], d['body_thickness'], d['body_height']
    tab_h, tab_t = d['tab_height'], d['tab_thickness']
    lw, lt, ll, pitch = d['lead_width'], d['lead_thickness'], d['lead_length'], d['lead_pitch']
    if tab_t > t:
        raise InvalidArgument('part.dimensions.tab_thickness', tab_t,
                              f'must be <= body_thickness {t:g}')
    if 2 * pitch + lw > w:
        raise InvalidArgument('part.dimensions.lead_pitch', pitch,
                              f'puts the leads outside the body (max {(w - lw) / 2:g})')
    body = _box((w / 2, t / 2, h / 2))
    tab = _box((w / 2, tab_t / 2, tab_h / 2), (0, -(t - tab_t) / 2, (h + tab_h) / 2))
    lead_z = -(h + ll) / 2
    leads = [_box((lw / 2, lt / 2, ll / 2), (k * pitch, 0, lead_z)) for k in (-1, 0, 1)]
    collision = [body, tab, _box((pitch + lw / 2, lt / 2, ll / 2), (0, 0, lead_z))]
    return collision, [body, tab, *leads]


def _dip(d: Mapping[str, float]):
    n = check_int('part.dimensions.pins_per_row', d['pins_per_row'], low=1, high=64)
    bl, bw, bh = d['body_length'], d['body_width'], d['body_height']
    pitch, rows, pl = d['pin_pitch'], d['row_spacing'], d['pin_length']
    pw, pt = d['pin_width'], d['pin_thickness']
    span = (n - 1) * pitch + pw
    if span > bl:
        raise InvalidArgument('part.dimensions.pin_pitch', pitch,
                              f'with {n} pins per row needs body_length >= {span:g}')
    if not pt < rows <= 3 * bw:
        raise InvalidArgument('part.dimensions.row_spacing', rows,
                              f'must be within ({pt:g}, {3 * bw:g}]: above pin_thickness, '
                              'at most 3 * body_width')
    body = _box((bl / 2, bw / 2, bh / 2))
    pin_z = -(bh + pl) / 2
    pins = [_box((pw / 2, pt / 2, pl / 2), (-(n - 1) * pitch / 2 + k * pitch, s * rows / 2, pin_z))
            for s in (-1, 1) for k in range(n)]
    collision = [body] + [_box((span / 2, pt / 2, pl / 2), (0, s * rows / 2, pin_z))
                          for s in (-1, 1)]
    return collision, [body, *pins]


_BUILDERS = {'radial_capacitor': _radial_capacitor, 'to220': _to220, 'dip': _dip}


def _check_material(spec: PartSpec, default_mass: float) -> float:
    for name in ('lateral_friction', 'rolling_friction', 'spinning_friction', 'restitution'):
        LIMITS[f'part.{name}'].check(f'part.{name}', getattr(spec, name))
    if spec.mass is None:
        return default_mass
    return LIMITS['part.mass'].check('part.mass', spec.mass)


def mass_properties(solids: list[trimesh.Trimesh], mass: float
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mass centre (3,), principal axes (4,) xyzw and principal moments (3,) kg m^2 of `mass`
    spread uniformly over `solids` (watertight meshes, in one frame; where they overlap the
    overlap counts twice)."""
    volumes = np.array([m.volume for m in solids])
    centres = np.array([m.center_mass for m in solids])
    centre = (volumes[:, None] * centres).sum(axis=0) / volumes.sum()
    tensor = np.zeros((3, 3))
    for m, v, c in zip(solids, volumes, centres, strict=True):
        d = c - centre          # trimesh's moment_inertia: about the solid's own centre, density 1
        tensor += np.asarray(m.moment_inertia) + v * ((d @ d) * np.eye(3) - np.outer(d, d))
    tensor *= mass / volumes.sum()
    moments, axes = np.linalg.eigh(tensor)
    if np.linalg.det(axes) < 0:
        axes[:, 2] = -axes[:, 2]
    w, x, y, z = trimesh.transformations.quaternion_from_matrix(
        np.vstack([np.hstack([axes, np.zeros((3, 1))]), [0.0, 0.0, 0.0, 1.0]]))
    return centre, np.array([x, y, z, w]), np.maximum(moments, 0.0)


def _finish(spec: PartSpec, dims: Mapping[str, float], mass: float,
            collision: list[Primitive], visual: trimesh.Trimesh,
            volume: float, mass_frame=None, collision_note: str = '') -> PartGeometry:
    corners = np.vstack([_primitive_mesh(p).bounds for p in collision])
    low, high = corners.min(axis=0), corners.max(axis=0)
    # a mesh's sphere about its mass centre: its bounding box would move with the file's axes
    # (KiCad's TO-220 turned in its file spawned in a coarser grid, and 13 % fewer were valid)
    center = (low + high) / 2 if mass_frame is None else np.asarray(mass_frame[0], dtype=float)
    points = np.vstack([_primitive_mesh(p).vertices for p in collision])
    radius = float(np.linalg.norm(points - center, axis=1).max())
    return PartGeometry(spec=spec, dimensions=dict(dims), mass=mass,
                        primitives=tuple(collision), visual=visual, center=center,
                        radius=radius, volume=float(volume), mass_frame=mass_frame,
                        collision_note=collision_note)


def _builtin(spec: PartSpec) -> PartGeometry:
    defaults, default_mass, _ = BUILTIN_MODELS[spec.model]
    unknown = sorted(set(spec.dimensions) - set(defaults))
    if unknown:
        raise InvalidArgument(f'part.dimensions.{unknown[0]}', spec.dimensions[unknown[0]],
                              f'is not a dimension of {spec.model} '
                              f'(known: {", ".join(sorted(defaults))})')
    dims = {}
    for name, default in defaults.items():
        value = spec.dimensions.get(name, default)
        if name == 'pins_per_row':
            dims[name] = float(check_int(f'part.dimensions.{name}', value, low=1, high=64))
        else:
            dims[name] = check_number(f'part.dimensions.{name}', value, low=MIN_PART_SIZE,
                                      high=MAX_PART_SIZE)
    mass = _check_material(spec, default_mass)
    collision, visual_parts = _BUILDERS[spec.model](dims)
    visual = trimesh.util.concatenate([_primitive_mesh(p) for p in visual_parts])
    volume = float(sum(_primitive_mesh(p).volume for p in visual_parts))
    return _finish(spec, dims, mass, collision, visual, volume)


def states_units(path: str) -> bool:
    """Whether a mesh file states its own length units (STEP, glTF): read in metres, its scale
    is 1."""
    return os.path.splitext(path)[1].lower() in STATED_UNITS


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


def _hull(points: np.ndarray) -> trimesh.Trimesh | None:
    try:
        hull = trimesh.convex.convex_hull(points)
    except Exception:  # qhull fails on flat or collinear input
        return None
    return hull if hull.volume > 0 else None


def _convex_cover(mesh: trimesh.Trimesh, path: str) -> tuple[list[trimesh.Trimesh], str]:
    """The convex pieces a mesh collides as, and how they were made, in words.

    Each connected body: closed and convex (`pieces.is_convex`), its hull; closed and concave,
    CoACD's pieces (`pieces.convex_pieces`); open, its hull (an open body has no inside to cut,
    so its concavities stay filled: said in the words). More than MAX_MESH_HULLS pieces in all,
    or more than MAX_MESH_HULLS bodies: the hull of the whole mesh, said too.
    """
    bodies = mesh.split(only_watertight=False)
    if len(bodies) > MAX_MESH_HULLS:
        whole = _hull(mesh.vertices)
        if whole is None:
            raise MeshError('part.mesh_path', path, 'has zero volume (flat or a line)')
        return [whole], (f'one convex hull of the whole mesh: it has {len(bodies)} separate '
                         f'bodies, more than {MAX_MESH_HULLS}')
    hulls, counts, failed = [], {'convex': 0, 'concave': 0, 'open': 0}, ''
    for body in bodies:
        closed = body.is_watertight and body.volume > 0
        if closed and not pieces.is_convex(body):
            try:
                cut = [h for h in (_hull(p) for p in pieces.convex_pieces(body))
                       if h is not None]
            except Exception as exc:    # CoACD's C++ raises what it raises: keep the hull
                cut, failed = [], f'; CoACD could not cut a body ({exc}): it is its hull'
            if cut:
                hulls += cut
                counts['concave'] += 1
                continue
        hull = _hull(body.vertices)
        if hull is not None:
            hulls.append(hull)
            counts['convex' if closed else 'open'] += 1
    if not hulls:
        hull = _hull(mesh.vertices)
        if hull is None:
            raise MeshError('part.mesh_path', path, 'has zero volume (flat or a line)')
        return [hull], 'one convex hull of the whole mesh: no body of it has volume'
    if len(hulls) > MAX_MESH_HULLS:
        return [_hull(mesh.vertices)], (f'one convex hull of the whole mesh: its pieces number '
                                        f'{len(hulls)}, more than {MAX_MESH_HULLS}')
    words = []
    if counts['concave']:
        words.append(f'{counts["concave"]} concave closed body(ies) cut into convex pieces by '
                     f'CoACD (concavity threshold {pieces.THRESHOLD:g})')
    if counts['convex']:
        words.append(f'{counts["convex"]} convex closed body(ies) as its hull')
    if counts['open']:
        words.append(f'{counts["open"]} open body(ies) as its hull (not closed, so not cut: '
                     'its hollows and gaps collide as filled; close the mesh to have it cut)')
    return hulls, '; '.join(words) + failed


def _mesh_part(spec: PartSpec) -> PartGeometry:
    mesh = load_mesh(spec.mesh_path, spec.scale)
    if spec.mass is None:
        raise InvalidArgument('part.mass', None, 'is required for a mesh part, kg')
    mass = _check_material(spec, 0.0)
    hulls, note = _convex_cover(mesh, spec.mesh_path)
    collision = [Primitive('hull', (), vertices=np.asarray(h.vertices, dtype=np.float64),
                           faces=np.asarray(h.faces, dtype=np.int64)) for h in hulls]
    volume = mesh.volume if mesh.is_watertight else sum(h.volume for h in hulls)
    # The mass where the material is: the solid itself when it is closed, else its hulls.
    solids = [mesh] if mesh.is_watertight and mesh.volume > 0 else hulls
    centre, axes, _ = mass_properties(solids, mass)
    return _finish(spec, {}, mass, collision, mesh, volume, (centre, axes), note)


def build_part(spec: PartSpec) -> PartGeometry:
    """Check a part spec and build its geometry. Raises InvalidArgument or UnknownPart."""
    if spec.model == 'mesh':
        return _mesh_part(spec)
    if spec.model not in BUILTIN_MODELS:
        raise UnknownPart(f'part.model: {spec.model!r} is not a part model '
                          f'(known: {", ".join(sorted(BUILTIN_MODELS))}, mesh)')
    return _builtin(spec)
