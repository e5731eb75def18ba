"""How a part comes to rest on a flat floor: its aspects, which aspect a resting pose shows,
the quasi-static prediction, and drop counts against a measurement.

An aspect is a face of the part's convex hull it can stand on (a face onto which the mass
centre projects: trimesh.poses.compute_stable_poses), named from its outward normal in the
part's frame: `+x` ... `-z` when the normal lies within MERGE_ANGLE of an axis; `side_<axis>`
for the many narrow faces of a round body's side, all perpendicular to its axis (more than
ROUND_FACES of them: merged into one, as a user counts a cylinder on its side); `face_<k>`
otherwise, numbered by falling quasi-static share (equal shares by
the normal, +x first, then +y, +z). Faces whose normals lie within MERGE_ANGLE
of each other are one aspect. The quasi-static share of a face is trimesh's: the solid angle
of the directions of gravity that roll the part onto it without momentum.

Pure: numpy, scipy and trimesh; no simulator.
"""

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
import math

import numpy as np
from scipy import stats
import trimesh

from ..states import rotate
from .geometry import build_part, PartGeometry
from .spec import geometry_key, PartSpec

MERGE_ANGLE = math.radians(5.0)     # faces this close in normal are one aspect
MATCH_ANGLE = math.radians(10.0)    # a pose this far from every aspect is OTHER
ROUND_FACES = 8                     # more faces than this around one axis: a round side
OTHER = 'other'                     # a pose on no aspect (leaning, balanced on an edge)
AXES = {'+x': (1, 0, 0), '-x': (-1, 0, 0), '+y': (0, 1, 0), '-y': (0, -1, 0),
        '+z': (0, 0, 1), '-z': (0, 0, -1)}


@dataclass(frozen=True)
class Aspect:
    """name; normal: the unit outward normal (3,) of the face the part rests on, in the part
    frame (a round side's: its likeliest face's); normals: every face's of the aspect (K, 3);
    quasi_static: its share without momentum."""

    name: str
    normal: tuple[float, float, float]
    normals: np.ndarray
    quasi_static: float


def stable_aspects(mesh: trimesh.Trimesh, centre: Sequence[float]) -> list[Aspect]:
    """The aspects of a part of `mesh` (its frame, m) with its mass centre at `centre` (3,),
    likeliest first (module docstring)."""
    transforms, shares = trimesh.poses.compute_stable_poses(
        mesh.convex_hull, center_mass=np.asarray(centre, dtype=float))
    normals = np.array([t[:3, :3].T @ [0.0, 0.0, -1.0] for t in transforms])
    shares = np.asarray(shares, dtype=float) / max(float(np.sum(shares)), 1e-300)
    groups: dict[str, list[int]] = {}
    left = list(range(len(normals)))
    for axis_name, axis in (('x', 0), ('y', 1), ('z', 2)):     # a round body's side
        side = [i for i in left if abs(normals[i][axis]) < math.sin(MERGE_ANGLE)]
        if len(side) > ROUND_FACES:
            groups[f'side_{axis_name}'] = side
            left = [i for i in left if i not in side]
    cos_merge = math.cos(MERGE_ANGLE)
    for name, axis in AXES.items():
        on = [i for i in left if normals[i] @ axis > cos_merge]
        if on:
            groups[name] = on
            left = [i for i in left if i not in on]
    clusters: list[list[int]] = []
    for i in sorted(left, key=lambda i: (-round(shares[i], 6), *(-normals[i]).round(6))):
        for c in clusters:
            if normals[c[0]] @ normals[i] > cos_merge:
                c.append(i)
                break
        else:
            clusters.append([i])
    # by falling share, a tie (a mirror pair) by the normal, +x first: the same names on any run
    clusters.sort(key=lambda c: (-round(float(shares[c].sum()), 6), *(-normals[c[0]]).round(6)))
    groups.update({f'face_{k + 1}': c for k, c in enumerate(clusters)})
    aspects = []
    for name, members in groups.items():
        best = members[int(np.argmax(shares[members]))]
        mean = normals[members].mean(axis=0)
        normal = mean / np.linalg.norm(mean) if np.linalg.norm(mean) > 0.5 else normals[best]
        aspects.append(Aspect(name, tuple(float(v) for v in normal), normals[members],
                              float(shares[members].sum())))
    return sorted(aspects, key=lambda a: (-round(a.quasi_static, 6), *(-np.array(a.normal))
                                          .round(6)))


_BY_GEOMETRY: dict[tuple, tuple[Aspect, ...]] = {}


def part_aspects(part: PartGeometry) -> tuple[Aspect, ...]:
    """A built part's aspects: stable_aspects of its visual mesh about its mass centre (a
    mesh's own, a built-in model's frame origin), computed once per geometry in a process
    (the file's check, the part's account and the summary ask for the same part's)."""
    key = geometry_key(part.spec)
    if key not in _BY_GEOMETRY:
        centre = part.mass_frame[0] if part.mass_frame is not None else np.zeros(3)
        _BY_GEOMETRY[key] = tuple(stable_aspects(part.visual, centre))
    return _BY_GEOMETRY[key]


def spec_aspects(spec: PartSpec) -> tuple[Aspect, ...]:
    """The aspects of the part a spec describes (part_aspects), its part built only when no
    aspects of its geometry are known yet."""
    return _BY_GEOMETRY.get(geometry_key(spec)) or part_aspects(build_part(spec))


def classify(aspects: Sequence[Aspect], orientations: np.ndarray) -> list[str]:
    """The aspect each resting part shows, by the direction of gravity in its frame (the
    orientations (N, 4) xyzw of the part frame in a frame whose z is up); OTHER when no aspect
    lies within MATCH_ANGLE."""
    conjugates = np.asarray(orientations, dtype=float) * [-1.0, -1.0, -1.0, 1.0]
    down = rotate(conjugates, np.array([0.0, 0.0, -1.0])) if len(conjugates) else np.empty(
        (0, 3))
    out = []
    for d in down:
        best = max(((float(np.max(a.normals @ d)), a.name) for a in aspects), default=(-1, ''))
        out.append(best[1] if best[0] > math.cos(MATCH_ANGLE) else OTHER)
    return out


def share_interval(count: int, total: int) -> tuple[float, float]:
    """The 95 % Wilson interval of a share count / total."""
    if total <= 0:
        return 0.0, 1.0
    z = 1.959963984540054
    p = count / total
    centre = (p + z * z / (2 * total)) / (1 + z * z / total)
    half = z * math.sqrt(p * (1 - p) / total + z * z / (4 * total * total)) / (1 + z * z / total)
    return max(0.0, centre - half), min(1.0, centre + half)


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
