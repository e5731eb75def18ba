"""Parallel-jaw grasps proposed from a part's geometry, for a user to start from.

The jaws close across the part at its mass centre, along a direction in which the part has
two opposed parallel faces (each direction at least FACE_SHARE of the surface), or across a
round body (a principal axis, or an axis of the file's frame, at right angles to one the part
is round about, `grasp_fit.round_axis`: a cylinder has no flat faces to close on), at the mass
centre or, where the body lies off it, on the body's axis level with it (an axial resistor's
body above the leads bent down to the board). Each closing direction gets one grasp per way
the part can lie with it horizontal: on a face of at least FACE_SHARE (the up axis that face's
opposite), or on a round body's side. A part with neither (a ceramic disc capacitor's domed
faces) gets the jaws across each principal axis at the mass centre, lying on each other. The
jaws open to the width measured across the grasp point plus JAW_MARGIN on each side.

For a suction cup (`propose_suction`): per way the part can lie (its stable aspects, from
the hull's faces; a round body's side at four rolls), the cup comes down along the aspect's
up axis onto the top of the part, at the point nearest the mass centre's vertical where it
seals and holds (`suction.seal`, `suction.holding`), searched on a grid of half the cup's
radius outward from that vertical.

A proposal is a start, not a gripper design: `run --check` prints them as YAML to paste under
`part.grasps` and edit, and `part.grasps: auto` takes them as they are.

Units: metres; the part frame.
"""

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from pick_common.errors import InvalidArgument
from pick_common.parts.aspects import part_aspects
from pick_common.parts.geometry import PartGeometry
import trimesh

from .grasp_fit import Caster, crossings, round_axis, surface
from .grasps import GraspPose, SuctionGrasp
from .suction import holding, lift, seal

if TYPE_CHECKING:       # the gripper kinds ask for proposals; this module never imports them
    from .grippers import SuctionCup

# 3 mm on each side of the part: the margin of every grasp of the project's test case
# (config/test_case/grippers_pth*.yaml: 11 mm over the capacitor's 5 mm body, 16 and 10.5 mm
# over the TO-220's 10 and 4.5 mm). A chosen margin, not a datasheet's: set jaw_opening_mm to
# what your gripper's stroke and the parts' spacing allow.
JAW_MARGIN = 0.003
# A face a part can lie on or be closed across: at least this share of its surface area.
FACE_SHARE = 0.05
AXIS_NAMES = ('x', 'y', 'z')
SNAP = np.radians(3.0)      # a direction this near a frame axis is taken as that axis
ROUNDING = 1e-5             # jaw openings and grasp points to 0.01 mm, as a person reads them
MAX_BODIES = 8              # the connected bodies looked at for a round body off the mass centre


@dataclass(frozen=True)
class Proposal:
    """A proposed grasp and the width it closes on, m (a suction grasp's: the rim's
    deviation from a plane)."""

    grasp: GraspPose | SuctionGrasp
    width: float


def _directions(part: PartGeometry) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """(face directions: outward normals of faces of at least FACE_SHARE of the surface,
    principal axes: both signs of the part's three), unit vectors in the part frame."""
    mesh = trimesh.Trimesh(*_faces(part), process=True)
    normals, areas = mesh.face_normals, mesh.area_faces
    keys = np.round(normals, 3)
    faces = []
    for key in np.unique(keys, axis=0):
        same = (keys == key).all(axis=1)
        if areas[same].sum() >= FACE_SHARE * areas.sum():
            n = (normals[same] * areas[same, None]).sum(axis=0)
            faces.append(n / np.linalg.norm(n))
    if part.mass_frame is not None:
        x, y, z, w = part.mass_frame[1]
        axes = trimesh.transformations.quaternion_matrix([w, x, y, z])[:3, :3].T
    else:
        axes = np.eye(3)
    principal = [s * a for a in axes for s in (1.0, -1.0)]
    return faces, principal


def _faces(part: PartGeometry) -> tuple[np.ndarray, np.ndarray]:
    triangles = surface(part)
    return triangles.reshape(-1, 3), np.arange(len(triangles) * 3).reshape(-1, 3)


def _snap(v: np.ndarray) -> np.ndarray:
    """A direction within SNAP of a frame axis becomes that axis: a part drawn in CAD has
    its symmetry along its frame's axes, and a mesh's principal axes stray from them by a
    few degrees where a lead, a flat or the tessellation breaks the symmetry slightly."""
    v = v / np.linalg.norm(v)
    k = int(np.argmax(np.abs(v)))
    if abs(float(v[k])) >= np.cos(SNAP):
        v = np.sign(v[k]) * np.eye(3)[k]
    return v + 0.0        # + 0.0: no -0 in the YAML


def _name(v: np.ndarray) -> str:
    """+x, -z, ... for a frame axis; else the nearest axis and the angle from it, '+z9deg'."""
    k = int(np.argmax(np.abs(v)))
    axis = ('+' if v[k] > 0 else '-') + AXIS_NAMES[k]
    angle = np.degrees(np.arccos(min(1.0, abs(float(v[k])))))
    return axis if angle < 1e-6 else f'{axis}{angle:.0f}deg'


def propose(part: PartGeometry, margin: float = JAW_MARGIN) -> tuple[Proposal, ...]:
    """Grasps at the mass centre across opposed faces, one per way the part can lie with the
    closing direction horizontal; and across each round body, one grasp that the check turns
    with the body's roll (`Validator.free_axes`), lying on its side, plus one per flat end it
    can stand on; on a round body's two ends, lying, one grasp, which turns the same way.
    With none of these, across each principal axis, lying on each at right angles to it."""
    centre = part.mass_centre
    centre = np.round(centre / ROUNDING) * ROUNDING
    faces, principal = _directions(part)
    # round bodies: an axis it is round about (the frame's axes where they are, else the
    # principal axes: a round body's two equal moments leave its principal axes across it
    # at any angle), and a direction across it
    triangles = surface(part)
    rounds: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []     # axis, across, point
    for a in [*principal[::2], *np.eye(3)]:   # a CAD file draws its bodies along its axes
        a = _snap(a)
        if any(abs(a @ b) > 0.999 for b, _, _ in rounds):
            continue
        square = [s * e for e in np.eye(3) for s in (1.0, -1.0) if abs(e @ a) < 1e-6]
        sides = square or [p for p in principal if abs(p @ a) < 1e-6]
        if not sides:
            continue
        def round_at(p: np.ndarray, a: np.ndarray = a, side: np.ndarray = sides[0]) -> bool:
            return abs(float(round_axis(part, p, side, a) @ a)) > 0.999

        # the mass centre first; the bodies off it only when the part is not round there
        point = centre if round_at(centre) else next(
            (p for p in _off_centre(part, triangles, centre, a, sides[0]) if round_at(p)), None)
        if point is not None:
            rounds.append((a, _distinct([sides[0]], signed=False)[0], point))
    found: list[Proposal] = []

    def add(u: np.ndarray, c: np.ndarray, at: np.ndarray = centre) -> None:
        t = crossings(triangles, at, c)
        if len(t) == 0 or t.min() > 0 or t.max() < 0:
            return                  # the grasp point lies in a hollow along this direction
        width = float(t.max() - t.min())
        opening = float(np.round((width + 2 * margin) / ROUNDING) * ROUNDING)
        found.append(Proposal(GraspPose(
            f'up{_name(u)}_close{_name(c)}', tuple(float(v) for v in u),
            tuple(float(v) for v in c), opening, tuple(float(v) for v in at)), width))

    for a, c, at in rounds:
        add(_snap(np.cross(a, c)), c, at)       # lying on its side, at any roll
        for u in _distinct([-f for f in faces], signed=True):
            if abs(u @ a) > 0.999:              # standing on a flat end
                add(u, c, at)
    closings = _distinct([f for f in faces if any(f @ g < -0.999 for g in faces)],
                         signed=False)
    for c in closings:
        if any(abs(c @ a) < 1e-3 for a, _, _ in rounds):
            continue                            # across a round body: its grasps are above
        ups = [u for u in _distinct([-f for f in faces], signed=True) if abs(u @ c) <= 1e-3]
        if any(abs(c @ a) > 0.999 for a, _, _ in rounds):
            ups = ups[:1] or [_snap(np.cross(c, _distinct([np.eye(3)[int(np.argmin(
                np.abs(c)))]], signed=False)[0]))]   # on its ends, lying: it turns with the roll
        for u in ups:
            add(u, c)
    if not found:           # no opposed faces, no round body: across its principal axes
        for c in _distinct(principal, signed=False):
            for u in _distinct(principal, signed=True):
                if abs(u @ c) <= 1e-3:
                    add(u, c)
    return tuple(found)


def _off_centre(part: PartGeometry, triangles: np.ndarray, centre: np.ndarray,
                axis: np.ndarray, across: np.ndarray) -> list[np.ndarray]:
    """Where a round body about `axis` may lie off the mass centre, in the plane through the
    centre at right angles to `axis`: the middle of each of the part's bodies (the connected
    pieces of its mesh, the largest first, at most MAX_BODIES) brought into that plane; and,
    along `across` and the direction at right angles to it, the middle of each stretch
    between two crossings of the part's surface, centred along the other direction between
    the crossings nearest it. An axial resistor's body lies above its mass centre, which its
    leads, bent down to the board, pull below the body's axis. The candidates a check of
    roundness (`round_axis`) then accepts or not."""
    out: list[np.ndarray] = []

    def keep(p: np.ndarray) -> None:
        p = np.round(p / ROUNDING) * ROUNDING
        if not any(np.allclose(p, q) for q in [centre, *out]):
            out.append(p)

    bodies = sorted(part.visual.split(only_watertight=False), key=lambda b: -b.area)
    for body in bodies[:MAX_BODIES]:
        middle = body.bounds.mean(axis=0)
        keep(middle + ((centre - middle) @ axis) * axis)
    for b in (across, np.cross(axis, across)):
        c = np.cross(axis, b)
        t = np.unique(np.round(crossings(triangles, centre, b) / ROUNDING) * ROUNDING)
        for enter, leave in zip(t[:-1], t[1:], strict=True):
            p = centre + 0.5 * (enter + leave) * b
            s = crossings(triangles, p, c)
            below, above = s[s < -ROUNDING], s[s > ROUNDING]
            if len(below) and len(above):
                keep(p + 0.5 * (below.max() + above.min()) * c)
    return out


def _distinct(directions: list[np.ndarray], signed: bool) -> list[np.ndarray]:
    """Directions snapped to the frame's axes, each once (and, unsigned, once with its
    opposite, pointing along its largest positive component)."""
    kept: list[np.ndarray] = []
    for d in directions:
        d = _snap(d)
        if not signed and d[np.argmax(np.abs(d))] < 0:
            d = -d + 0.0
        if not any((d @ k if signed else abs(d @ k)) > 0.999 for k in kept):
            kept.append(d)
    return kept


def propose_suction(part: PartGeometry, cup: 'SuctionCup') -> tuple[Proposal, ...]:
    """One suction grasp per way the part can lie (module docstring); InvalidArgument naming
    gripper.cup_diameter when the cup seals nowhere, with the largest of the cup's halves and
    quarters that would, or when its vacuum cannot lift the part at any grasp (`lift`: then
    no seal is searched for; KiCad's 15.8 g D-sub 9 on the 4 mm cup searched over 23 min)."""
    force, needed = lift(part, cup)
    if force < needed:
        raise InvalidArgument('gripper.cup_diameter', round(cup.cup_diameter * 1000, 3),
                              f'(mm) gives a vacuum force of {force:.3g} N where the part '
                              f'({part.mass * 1000:.3g} g) needs {needed:.3g} N (its weight '
                              "and the robot's acceleration over the friction, times the "
                              'safety factor): no grasp of it holds the part; choose a '
                              'larger cup or a stronger vacuum')
    found = _cup_grasps(part, cup)
    if found:
        return found
    for share in (0.75, 0.5, 0.25):
        smaller = cup.with_values(cup_diameter=share * cup.cup_diameter)
        if _cup_grasps(part, smaller):
            fits = f'a {smaller.cup_diameter * 1000:g} mm cup would seal on it'
            break
    else:
        fits = f'not even a {0.25 * cup.cup_diameter * 1000:g} mm cup would'
    raise InvalidArgument('gripper.cup_diameter', round(cup.cup_diameter * 1000, 3),
                          '(mm) is larger than every flat patch on the top of the part as it '
                          f'can lie: {fits}; write its grasps, or choose a smaller cup')


def _cup_grasps(part: PartGeometry, cup: 'SuctionCup') -> tuple[Proposal, ...]:
    centre = part.mass_centre
    triangles = surface(part)
    step = cup.cup_diameter / 4
    reach = int(np.ceil(part.radius / step))
    offsets = sorted(((i, j) for i in range(-reach, reach + 1) for j in range(-reach, reach + 1)
                      if np.hypot(i, j) * step <= part.radius), key=lambda ij: np.hypot(*ij))
    out = []
    for up in _cup_ups(part):
        if any(np.allclose(up, p.grasp.up_axis) for p in out):
            continue
        e1 = _snap(np.cross(up, np.eye(3)[int(np.argmin(np.abs(up)))]))
        e2 = np.cross(up, e1)
        top = 2 * part.radius + float(np.linalg.norm(centre))
        down = Caster(triangles, -up)
        sealing = None      # the surface cast along the checked grasp's -up, as seal casts it
        bases = [centre + step * (i * e1 + j * e2) for i, j in offsets]
        for base, t in zip(bases, down.crossings_of(np.array(bases) + top * up), strict=True):
            t = t[t >= 0]
            if not len(t):
                continue
            point = np.round((base + (top - float(t.min())) * up) / ROUNDING) * ROUNDING
            grasp = SuctionGrasp(f'cup_up{_name(up)}', tuple(float(v) for v in up),
                                 tuple(float(v) for v in point))
            checked = cup.check_grasp(grasp, f'grasps.{grasp.name}', grasp.name)
            if sealing is None:
                sealing = (down if np.array_equal(checked.up, -down.direction)
                           else Caster(triangles, -checked.up))
            found = seal(part, cup, checked, sealing)
            if found.ok and holding(part, cup, checked).ok:
                out.append(Proposal(grasp, found.deviation))
                break
    return tuple(out)


def _cup_ups(part: PartGeometry) -> list[np.ndarray]:
    """The up axes the cup comes down along: each aspect's (minus the normal of the face it
    rests on), and for a round body lying on its side (aspect `side_<axis>`) the four frame
    axes across it: a cup, unlike the jaws, is not turned with the roll by the check, and
    four rolls a quarter turn apart leave none more than 45 deg (check.tolerance's default)
    from one."""
    ups = []
    for aspect in part_aspects(part):
        if aspect.name.startswith('side_'):
            k = AXIS_NAMES.index(aspect.name[-1])
            ups += [s * e for e in np.eye(3) if e[k] == 0 for s in (1.0, -1.0)]
        else:
            ups.append(_snap(-np.asarray(aspect.normal, dtype=np.float64)))
    return ups


def as_yaml(proposals: tuple[Proposal, ...]) -> list[str]:
    """The proposals as the lines of `part.grasps` in an experiment file (mm)."""
    return ['  grasps:'] + [f'    - {p.grasp.as_yaml(p.width)}' for p in proposals]
