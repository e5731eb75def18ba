"""Parallel jaws: the simplified gripper of the paper's figure 8, one of the gripper kinds
(the package's __init__ says what a kind owns). The collision stack (fcl, trimesh: geometry,
grasp_fit) is imported in the methods that build shapes and fits, so that naming a gripper
(config.Setup, the experiment file's schema) loads none of it.

Units: metres; the part frame, or the gripper frame for its shapes.
"""

from dataclasses import dataclass
import math
from typing import ClassVar, TYPE_CHECKING

import numpy as np
from pick_common.errors import InvalidArgument, Limit

from ..grasps import CAPACITOR_GRASPS, Grasp, grasp_point, GraspPose, PARALLEL_LIMIT, unit
from .base import Grip, Key, Kind

if TYPE_CHECKING:
    from pick_common.parts.geometry import PartGeometry

    from ..geometry import BoxShape, CylinderShape, Shape

JAW_OPENING = Limit(0.0, 1.0, low_open=True)     # a jaws' grasp's opening U, m
MM = 1000.0         # mm per m, for a part sheet


@dataclass(frozen=True)
class Jaws(Kind):
    """The simplified parallel-jaw gripper (paper figure 8).

    body_diameter D and body_length of the body cylinder; jaw_height V and jaw_depth W of the
    jaws' workspace cuboid (its width U is the grasp's jaw opening). m.

    finger_clearance: how far above the bottom of the grasped part the fingertips stop, m. The
    fingers close around the part as a parallel gripper's do: the jaws' cuboid reaches from the
    fingertips up, and the body sits on top of it. The grasped part's bottom is the lowest
    point, along the grasp's up axis, of the collision primitive that holds the grasp point
    (the body of a built-in part). At 0 the fingertips would be level with the floor under
    every resting part (and below it by the physics' overlap); pick programs stop them short
    of the surface. The fingertips never go above the grasp point nor deeper than V below it.
    """

    kind: ClassVar[str] = 'jaws'
    description: ClassVar[str] = 'parallel jaws'
    written: ClassVar[type] = GraspPose
    default_grasps: ClassVar[tuple] = CAPACITOR_GRASPS     # grasps a file may leave out
    KEYS: ClassVar[tuple[Key, ...]] = (
        Key('body_diameter', 'mm', Limit(0.0, 1.0, low_open=True), 'D, m',
            "assumed (the paper's figure 8 names D without a value)"),
        Key('body_length', 'mm', Limit(0.0, 2.0, low_open=True), 'm'),
        Key('jaw_height', 'mm', Limit(0.0, 1.0, low_open=True), 'V, m',
            "assumed (the paper's figure 8 names V without a value)"),
        Key('jaw_depth', 'mm', Limit(0.0, 1.0, low_open=True), 'W, m',
            "assumed (the paper's figure 8 names W without a value)"),
        Key('finger_clearance', 'mm', Limit(0.0, 1.0),
            "height of the fingertips above the grasped part's bottom, m"),
    )

    body_diameter: float = 0.020
    body_length: float = 0.060
    jaw_height: float = 0.015
    jaw_depth: float = 0.006
    finger_clearance: float = 0.001

    @property
    def size(self) -> tuple[float, ...]:
        """What "smaller" means when jaws are compared: the body's diameter first (what must
        fit between neighbours), then the jaws' depth and height, then the body's length."""
        return self.body_diameter, self.jaw_depth, self.jaw_height, self.body_length

    def check_grasp(self, g, where: str, name: str) -> Grasp:
        """The checked grasp: its closing axis made orthogonal to its up axis."""
        up = unit(f'{where}.up_axis', g.up_axis)
        closing = unit(f'{where}.closing_axis', g.closing_axis)
        angle = math.acos(min(1.0, abs(float(up @ closing))))
        if angle < PARALLEL_LIMIT:
            raise InvalidArgument(f'{where}.closing_axis', g.closing_axis,
                                  f'is parallel to up_axis {g.up_axis} (within '
                                  f'{math.degrees(PARALLEL_LIMIT):g} deg)')
        closing = closing - (closing @ up) * up
        closing /= np.linalg.norm(closing)
        opening = JAW_OPENING.check(f'{where}.jaw_opening', g.jaw_opening)
        return Grasp(name, up, closing, opening, grasp_point(where, g.grasp_point))

    def width(self, grasp: Grasp) -> float:
        return grasp.jaw_opening

    def shapes(self, grasp: Grasp, depth: float) -> 'tuple[BoxShape, CylinderShape]':
        """The jaws' workspace cuboid (U x W x V, z from -depth to V - depth: the fingertips
        `depth` below the grasp point) and the body cylinder (diameter D, from V - depth up
        body_length), in the gripper frame: origin at the grasp point (the point the jaws
        close on), x along the closing direction, z up the gripper."""
        import fcl

        from ..geometry import BoxShape, CylinderShape
        v, length, opening = self.jaw_height, self.body_length, grasp.jaw_opening
        jaws = BoxShape(np.eye(3), np.array([0.0, 0.0, v / 2 - depth]),
                        fcl.Box(opening, self.jaw_depth, v),
                        np.array([opening / 2, self.jaw_depth / 2, v / 2]))
        body = CylinderShape(np.eye(3), np.array([0.0, 0.0, v - depth + length / 2]),
                             fcl.Cylinder(self.body_diameter / 2, length),
                             self.body_diameter / 2, length / 2)
        return jaws, body

    def grip(self, part: 'PartGeometry', written: tuple, grasps: tuple[Grasp, ...],
             tilts: np.ndarray, part_shapes: 'tuple[Shape, ...]') -> Grip:
        """Raises InvalidArgument for a grasp whose jaws cannot close on the part (grasp_fit)."""
        from ..grasp_fit import check_grasps_fit
        fits = check_grasps_fit(part, written)
        depths = tuple(self._finger_depth(part, g) for g in grasps)
        return Grip(tilts=tilts, fits=fits, finger_depths=depths,
                    free_axes=np.stack([_free_axis(part, part_shapes, g) for g in grasps]),
                    shapes=tuple(self.shapes(g, d) for g, d in zip(grasps, depths, strict=True)),
                    usable=np.ones(len(grasps), dtype=bool))

    def _finger_depth(self, part: 'PartGeometry', grasp: Grasp) -> float:
        """How far below the grasp point the fingertips go, m: to `finger_clearance` above the
        bottom of the body the jaws close on (grasp_fit.body_bottom), between the grasp point
        and V below it."""
        from ..grasp_fit import body_bottom
        bottom = body_bottom(part, grasp.point, grasp.closing, grasp.up, self.jaw_depth,
                             self.jaw_height + self.finger_clearance)
        return min(self.jaw_height, max(0.0, bottom - self.finger_clearance))

    def approach(self, x: np.ndarray, rotations: np.ndarray, up: np.ndarray) -> np.ndarray:
        """(n, 3): the most vertical axis at right angles to the closing axes x (n, 3), in the
        container frame; a vertical closing axis (no approach within any cone) takes the
        grasp's up axis, `up` (n, 3) in the frames of parts at `rotations` (n, 3, 3)."""
        z = np.array([0.0, 0.0, 1.0]) - x[:, 2:3] * x
        norm = np.linalg.norm(z, axis=1)
        flat = norm < 1e-9
        z[flat] = np.einsum('nij,nj->ni', rotations[flat], up[flat])
        z /= np.linalg.norm(z, axis=1, keepdims=True)
        return z

    # ---- what a part sheet says of it (mm: MM m)
    def account(self) -> list[str]:
        """Its line on a part sheet: none (the jaws are said in the file's keys)."""
        return []

    def figures(self, geometry, k: int, written: GraspPose) -> dict:
        """What the check computed of grasp k before any scene (`geometry`: its
        check_geometry.CheckGeometry), mm: what the jaws close on and whether they turn on a
        round body."""
        fit, axis = geometry.grasp_fits[k], geometry.free_axes[k]
        return {
            'gripper': self.kind, 'closing_axis': [float(v) for v in written.closing_axis],
            'jaw_opening_mm': round(written.jaw_opening * MM, 3),
            'problem': fit.problem(), 'closes_on_mm': round(fit.width * MM, 3),
            'span_mm': None if fit.span is None else [round(-fit.span[0] * MM, 3),
                                                      round(fit.span[1] * MM, 3)],
            'round_axis': [round(float(v), 3) for v in axis] if axis.any() else None}

    @staticmethod
    def figures_line(f: dict, at: str) -> str:
        what = f['problem'] or (f'closes on {f["closes_on_mm"]:.2f} mm of part '
                                f'({f["span_mm"][0]:.2f} and {f["span_mm"][1]:.2f} mm either '
                                'side of the grasp point)')
        roll = (f'; round there, so it grips at any roll about {f["round_axis"]}'
                if f['round_axis'] else '; fixed to the part (not across a round body)')
        return (f'  grasp {f["name"]!r}: jaws open {f["jaw_opening_mm"]:.2f} mm {at}, closing '
                f'{f["closing_axis"]}: {what}{roll}')

    def pick_caption(self, geometry, g: int) -> str:
        return (f'jaws {geometry.grasps[g].jaw_opening * MM:g} mm, fingertips '
                f'{geometry.finger_depths[g] * MM:.1f} mm below the point')

    def pick_marks(self, geometry, g: int) -> tuple:
        """Lines to draw on the part at a pick, (points (n, 3) in the part frame, ok): none."""
        return ()

    def proposed_widths(self, geometry) -> tuple[float, ...]:
        """Per grasp, the width its jaws close on, m (the comment of a proposal)."""
        return tuple(fit.width for fit in geometry.grasp_fits)

    @property
    def proposal_rule(self) -> str:
        from ..grasp_proposals import JAW_MARGIN  # trimesh: loaded when asked
        return ('across opposed faces at the mass centre and round bodies level with it (or, '
                'with neither, across its principal axes), jaws '
                f'{JAW_MARGIN * MM:g} mm wider than the part each side')

    def propose(self, part: 'PartGeometry') -> tuple:
        """The jaws' proposals (grasp_proposals.propose); InvalidArgument naming `grasps`
        when there is none."""
        from ..grasp_proposals import propose  # trimesh: loaded when asked
        found = propose(part)
        if not found:
            raise InvalidArgument('grasps', 'auto', 'found no grasp: the part has no opposed '
                                  'faces and no round body (at its mass centre or off it); '
                                  'write its grasps')
        return found


def _free_axis(part: 'PartGeometry', shapes: 'tuple[Shape, ...]', grasp: Grasp) -> np.ndarray:
    """The axis of a cylinder of the part that holds the grasp point on its axis and that the
    closing axis crosses at a right angle or runs along (the jaws on its ends), or zeros. A
    built-in model's cylinders are its primitives; a mesh's are found from its surface
    (`grasp_fit.round_axis`)."""
    from ..geometry import contains, CylinderShape
    from ..grasp_fit import round_axis
    if part.spec.model == 'mesh':
        return round_axis(part, grasp.point, grasp.closing, grasp.up)
    for shape in shapes:
        axis = shape.rotation[:, 2]
        off = grasp.point - shape.center
        along = abs(float(axis @ grasp.closing))      # across the body, or on its two ends
        if (isinstance(shape, CylinderShape) and contains(shape, grasp.point)
                and (along < 1e-6 or along > 1 - 1e-9)
                and np.linalg.norm(off - (off @ axis) * axis) < 1e-9):
            return axis.copy()
    return np.zeros(3)
