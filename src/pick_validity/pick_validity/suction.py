"""Whether a suction cup can hold the part at a grasp, before any scene: does its rim seal on
the part's surface, and does the vacuum hold the part's weight, the robot's acceleration and
the moment of the mass centre's offset.

The seal. The cup approaches along minus the grasp's up axis, its centre on the grasp point.
Lines along the approach are cast onto the part's surface (grasp_fit.crossings on the surface
that bounds its material) from RIM_POINTS points on a ring of the cup's diameter and from
points inside it, and the first surface each meets from above is where the cup would touch:
- the grasp point must lie on that surface (within ON_SURFACE);
- every line must meet the part: one that misses leaves the part at an edge, or falls
  through a hole, inside the ring or under its rim;
- the rim's points and the surface inside the ring must lie within the cup's give of one
  plane (the rim's least-squares plane): LIP_GIVE of the cup's height. Our reading of Dex-Net
  3.0's compliant contact model (Mahler et al., ICRA 2018: a seal forms when the cup's
  perimeter lies on the surface and no spring of the cup stretches more than a small share),
  in the form of a deviation from a plane; a lead or a boss standing inside the ring, a
  curved face and a cup across a corner all exceed it. Not their spring model itself.

The holding force (Schmalz, "Theoretical holding force of a suction cup", load case II: the
cup horizontal, the part moved sideways): the vacuum's force on the cup's area, vacuum * pi *
r^2, must be at least m (g + a / mu) S; and the moment of the weight and of the acceleration
about the rim, m (g d + a h) with d the mass centre's distance from the cup's axis and h its
depth below the rim's plane, at most the vacuum's force times the cup's radius over S (the
cup peels about its rim: statics, no catalogue). The margin is the smaller ratio; the cup
holds at 1 or more.

Pure: no rclpy, no simulator. Units: m, kg, Pa; the part frame.
"""

from dataclasses import dataclass
import math
from typing import TYPE_CHECKING

import numpy as np
from pick_common.parts.geometry import PartGeometry
from pick_common.states import perpendicular

from .grasp_fit import Caster, surface
from .grasps import CupGrasp

if TYPE_CHECKING:
    from .grippers import SuctionCup

RIM_POINTS = 32
INNER_RINGS = (0.0, 0.3, 0.6, 0.85)     # shares of the cup's radius cast inside the rim
ON_SURFACE = 1e-4       # m: a grasp point this near the first surface below it lies on it
LIP_GIVE = 0.10         # the share of its height by which the cup's lip gives
GRAVITY = 9.81          # m/s^2
OFF_SURFACE = "the grasp point is not on the part's surface"


@dataclass(frozen=True)
class Seal:
    """Does the cup seal at a grasp: `reason` '' when it does, else why not; `deviation` the
    largest distance of the rim and the surface inside it from the rim's plane, m (nan when a
    line missed); `give` the most the cup allows, m; `rim` (RIM_POINTS, 3) where the rim
    touches the part (nan where a line missed), the part frame."""

    reason: str
    deviation: float
    give: float
    rim: np.ndarray

    @property
    def ok(self) -> bool:
        return not self.reason


@dataclass(frozen=True)
class Holding:
    """The cup's force and moment against what it must hold: `force` the vacuum's, N;
    `needed` m (g + a / mu) S, N; `offset` the mass centre's distance from the cup's axis, m;
    `margin` the smaller of the force's and the moment's ratios (holds at 1 or more)."""

    force: float
    needed: float
    offset: float
    margin: float

    @property
    def ok(self) -> bool:
        return self.margin >= 1.0


def _basis(up: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    a = perpendicular(up)
    return a, np.cross(up, a)


def _heights(down: Caster, points: np.ndarray, up: np.ndarray, top: float) -> np.ndarray:
    """Per point (in the plane through the grasp point), the height along `up` of the first
    surface a line coming down from `top` above it meets (`down`: the part's surface cast
    along -up); nan where the line misses."""
    out = np.full(len(points), np.nan)
    for i, t in enumerate(down.crossings_of(np.asarray(points) + top * up)):
        t = t[t >= 0.0]
        if len(t):
            out[i] = top - float(t.min())
    return out


def seal(part: PartGeometry, cup: 'SuctionCup', grasp: CupGrasp,
         down: Caster | None = None) -> Seal:
    """Does the cup's rim seal on the part at `grasp` (module docstring). `down`: the part's
    surface cast along -up (a search for a seal casts many with one)."""
    up, point = grasp.up, grasp.point
    if down is None:
        down = Caster(surface(part), -up)
    e1, e2 = _basis(up)
    radius = cup.cup_diameter / 2
    top = 2.0 * part.radius + float(np.linalg.norm(point)) + radius
    angles = np.linspace(0.0, 2 * math.pi, RIM_POINTS, endpoint=False)
    ring = np.cos(angles)[:, None] * e1 + np.sin(angles)[:, None] * e2
    give = LIP_GIVE * cup.cup_height
    mm = 1000.0
    centre = _heights(down, point[None], up, top)[0]
    if math.isnan(centre) or abs(centre) > ON_SURFACE:
        where = ('the line along the approach through it misses the part' if math.isnan(centre)
                 else f'the first surface along the approach lies {centre * mm:+.2f} mm from '
                 'it along up_axis')
        return Seal(f"the grasp point is not on the part's surface: {where}", math.nan, give,
                    np.full((RIM_POINTS, 3), np.nan))
    rim_z = _heights(down, point + radius * ring, up, top)
    rim = point + radius * ring + rim_z[:, None] * up
    if np.isnan(rim_z).any():
        k = int(np.flatnonzero(np.isnan(rim_z))[0])
        return Seal(f'the rim leaves the part: the line at {math.degrees(angles[k]):.0f} deg '
                    f'round the {cup.cup_diameter * mm:.2f} mm ring meets no surface (an edge '
                    'or a hole under the rim)', math.nan, give, rim)
    inner = [point + s * radius * (np.cos(a) * e1 + np.sin(a) * e2)
             for s in INNER_RINGS for a in np.linspace(0.0, 2 * math.pi,
                                                      max(1, int(RIM_POINTS * s)),
                                                      endpoint=False)]
    inner_z = _heights(down, np.array(inner), up, top)
    if np.isnan(inner_z).any():
        return Seal('a line inside the ring meets no surface: a hole or an edge lies inside '
                    'the cup', math.nan, give, rim)
    # the rim's least-squares plane, z = c0 + c1 x + c2 y in the cup's (e1, e2) coordinates
    xy = np.column_stack([np.ones(RIM_POINTS), radius * ring @ e1, radius * ring @ e2])
    coef, *_ = np.linalg.lstsq(xy, rim_z, rcond=None)
    inner_xy = np.array(inner) - point
    inner_plane = coef[0] + inner_xy @ e1 * coef[1] + inner_xy @ e2 * coef[2]
    tilt = 1.0 / math.sqrt(1.0 + coef[1] ** 2 + coef[2] ** 2)       # heights to distances
    rim_off = float(np.abs(rim_z - xy @ coef).max()) * tilt
    inner_off = float(np.abs(inner_z - inner_plane).max()) * tilt
    deviation = max(rim_off, inner_off)
    if deviation > give:
        what = ('the rim leaves its plane' if rim_off >= inner_off else
                "the surface inside the ring stands out of the rim's plane")
        return Seal(f'{what} by {deviation * mm:.2f} mm; the cup gives '
                    f'{give * mm:.2f} mm ({100 * LIP_GIVE:g} % of its '
                    f'{cup.cup_height * mm:g} mm height): a curved face, an edge, or a lead or '
                    'boss inside the ring', deviation, give, rim)
    return Seal('', deviation, give, rim)


def lift(part: PartGeometry, cup: 'SuctionCup') -> tuple[float, float]:
    """(the vacuum's force on the cup's area, the force the part needs: its weight and the
    robot's acceleration over the friction, times the safety factor), N; the same at every
    grasp, so where the first is the smaller no grasp holds (module docstring)."""
    force = cup.vacuum * math.pi * (cup.cup_diameter / 2) ** 2
    return force, part.mass * (GRAVITY + cup.acceleration / cup.cup_friction) * cup.safety_factor


def holding(part: PartGeometry, cup: 'SuctionCup', grasp: CupGrasp) -> Holding:
    """The cup's holding force and margin at `grasp` (module docstring)."""
    centre = part.mass_centre
    radius = cup.cup_diameter / 2
    force, needed = lift(part, cup)
    m = part.mass
    arm = centre - grasp.point
    depth = max(0.0, -float(arm @ grasp.up))
    offset = float(np.linalg.norm(arm - (arm @ grasp.up) * grasp.up))
    moment = m * (GRAVITY * offset + cup.acceleration * depth) * cup.safety_factor
    margin = force / needed if needed > 0 else math.inf
    if moment > 0:
        margin = min(margin, force * radius / moment)
    return Holding(force, needed, offset, margin)
