"""A single suction cup on a body (the paper's further work: "other kinds of grippers, such
as vacuum"), one of the gripper kinds (the package's __init__ says what a kind owns); whether
it seals and holds at a grasp is suction.py's physics. The collision stack is imported in the
methods that build shapes and seals, as jaws.py says why.

Units: metres, pascals, m/s^2; the part frame, or the gripper frame for its shapes.
"""

from dataclasses import dataclass
from typing import ClassVar, TYPE_CHECKING

import numpy as np
from pick_common.errors import InvalidArgument, Limit
from pick_common.states import perpendicular

from ..grasps import CupGrasp, grasp_point, SuctionGrasp, unit
from .base import Grip, Key, Kind

if TYPE_CHECKING:
    from pick_common.parts.geometry import PartGeometry

    from ..geometry import CylinderShape, Shape

# Where the suction cup's defaults come from.
VACUUM_SOURCE = (
    'vacuum 60 kPa: Schmalz, glossary "Holding force" (a cup\'s holding force is usually '
    'stated at 60 % vacuum); safety factor 2 and cup friction 0.5: Schmalz, "Theoretical '
    'holding force of a suction cup" (S at least 1.5 for smooth, dense workpieces, 2.0 or more '
    'for critical ones; mu 0.5 for metal, glass, stone); cup 4 x 3 mm, body 10 x 60 mm and the '
    "robot's acceleration 10 m/s^2: assumed")
SCHMALZ_FORCE = 'Schmalz, "Theoretical holding force of a suction cup"'
MM = 1000.0         # mm per m, for a part sheet


@dataclass(frozen=True)
class SuctionCup(Kind):
    """A single suction cup on a body. m, Pa, m/s^2.

    cup_diameter and cup_height: the cup's rim and how high its lip (or bellows) stands above
    the rim to the body; the cup approaches along minus the grasp's up axis and seals when its
    rim lies on the part all round (`suction.seal`). body_diameter and body_length: the
    cylinder above the cup. vacuum: the pressure below the atmosphere the cup holds at;
    safety_factor, acceleration (the robot's, horizontal) and cup_friction (cup on part) set
    the force the cup must hold (`suction.holding`). Defaults and their sources: KEYS
    (VACUUM_SOURCE in one sentence).
    """

    kind: ClassVar[str] = 'suction'
    description: ClassVar[str] = 'a suction cup'
    written: ClassVar[type] = SuctionGrasp
    default_grasps: ClassVar[tuple] = ()      # none: a cup's grasps are the part's own
    KEYS: ClassVar[tuple[Key, ...]] = (
        Key('cup_diameter', 'mm', Limit(0.0, 0.5, low_open=True), "the cup's rim, m"),
        Key('cup_height', 'mm', Limit(0.0, 0.5, low_open=True),
            "the cup's lip from its rim to the body, m"),
        Key('body_diameter', 'mm', Limit(0.0, 1.0, low_open=True), 'm'),
        Key('body_length', 'mm', Limit(0.0, 2.0, low_open=True), 'm'),
        Key('vacuum', 'kPa', Limit(0.0, 101_325.0, low_open=True),
            'pressure below the atmosphere the cup holds at, Pa',
            'Schmalz, glossary "Holding force" (a cup\'s holding force is usually stated at '
            '60 % vacuum)'),
        Key('safety_factor', '', Limit(1.0, 10.0), 'on the force the cup must hold',
            f'{SCHMALZ_FORCE} (S at least 1.5 for smooth, dense workpieces, 2.0 or more for '
            'critical ones)'),
        Key('acceleration', 'm/s^2', Limit(0.0, 1000.0),
            "the robot's horizontal acceleration, m/s^2"),
        Key('cup_friction', '', Limit(0.0, 2.0, low_open=True), 'friction of the cup on the part',
            f'{SCHMALZ_FORCE} (mu 0.5 for metal, glass, stone)'),
    )

    cup_diameter: float = 0.004
    cup_height: float = 0.003
    body_diameter: float = 0.010
    body_length: float = 0.060
    vacuum: float = 60_000.0
    safety_factor: float = 2.0
    acceleration: float = 10.0
    cup_friction: float = 0.5

    @property
    def size(self) -> tuple[float, ...]:
        """What "smaller" means when cups are compared: the body's diameter first, then the
        cup's diameter and height, then the body's length."""
        return self.body_diameter, self.cup_diameter, self.cup_height, self.body_length

    def check_grasp(self, g, where: str, name: str) -> CupGrasp:
        """The checked grasp: its closing axis a fixed one at right angles to its up axis (the
        gripper frame's x; the cup is round)."""
        up = unit(f'{where}.up_axis', g.up_axis)
        return CupGrasp(name, up, perpendicular(up), grasp_point(where, g.grasp_point))

    def width(self, grasp: CupGrasp) -> float:
        return self.cup_diameter

    def shapes(self, grasp: CupGrasp, depth: float = 0.0
               ) -> 'tuple[CylinderShape, CylinderShape]':
        """The cup (diameter cup_diameter, from its rim at the grasp point up cup_height) and
        the body cylinder above it, in the gripper frame: origin at the grasp point, z up the
        gripper (the grasp's up axis)."""
        import fcl

        from ..geometry import CylinderShape
        r, h, length = self.cup_diameter / 2, self.cup_height, self.body_length
        lip = CylinderShape(np.eye(3), np.array([0.0, 0.0, h / 2]), fcl.Cylinder(r, h), r,
                            h / 2)
        body = CylinderShape(np.eye(3), np.array([0.0, 0.0, h + length / 2]),
                             fcl.Cylinder(self.body_diameter / 2, length),
                             self.body_diameter / 2, length / 2)
        return lip, body

    def grip(self, part: 'PartGeometry', written: tuple, grasps: tuple[CupGrasp, ...],
             tilts: np.ndarray, part_shapes: 'tuple[Shape, ...]') -> Grip:
        """One approach per grasp, along minus its up axis (the cup is round: no wrist tilt,
        the tilts are [0]); each grasp's seal and holding. Raises InvalidArgument for a grasp
        point off the part's surface (a mistake, not a grasp that fails), and when no grasp
        both seals and holds, naming each grasp's reason."""
        from ..suction import holding, OFF_SURFACE, seal
        seals = tuple(seal(part, self, g) for g in grasps)
        for g, s in zip(grasps, seals, strict=True):
            if s.reason.startswith(OFF_SURFACE):
                raise InvalidArgument(f'grasps.{g.name}.grasp_point',
                                      [round(1000.0 * v, 3) for v in g.point], f'(mm) {s.reason}')
        holds = tuple(holding(part, self, g) for g in grasps)
        usable = np.array([s.ok and h.ok for s, h in zip(seals, holds, strict=True)])
        if not usable.any():
            why = '; '.join(f'{g.name!r}: ' + (s.reason or f'holds with a margin of only '
                                                  f'{h.margin:.2f}')
                            for g, s, h in zip(grasps, seals, holds, strict=True))
            raise InvalidArgument('grasps', [g.name for g in grasps],
                                  f'hold no grasp the cup can use: {why}')
        return Grip(tilts=np.zeros(1), fits=(), finger_depths=tuple(0.0 for _ in grasps),
                    free_axes=np.zeros((len(grasps), 3)),
                    shapes=tuple(self.shapes(g) for g in grasps), usable=usable,
                    seals=seals, holds=holds)

    def approach(self, x: np.ndarray, rotations: np.ndarray, up: np.ndarray) -> np.ndarray:
        """(n, 3): the cup's axis is the grasp's up axis `up` (n, 3) of parts at rotations
        (n, 3, 3), in the container frame."""
        return np.einsum('nij,nj->ni', rotations, up)

    # ---- what a part sheet says of it (mm: MM m)
    def account(self) -> list[str]:
        """Its line on a part sheet: its sizes, vacuum and load, and their sources."""
        return [f'  gripper: a suction cup {self.cup_diameter * MM:g} mm across and '
                f'{self.cup_height * MM:g} mm high on a {self.body_diameter * MM:g} x '
                f'{self.body_length * MM:g} mm body, {self.vacuum / 1000:g} kPa, safety '
                f'factor {self.safety_factor:g}, {self.acceleration:g} m/s^2, cup friction '
                f'{self.cup_friction:g} (defaults: {VACUUM_SOURCE})']

    def figures(self, geometry, k: int, written: SuctionGrasp) -> dict:
        """What the check computed of grasp k before any scene (`geometry`: its
        check_geometry.CheckGeometry), mm: its seal (true or false, the reason), the rim's
        deviation from a plane against the cup's give, the force margin and the distance of
        the grasp point from the mass centre's line."""
        found, held = geometry.seals[k], geometry.holds[k]
        return {
            'gripper': self.kind, 'seal': found.ok, 'reason': found.reason,
            'deviation_mm': None if np.isnan(found.deviation) else
            round(found.deviation * MM, 4), 'give_mm': round(found.give * MM, 4),
            'holding_force_n': round(held.force, 4), 'needed_n': round(held.needed, 4),
            'force_margin': round(held.margin, 3), 'holds': held.ok,
            'off_axis_mm': round(held.offset * MM, 3),
            'used': bool(geometry.usable[k])}

    @staticmethod
    def figures_line(f: dict, at: str) -> str:
        seal = ('seals: its rim and the surface inside lie within '
                f'{f["deviation_mm"]:.2f} mm of a plane (the cup gives {f["give_mm"]:.2f})'
                if f['seal'] else f'does not seal: {f["reason"]}')
        force = (f'holds {f["holding_force_n"]:.3f} N against {f["needed_n"]:.3f} N needed, '
                 f'margin {f["force_margin"]:.2f} with the moment of the mass centre '
                 f'{f["off_axis_mm"]:.2f} mm off the cup\'s axis'
                 + ('' if f['holds'] else ': does not hold'))
        used = '' if f['used'] else '; never used by the check'
        return f'  grasp {f["name"]!r}: cup {at}: {seal}; {force}{used}'

    def pick_caption(self, geometry, g: int) -> str:
        return f'cup {self.cup_diameter * MM:g} mm, ' + \
            ('seals' if geometry.seals[g].ok else 'no seal')

    def pick_marks(self, geometry, g: int) -> tuple:
        """Lines to draw on the part at a pick, (points (n, 3) in the part frame, ok): the
        rim where it touches the part, ok where it seals."""
        found = geometry.seals[g]
        return ((found.rim, found.ok),)

    def proposed_widths(self, geometry) -> tuple[float, ...]:
        """Per grasp, the rim's deviation from a plane, m (the comment of a proposal)."""
        return tuple(s.deviation for s in geometry.seals)

    proposal_rule: ClassVar[str] = ('per way the part can lie, the cup on its top where it '
                                    'seals and holds nearest the mass centre')

    def propose(self, part: 'PartGeometry') -> tuple:
        """The cup's proposals (grasp_proposals.propose_suction)."""
        from ..grasp_proposals import propose_suction  # trimesh: loaded when asked
        return propose_suction(part, self)
