"""Whether a grasp pose can hold the part at all, before any scene: its jaws, centred on the
grasp point and open to the jaw opening, must close on material.

Along the line through the grasp point in the closing direction, the part's material (where
the line crosses the part's surface) must lie within the open jaws, +-U/2 about the grasp
point, and the grasp point must lie on it (between the outermost crossings). A grasp point
where the jaws close on nothing (a corner of the part, its frame's origin beside it) or a part
wider than the jaws is refused with the width measured, so that a wrong grasp cannot reach a
run unnoticed: every candidate would fail placeability for want of a part between the jaws.

Units: metres; the part frame.
"""

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from pick_common.errors import InvalidArgument
from pick_common.parts.geometry import PartGeometry
from pick_common.parts.primitives import Hull

from .grasps import GraspPose

TOLERANCE = 1e-6        # m: a grasp point this near the surface is on it


@dataclass(frozen=True)
class GraspFit:
    """What the jaws of a grasp close on: `span` (low, high), m along the closing axis from
    the grasp point, of the part's material on the line through it (None when the line misses
    the part); `width` = high - low."""

    name: str
    span: tuple[float, float] | None
    jaw_opening: float

    @property
    def width(self) -> float:
        return 0.0 if self.span is None else self.span[1] - self.span[0]

    def problem(self) -> str:
        """Why the jaws cannot hold the part, or ''."""
        mm = 1000.0
        if self.span is None:
            return ('closes on nothing: the line through grasp_point along closing_axis '
                    'misses the part')
        low, high = self.span
        if not low - TOLERANCE <= 0.0 <= high + TOLERANCE:
            gap = low if low > 0 else -high
            return (f'has its grasp point off the part: the material on its closing line '
                    f'begins {gap * mm:.2f} mm from it')
        if self.width >= self.jaw_opening or max(-low, high) > self.jaw_opening / 2:
            return (f'cannot close on the part: it is {self.width * mm:.2f} mm across the '
                    f'closing axis ({-low * mm:.2f} and {high * mm:.2f} mm either side of the '
                    f'grasp point), and the jaws open {self.jaw_opening * mm:.2f} mm about it')
        return ''


# m: how far outside a triangle's shadow a line may pass and still be tested (`Caster`); far
# beyond the 1e-9 of an edge that `crossings` lets a crossing lie outside a triangle
SHADOW_SLACK = 1e-9
GRID_CELLS = 128   # the most cells a side of Caster's grid


class Caster:
    """`crossings` along one direction, many times: each triangle's shadow (its bounding box
    in the plane square to `direction`) is made once and filed in the cells of a grid over
    the shadows that it covers; a line is tested only against the triangles of its foot's cell
    whose shadow holds the foot (within SHADOW_SLACK). A triangle whose shadow does not hold
    it cannot be crossed by the line, and every shadow that holds a foot covers the foot's
    cell (the cell of a point is monotone in it), so the crossings are those of `crossings` on
    every triangle, to the bit, in the same order: the same arithmetic on the same triangles.
    A cup's seal casts 89 lines straight down onto the part, and a search for a seal on a DIP
    socket (6,758 triangles, a top of contact holes) thousands of seals."""

    def __init__(self, triangles: np.ndarray, direction: np.ndarray) -> None:
        self.triangles = np.asarray(triangles, dtype=np.float64)
        self.direction = np.asarray(direction, dtype=np.float64)
        d = self.direction / np.linalg.norm(self.direction)
        a = np.eye(3)[int(np.argmin(np.abs(d)))]
        self._axes = np.stack([np.cross(d, a), np.cross(d, np.cross(d, a))])
        self._axes /= np.linalg.norm(self._axes, axis=1)[:, None]
        shadow = self.triangles @ self._axes.T                  # (T, 3, 2)
        self._low = shadow.min(axis=1) - SHADOW_SLACK
        self._high = shadow.max(axis=1) + SHADOW_SLACK
        self._file()

    def _file(self) -> None:
        """The grid: GRID_CELLS cells a side (fewer for few triangles) over the shadows' box;
        per cell, its triangles in ascending order (`_start`, `_members`)."""
        count = len(self.triangles)
        side = max(1, min(GRID_CELLS, int(np.sqrt(count))))
        self._corner = self._low.min(axis=0) if count else np.zeros(2)
        span = (self._high.max(axis=0) - self._corner) if count else np.ones(2)
        self._cell = np.where(span > 0, span / side, 1.0)
        self._side = side
        lo = self._cells(self._low)
        hi = self._cells(self._high)
        nx, ny = hi[:, 0] - lo[:, 0] + 1, hi[:, 1] - lo[:, 1] + 1
        many = nx * ny
        tri = np.repeat(np.arange(count), many)
        k = np.arange(len(tri)) - np.repeat(np.cumsum(many) - many, many)
        cell = (lo[tri, 0] + k // ny[tri]) * side + lo[tri, 1] + k % ny[tri]
        order = np.lexsort((tri, cell))
        self._members = tri[order]
        self._start = np.searchsorted(cell[order], np.arange(side * side + 1))

    def _cells(self, points: np.ndarray) -> np.ndarray:
        """The grid column and row of each of `points` (N, 2), clipped to the grid."""
        return np.clip(np.floor((points - self._corner) / self._cell), 0,
                       self._side - 1).astype(np.int64)

    def crossings(self, origin: np.ndarray) -> np.ndarray:
        """`crossings(triangles, origin, direction)`."""
        return self.crossings_of(np.asarray(origin, dtype=np.float64)[None])[0]

    def crossings_of(self, origins: np.ndarray) -> list[np.ndarray]:
        """`crossings(triangles, origin, direction)` for each of `origins` (N, 3), in one
        pass over the (line, triangle) pairs whose shadow holds the line's foot."""
        origins = np.asarray(origins, dtype=np.float64)
        feet = origins @ self._axes.T                                       # (N, 2)
        ij = self._cells(feet)
        cell = ij[:, 0] * self._side + ij[:, 1]
        first, many = self._start[cell], self._start[cell + 1] - self._start[cell]
        line = np.repeat(np.arange(len(origins)), many)
        near = self._members[np.repeat(first - np.cumsum(many) + many, many)
                             + np.arange(len(line))]
        held = ((self._low[near] <= feet[line]) & (feet[line] <= self._high[near])).all(axis=1)
        line, near = line[held], near[held]
        t, hit = _crossed(self.triangles[near], origins[line], self.direction)
        return np.split(t[hit], np.cumsum(np.bincount(line[hit], minlength=len(origins)))[:-1])


def crossings(triangles: np.ndarray, origin: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Where the line origin + t * direction crosses the triangles (T, 3, 3): the t of each
    crossing (Moeller-Trumbore, both faces, the whole line)."""
    t, hit = _crossed(triangles, origin, direction)
    return t[hit]


def _crossed(triangles: np.ndarray, origin: np.ndarray, direction: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray]:
    """Moeller-Trumbore for each triangle (T, 3, 3) and the line from `origin` (3,) or each
    triangle's own (T, 3): the line's t at the triangle's plane, and whether it crosses the
    triangle."""
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    e1, e2 = b - a, c - a
    p = np.cross(direction, e2)
    det = np.einsum('ij,ij->i', e1, p)
    ok = np.abs(det) > 1e-18
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    s = origin - a
    u = np.einsum('ij,ij->i', s, p) * inv
    q = np.cross(s, e1)
    v = (q @ direction) * inv
    t = np.einsum('ij,ij->i', e2, q) * inv
    hit = ok & (u >= -1e-9) & (v >= -1e-9) & (u + v <= 1.0 + 1e-9)
    return t, hit


def surface(part: PartGeometry) -> np.ndarray:
    """The triangles (T, 3, 3) that bound the part's material: its own mesh when it is closed;
    else its hulls (an open mesh's missing triangle would leave one side of a closing line
    uncrossed, and a grasp through it refused), as the mass properties take them."""
    if part.visual.is_watertight:
        return np.asarray(part.visual.triangles)
    hulls = [p.vertices[p.faces] for p in part.primitives if isinstance(p, Hull)]
    return np.concatenate(hulls) if hulls else np.asarray(part.visual.triangles)


# How far the grasped body reaches below the grasp point (`body_bottom`): scanned in steps of
# DEPTH_STEP, a fraction of a step off the round levels where CAD files put their vertices (a
# line through a vertex or along an edge reads a chance length). The body ends where the
# closing lines find no material, or where what they find falls at once below BODY_DROP of
# what they found a step above (a fall JUMP times the step before's or more): the two leads
# below a 5 mm capacitor's body are a fifth of it, the hollow bottom of an electrolytic's bung
# (KiCad's model) half of it; a round body or a taper narrows to nothing step by step, and its
# end is where the material ends.
DEPTH_STEP = 5e-5           # m
DEPTH_OFFSET = 0.313        # of a step
BODY_DROP = 0.35
JUMP = 3.0


def _inside(triangles: np.ndarray, origin: np.ndarray, direction: np.ndarray) -> float:
    """The length of the line origin + t * direction inside the closed surface `triangles`:
    its crossings sorted and paired (a crossing on an edge, found in both its triangles,
    once), m."""
    t = np.unique(np.round(crossings(triangles, origin, direction), 9))
    if len(t) % 2:                  # through a vertex or along a face: its outermost span
        return float(t[-1] - t[0])
    return float((t[1::2] - t[::2]).sum())


def body_bottom(part: PartGeometry, point: np.ndarray, closing: np.ndarray, up: np.ndarray,
                width: float, limit: float) -> float:
    """How far the body the jaws close on reaches below `point` along -`up`, m (at most
    `limit`): the part's material met by lines along `closing` across the jaws' `width`
    (at its middle and a quarter of it either side), level by level down from the grasp
    point, until it ends (DEPTH_STEP, BODY_DROP); the end found to 0.05 um. The part's
    surface decides, never how it is cut into pieces: the same for a part from any file."""
    bodies = ([np.asarray(part.visual.triangles)] if part.visual.is_watertight else
              [p.vertices[p.faces] for p in part.primitives if isinstance(p, Hull)]
              or [np.asarray(part.visual.triangles)])
    point, closing, up = (np.asarray(v, dtype=np.float64) for v in (point, closing, up))
    across = np.cross(up, closing)
    offsets = [0.0, -width / 4, width / 4]

    def material(h: float) -> float:
        return sum(_inside(b, point - h * up + w * across, closing)
                   for b in bodies for w in offsets)

    before = above = material(0.0)
    h = DEPTH_OFFSET * DEPTH_STEP
    while h < limit:
        here = material(h + DEPTH_STEP)
        ended = here <= 0.0
        if ended or (here < BODY_DROP * above and above - here > JUMP * (before - above)):
            def on(m: float, above=above, ended=ended) -> bool:
                return m > 0.0 if ended else m >= BODY_DROP * above
            low, high = h, h + DEPTH_STEP      # the body ends between them
            for _ in range(10):
                mid = (low + high) / 2
                low, high = (mid, high) if on(material(mid)) else (low, mid)
            return min(low, limit)
        before, above, h = above, here, h + DEPTH_STEP
    return limit


def grasp_fit(part: PartGeometry, grasp: GraspPose) -> GraspFit:
    """What the jaws of `grasp` close on, on the surface that bounds the part's material."""
    closing = np.asarray(grasp.closing_axis, dtype=np.float64)
    closing = closing / np.linalg.norm(closing)
    point = np.asarray(grasp.grasp_point, dtype=np.float64)
    t = crossings(surface(part), point, closing)
    span = (float(t.min()), float(t.max())) if len(t) else None
    return GraspFit(grasp.name, span, float(grasp.jaw_opening))


# A round body's cross-section: ROUND_DIRECTIONS lines through the grasp point, each meeting
# the surface within ROUND_TOLERANCE (a fraction of the radius) of one radius on both sides. A
# cylinder tessellated with 16 facets is round within 2 % (cos(pi/16) = 0.981); a square
# section is not (its corners are 41 % further out than its sides).
ROUND_DIRECTIONS = 24
ROUND_TOLERANCE = 0.03


def round_axis(part: PartGeometry, point: np.ndarray, closing: np.ndarray,
               up: np.ndarray) -> np.ndarray:
    """For a mesh part: the axis (unit, part frame) about which the part is round where the
    jaws close on it, or zeros. The axis runs through the grasp point at right angles to the
    closing axis, across the up axis or along it, or along the closing axis itself (jaws on
    a round body's two ends); the part is round about it when every line through the point
    at right angles to it meets the part's surface at one radius on both sides. Jaws closing
    on such a body grip it at any roll about the axis, as those of a built-in capacitor do
    (`Validator.free_axes`)."""
    triangles = surface(part)
    for axis in (np.cross(closing, up), up, closing):
        axis = axis / np.linalg.norm(axis)
        first = up if abs(float(axis @ closing)) > 0.5 else closing     # at right angles to it
        first = first - (first @ axis) * axis
        first /= np.linalg.norm(first)
        side = np.cross(axis, first)
        radii = []
        for angle in np.linspace(0.0, np.pi, ROUND_DIRECTIONS, endpoint=False):
            t = crossings(triangles, point, np.cos(angle) * first + np.sin(angle) * side)
            if len(t) == 0 or t.min() > TOLERANCE or t.max() < -TOLERANCE:
                break
            radii += [-float(t.min()), float(t.max())]
        else:
            radius = float(np.median(radii))
            if radius > 0 and max(abs(r - radius) for r in radii) <= ROUND_TOLERANCE * radius:
                return axis
    return np.zeros(3)


def check_grasps_fit(part: PartGeometry, grasps: Sequence[GraspPose]) -> tuple[GraspFit, ...]:
    """Each grasp's fit; raises InvalidArgument for the first whose jaws cannot hold the part,
    naming the grasp, what it closes on and the width measured."""
    fits = tuple(grasp_fit(part, g) for g in grasps)
    for g, fit in zip(grasps, fits, strict=True):
        problem = fit.problem()
        if problem:
            raise InvalidArgument(f'grasps.{g.name}.grasp_point',
                                  [round(1000.0 * v, 3) for v in g.grasp_point],
                                  f'(mm) {problem}')
    return fits
