"""How a part comes to rest on a flat floor: its aspects, which aspect a resting pose shows,
the quasi-static prediction, and drop counts against a measurement.

An aspect is what a part can rest on, named from its geometry in the part's frame, not from
its tessellation: the same part from its STEP file and from STL exports of it at other
tessellations has the same aspects by the same names (but for faces of a few tenths of a
percent quasi-static share that a tessellation makes or unmakes: the facets of a chamfer,
the face a lead's tip and a rim span; KiCad's 5 mm capacitor, test_part_files.py). The part
rests on a face of its convex hull onto which its mass centre projects
(trimesh.poses.compute_stable_poses, which also gives each face's quasi-static share: the
solid angle of the directions of gravity that roll the part onto it without momentum). Those
faces are grouped:
- a round side: faces whose normals lie within MERGE_ANGLE of one circle of directions about
  an axis, at least ROUND_FACES directions (MERGE_ANGLE apart) in an arc with no gap wider
  than ROUND_GAP that spans at least ROUND_SPAN: a tessellated cylinder's side (its normals
  square to its axis) or a cone's (a chamfer's, a tapered body's), which a user counts as
  one. Found from the faces themselves, about any axis; a cylinder's named `side_x`, `side_y`
  or `side_z` when its axis lies within MERGE_ANGLE of a frame axis, a cone's `cone_+x` ...
  `cone_-z` by the way its normals lean, else `side_1`, `cone_1` ... by falling share;
- a flat face: faces whose normals lie within MERGE_ANGLE of each other (a face tessellated
  into triangles), named `+x` ... `-z` when its normal lies within MERGE_ANGLE of an axis,
  else `face_1`, `face_2` ... by falling share in steps of SHARE_STEP, within a step by the
  normal (+x first, then +y, +z, in steps of 0.1): a mirror pair's two shares differ with
  the tessellation in their fourth decimal.
A resting pose shows the aspect gravity points through in the part's frame: a round side's
when gravity lies within MATCH_ANGLE of its circle (a cylinder rests on its side at any roll,
between its facets' normals), a flat face's when within MATCH_ANGLE of its normal; OTHER
otherwise (leaning, on an edge).

Pure: numpy, scipy and trimesh; no simulator.
"""

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
import math

import numpy as np
from scipy import stats
from scipy.spatial import ConvexHull, QhullError
import trimesh

from ..states import perpendicular, rotate
from .geometry import PartGeometry
from .spec import geometry_key

MERGE_ANGLE = math.radians(5.0)     # faces this close in normal are one aspect
MATCH_ANGLE = math.radians(10.0)    # a pose this far from every aspect is OTHER
ROUND_FACES = 8                     # the fewest facet directions around a round side
ROUND_GAP = math.radians(45.0)      # the widest gap between a round side's directions
ROUND_SPAN = math.radians(90.0)     # the least a round side's directions span around it
SHARE_STEP = 0.005                  # shares this close number aspects by their normals
OTHER = 'other'                     # a pose on no aspect (leaning, balanced on an edge)
AXES = {'+x': (1, 0, 0), '-x': (-1, 0, 0), '+y': (0, 1, 0), '-y': (0, -1, 0),
        '+z': (0, 0, 1), '-z': (0, 0, -1)}


@dataclass(frozen=True)
class Aspect:
    """name; normal: the unit outward normal (3,) of the face the part rests on, in the part
    frame (a round side's: its faces' mean, or its likeliest face's); normals: every face's of
    the aspect (K, 3); quasi_static: its share without momentum; axis: a round side's axis
    (3,), unit, in the part frame (None for a flat face), and level: the cosine of its
    normals' angle to the axis (0 for a cylinder's side)."""

    name: str
    normal: tuple[float, float, float]
    normals: np.ndarray
    quasi_static: float
    axis: tuple[float, float, float] | None = None
    level: float = 0.0


def _directions(normals: np.ndarray, shares: np.ndarray) -> list[list[int]]:
    """The faces grouped by normal: each group the faces within MERGE_ANGLE of its likeliest
    one, likeliest group first."""
    cos_merge = math.cos(MERGE_ANGLE)
    groups: list[list[int]] = []
    for i in sorted(range(len(normals)), key=lambda i: (-shares[i], *(-normals[i]).round(9))):
        for g in groups:
            if normals[g[0]] @ normals[i] > cos_merge:
                g.append(i)
                break
        else:
            groups.append([i])
    return groups


def _round_sides(normals: np.ndarray, groups: list[list[int]]
                 ) -> list[tuple[np.ndarray, float, list[int]]]:
    """The round sides among the face groups (module docstring): each (axis (3,), the cosine
    of its normals' angle to the axis: 0 for a cylinder, toward +axis for a cone; the indices
    of its groups), most groups first. A round side's normals lie on one circle of
    directions, the plane axis . n = cosine, which a direction and its two nearest fix."""
    heads = np.array([normals[g[0]] for g in groups])
    if len(heads) < ROUND_FACES:
        return []
    cos = np.clip(heads @ heads.T, -1.0, 1.0)
    near = (cos < math.cos(MERGE_ANGLE)) & (cos > math.cos(ROUND_GAP))
    sin_merge = math.sin(MERGE_ANGLE)
    candidates = []
    for k in range(len(heads)):
        others = np.flatnonzero(near[k])
        if len(others) < 2:
            continue
        a, b = others[np.argsort(-cos[k, others])[:2]]       # its two nearest directions
        axis = np.cross(heads[a] - heads[k], heads[b] - heads[k])
        if np.linalg.norm(axis) < 1e-12:
            continue
        axis /= np.linalg.norm(axis)
        level = float(axis @ heads[k])
        if abs(level) < sin_merge:           # a cylinder: one sign for the axis, any run
            level = 0.0
            axis = axis if axis @ [1.0, 2.0, 4.0] >= 0 else -axis
        elif level < 0:                       # a cone: its axis the way its normals lean
            axis, level = -axis, -level
        candidates.append((tuple(np.round(axis, 9)), round(level, 9)))
    candidates = sorted(set(candidates))

    def members_of(axis: np.ndarray, level: float, used: set[int]) -> list[int]:
        circle = [k for k in np.flatnonzero(np.abs(heads @ axis - level) < sin_merge)
                  if k not in used]
        return [circle[k] for arc in _arcs(heads[circle], axis) for k in arc]

    found, used = [], set()
    while True:        # the circle with the most faces first, then the next among the rest
        best = max(((np.array(a), lv, members_of(np.array(a), lv, used))
                    for a, lv in candidates), key=lambda c: len(c[2]), default=None)
        if best is None or len(best[2]) < ROUND_FACES:
            break
        axis, level, members = best
        # the circle refined: the plane through every member's direction (least squares)
        fit = np.linalg.svd(heads[members] - heads[members].mean(axis=0))[2][-1]
        fit = fit if fit @ axis >= 0 else -fit
        fitted = float(np.mean(heads[members] @ fit))
        if abs(fitted) < sin_merge:
            fitted, fit = 0.0, fit if fit @ [1.0, 2.0, 4.0] >= 0 else -fit
        again = members_of(fit, fitted, used)
        if len(again) >= len(members):
            axis, level, members = fit, fitted, again
        found.append((axis, level, members))
        used.update(members)
    return found


def _arcs(directions: np.ndarray, axis: np.ndarray) -> list[list[int]]:
    """The runs of `directions` (square to `axis`) around it with no gap wider than ROUND_GAP,
    at least ROUND_FACES directions each and spanning at least ROUND_SPAN, as indices into
    `directions`."""
    if len(directions) < ROUND_FACES:
        return []
    first = directions[0] - (directions[0] @ axis) * axis
    if np.linalg.norm(first) < 1e-9:
        return []
    first /= np.linalg.norm(first)
    second = np.cross(axis, first)
    angles = np.arctan2(directions @ second, directions @ first) % (2 * math.pi)
    order = np.argsort(angles)
    gaps = np.diff(np.append(angles[order], angles[order[0]] + 2 * math.pi))
    if (gaps <= ROUND_GAP).all():
        return [order.tolist()] if len(order) >= ROUND_FACES else []
    start = int(np.argmax(gaps > ROUND_GAP)) + 1        # just after a wide gap
    runs, run = [], []
    for k in range(len(order)):
        index = (start + k) % len(order)
        run.append(int(order[index]))
        if gaps[index] > ROUND_GAP:
            runs.append(run)
            run = []
    runs.append(run)

    def spans(run: list[int]) -> float:
        return float(np.sum(np.diff(np.unwrap(angles[run]))))

    return [r for r in runs if len(r) >= ROUND_FACES and spans(r) >= ROUND_SPAN]


def _axis_name(direction: np.ndarray, signed: bool) -> str | None:
    """'+x' ... '-z' (or 'x', 'y', 'z' unsigned) when `direction` lies within MERGE_ANGLE of a
    frame axis, else None."""
    for name, axis in AXES.items():
        cos = float(direction @ axis)
        if (cos if signed else abs(cos)) > math.cos(MERGE_ANGLE):
            return name if signed else name[1]
    return None


def stable_aspects(mesh: trimesh.Trimesh, centre: Sequence[float]) -> list[Aspect]:
    """The aspects of a part of `mesh` (its frame, m) with its mass centre at `centre` (3,),
    likeliest first (module docstring)."""
    transforms, shares = trimesh.poses.compute_stable_poses(
        mesh.convex_hull, center_mass=np.asarray(centre, dtype=float))
    normals = np.array([t[:3, :3].T @ [0.0, 0.0, -1.0] for t in transforms])
    shares = np.asarray(shares, dtype=float) / max(float(np.sum(shares)), 1e-300)
    groups = _directions(normals, shares)
    sides = _round_sides(normals, groups)
    in_sides = {k for _, _, members in sides for k in members}
    found = []          # (name or None, member faces, axis or None, level)
    taken = set()
    for axis, level, members in sides:
        faces = [i for k in members for i in groups[k]]
        name = (_axis_name(axis, False) if level == 0.0 else _axis_name(axis, True))
        name = name and (f'side_{name}' if level == 0.0 else f'cone_{name}')
        name = None if name in taken else name      # two about one axis: numbered
        taken.add(name)
        found.append((name, faces, axis, level))
    for k, g in enumerate(groups):
        if k not in in_sides:
            found.append((_axis_name(normals[g[0]], True), g, None, 0.0))
    aspects = []
    for name, faces, axis, level in found:
        best = faces[int(np.argmax(shares[faces]))]
        mean = normals[faces].mean(axis=0)
        normal = mean / np.linalg.norm(mean) if np.linalg.norm(mean) > 0.5 else normals[best]
        aspects.append(Aspect(name or '', tuple(float(v) for v in normal), normals[faces],
                              float(shares[faces].sum()),
                              None if axis is None else tuple(float(v) for v in axis), level))
    # unnamed ones numbered by falling share, a tie (a mirror pair) by the normal, +x first
    aspects.sort(key=lambda a: (-round(a.quasi_static / SHARE_STEP),
                                *(-np.array(a.normal)).round(1), -a.quasi_static))
    counts = {'side': 0, 'cone': 0, 'face': 0}
    for k, a in enumerate(aspects):
        if not a.name:
            kind = 'face' if a.axis is None else 'side' if a.level == 0.0 else 'cone'
            counts[kind] += 1
            aspects[k] = replace(a, name=f'{kind}_{counts[kind]}')
    return aspects


PLANE_TOLERANCE = 1e-7      # m: hull vertices this near a face's plane touch the floor


@dataclass(frozen=True)
class RestingFace:
    """The part resting on a flat surface on a face of its convex hull: `normal` the face's
    outward unit normal (it points down into the surface), `offset` the face's plane (normal .
    x = offset), `ratio` its stability margin d / h: d the distance from the projected mass
    centre to the face's support polygon's nearest edge, h the mass centre's height above
    the face, so the tilt (as a tangent) the part tips over at."""

    normal: np.ndarray
    offset: float
    ratio: float


def resting_faces(mesh: trimesh.Trimesh, centre: Sequence[float], margin: float = 0.0
                  ) -> tuple[RestingFace, ...]:
    """The faces of `mesh`'s convex hull (its frame, m) a part with its mass centre at
    `centre` rests on with a stability margin d / h of at least `margin`, steadiest first:
    the quasi-static rule of stable placements Wan and Harada's regrasp planners use. Beside
    stable_aspects (the same faces, grouped, with their quasi-static shares) for what needs
    each face's margin: the regrasp station's placements."""
    hull = mesh.convex_hull
    vertices = np.asarray(hull.vertices)
    centre = np.asarray(centre, dtype=float)
    found = []
    for n in np.unique(np.round(hull.face_normals, 6), axis=0):
        n = n / np.linalg.norm(n)
        offset = float((vertices @ n).max())
        height = offset - float(centre @ n)
        touching = vertices[vertices @ n >= offset - PLANE_TOLERANCE]
        if height <= 0 or len(touching) < 3:
            continue
        e1 = perpendicular(n)
        e2 = np.cross(n, e1)
        flat = np.column_stack([touching @ e1, touching @ e2])
        try:
            polygon = ConvexHull(flat)
        except QhullError:                  # the touching points lie on a line: an edge
            continue
        c = np.array([centre @ e1, centre @ e2])
        # Qhull's facet equations: a . p + b <= 0 inside; -(a . c + b) is c's distance inside
        distance = float(-(polygon.equations[:, :2] @ c + polygon.equations[:, 2]).max())
        ratio = distance / height
        if ratio >= margin:
            found.append(RestingFace(n, offset, ratio))
    return tuple(sorted(found, key=lambda p: -p.ratio))


_BY_GEOMETRY: dict[tuple, tuple[Aspect, ...]] = {}


def part_aspects(part: PartGeometry) -> tuple[Aspect, ...]:
    """A built part's aspects: stable_aspects of its visual mesh about its mass centre (a
    mesh's own, a built-in model's frame origin), computed once per geometry in a process
    (the file's loading, its check and the part's account ask for the same part's)."""
    key = geometry_key(part.spec)
    if key not in _BY_GEOMETRY:
        centre = part.mass_centre
        _BY_GEOMETRY[key] = tuple(stable_aspects(part.visual, centre))
    return _BY_GEOMETRY[key]



def classify(aspects: Sequence[Aspect], orientations: np.ndarray) -> list[str]:
    """The aspect each resting part shows, by the direction of gravity in its frame (the
    orientations (N, 4) xyzw of the part frame in a frame whose z is up): a round side's when
    gravity lies within MATCH_ANGLE of its circle of normals (for a cylinder, the plane square
    to its axis), a flat face's when within MATCH_ANGLE of one of its normals, the nearer when
    both; OTHER when none is."""
    conjugates = np.asarray(orientations, dtype=float) * [-1.0, -1.0, -1.0, 1.0]
    down = rotate(conjugates, np.array([0.0, 0.0, -1.0])) if len(conjugates) else np.empty(
        (0, 3))
    out = []
    for d in down:
        best, name = MATCH_ANGLE, OTHER
        for a in aspects:
            if a.axis is not None:
                off = abs(math.asin(max(-1.0, min(1.0, float(d @ a.axis))))
                          - math.asin(a.level))
                # on the side's arc: between its facets' directions, not past its ends
                if float(np.max(a.normals @ d)) < math.cos(ROUND_GAP):
                    continue
            else:
                off = math.acos(min(1.0, float(np.max(a.normals @ d))))
            if off <= best:
                best, name = off, a.name
        out.append(name)
    return out




def agreement(simulated: Mapping[str, int], measured: Mapping[str, int]) -> float:
    """The p value of the G-test that the simulated and the measured counts (aspect name ->
    count) come from one distribution (a 2 x K contingency table over the aspects either has;
    an aspect neither saw is left out). A small p: the simulation disagrees."""
    names = [n for n in dict.fromkeys([*simulated, *measured])
             if simulated.get(n, 0) + measured.get(n, 0) > 0]
    if len(names) < 2:
        return 1.0
    table = np.array([[simulated.get(n, 0) for n in names], [measured.get(n, 0) for n in names]])
    if table.sum(axis=1).min() == 0:
        return 1.0
    return float(stats.chi2_contingency(table, lambda_='log-likelihood')[1])
