"""The staged validity check (paper section 4.1, figure 3), with python-fcl.

Per part, in order, stopping at the first stage that fails:
0. location: a part whose centre is not in the container (beside it, under its floor, or
   more than `rim_tolerance` above its rim) is answered OUTSIDE and not checked;
1. candidacy: a grasp pose's up axis within `tolerance` of world +Z (the nearest is chosen),
   with at least one wrist tilt whose approach lies within `approach_cone` of world +Z;
2. placeability (figure 6): tilts at which the gripper, holding the part as it picked it,
   stays clear of the placing surface once the pair is turned to the part's place orientation;
3. container: of those, tilts at which the gripper clears the container's walls and floor;
4. neighbours: of those, tilts at which the gripper clears every other part (skipped for the
   static bin analysis). A part with a tilt left is valid.

The gripper closes along the grasp's closing axis as the part lies (x), and its axis (z) is
the most vertical one perpendicular to it, turned by the wrist tilt about x; its origin is at
the grasp point. Jaws that close across a round body (the grasp point on the axis of a cylinder
of the part, the closing axis across that axis) grip it at any angle about the axis, as a cell
does, whose camera cannot see a cylinder's roll: the grasp is turned about the axis to bring
its up axis nearest world +Z before the stages (`Validator.free_axes`); a capacitor lying on
its side is then approached from above whatever its roll. So the part-in-gripper pose, and
with it placeability, depends on how the part lies: the same grasp of a part tilted one way
can be placed and tilted the other way not.
Container and neighbour stages decide what exact bounds can decide and ask FCL the rest
(`pairs`); `naive.naive_check` asks FCL everything, with no broadphase and no caching, and must
give identical results. What a check answers lives in `results`.

Poses are (N, 7) float64, xyz m + xyzw unit quaternion, in the container frame (origin at the
centre of the inner floor, +Z up).
"""


from collections.abc import Iterable, Sequence
from dataclasses import replace
import math
import time

import numpy as np
from pick_common import containers
from pick_common.containers import ContainerSpec
from pick_common.parts.geometry import PartGeometry

from .check_geometry import build_geometry
from .config import Setup
from .geometry import matrix_to_quaternion, place, quaternions_to_matrices, support, turn_onto
from .pairs import Pairs
from .results import (
    CENTRE_TOLERANCE,
    check_poses,
    PartResult,
    Report,
    STAGE_CANDIDACY,
    STAGE_CONTAINER,
    STAGE_NEIGHBOUR,
    STAGE_OUTSIDE,
    STAGE_PLACEABILITY,
    STAGE_VALID,
    target_rows,
    TIE,
)


def _deg(rad: float) -> str:
    return f'{math.degrees(rad):.1f} deg'


class Validator:
    """The checks for one part model, gripper, set of grasps, placement and settings.

    Build once and reuse: the geometry every check shares (check_geometry.CheckGeometry: part
    and gripper shapes, how deep each grasp's fingers reach, the round bodies a grasp may turn
    about) is computed here, never per part, and read as `validator.geometry`. Only the
    Validator writes a part's stage and reason.
    """

    def __init__(self, setup: Setup, part: PartGeometry | None = None) -> None:
        """`part`: the geometry of setup.part when the caller has built it already (the
        world's); built here otherwise. Raises InvalidArgument for a bad setup, a grasp whose
        jaws cannot close on the part among them (grasp_fit)."""
        self.setup = setup
        self.geometry = build_geometry(setup, part)
        if setup.config.regrasp_station:
            self.geometry = replace(self.geometry, station_ok=self._station_ok())

    def turned(self, rotations: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """For parts at rotations (n, 3, 3): each grasp's angle from world +Z (n, G) once
        turned about its free axis to the most vertical, and that turn (n, G), rad (0 for a
        fixed grasp). With w the world +Z in the part frame and u the up axis, a turn t about
        the unit axis a gives the up axis a height of A cos t + B sin t + C, where
        A = w.u - (a.u)(a.w), B = w.(a x u), C = (a.u)(a.w): largest at t = atan2(B, A)."""
        ups = np.stack([g.up for g in self.geometry.grasps])                     # (G, 3)
        w = rotations[:, 2, :]                                          # (n, 3)
        a = self.geometry.free_axes
        au = np.einsum('gk,gk->g', a, ups)
        aw = w @ a.T                                                    # (n, G)
        big_a = w @ ups.T - au * aw
        big_b = w @ np.cross(a, ups).T
        free = np.linalg.norm(a, axis=1) > 0
        turn = np.where(free, np.arctan2(big_b, big_a), 0.0)
        height = np.where(free, np.hypot(big_a, big_b) + au * aw, w @ ups.T)
        return np.arccos(np.clip(height, -1.0, 1.0)), turn

    def approach_frames(self, rotations: np.ndarray, grasp_index: np.ndarray,
                        turns: np.ndarray | None = None) -> np.ndarray:
        """The gripper's rotations (n, T, 3, 3) for parts at rotations (n, 3, 3) held with the
        grasps `grasp_index` (n,), each grasp turned about its free axis as the check turns it
        (gripper_frames of the turned part). turns: `turned`'s, when the caller has them."""
        if turns is None:
            _, turns = self.turned(rotations)
        turn = turns[np.arange(len(rotations)), grasp_index]
        return self.gripper_frames(self._grip_rotations(rotations, grasp_index, turn),
                                   grasp_index)

    def _grip_rotations(self, rotations: np.ndarray, grasp_index: np.ndarray,
                        turn: np.ndarray) -> np.ndarray:
        """The part rotations (n, 3, 3) as the gripper takes them: turned by `turn` (n,) about
        the free axis of each part's grasp (Rodrigues)."""
        a = self.geometry.free_axes[grasp_index]                                 # (n, 3)
        k = np.zeros((len(a), 3, 3))
        k[:, 0, 1], k[:, 0, 2], k[:, 1, 2] = -a[:, 2], a[:, 1], -a[:, 0]
        k -= np.swapaxes(k, 1, 2)
        s, c = np.sin(turn)[:, None, None], np.cos(turn)[:, None, None]
        return rotations @ (np.eye(3) + s * k + (1.0 - c) * (k @ k))

    def gripper_frames(self, rotations: np.ndarray, grasp_index: np.ndarray) -> np.ndarray:
        """The gripper's rotations in the container frame, (n, T, 3, 3), for parts at
        rotations (n, 3, 3) held with the grasps `grasp_index` (n,), at every tilt: x along the
        part's closing axis, z the most vertical axis perpendicular to it, turned by the tilt
        about x (the gripper's kind says which is its axis: `approach`)."""
        geo = self.geometry
        closing = np.stack([g.closing for g in geo.grasps])[grasp_index]
        up = np.stack([g.up for g in geo.grasps])[grasp_index]
        x = np.einsum('nij,nj->ni', rotations, closing)
        z = geo.gripper.approach(x, rotations, up)
        base = np.stack([x, np.cross(z, x), z], axis=-1)
        return base[:, None] @ self.geometry.tilt_rotations[None]

    def _approachable(self, frames: np.ndarray) -> np.ndarray:
        """(n, T) bool: the gripper's axis lies within the approach cone of world +Z."""
        return frames[..., 2, 2] >= math.cos(self.geometry.config.approach_cone) - 1e-12

    def _placeable(self, rotations: np.ndarray, frames: np.ndarray,
                   grasp_index: np.ndarray, axis: np.ndarray | None = None,
                   offset: float | None = None) -> np.ndarray:
        """(n, T) bool: with the part turned to its place orientation, the gripper holding it
        as it picked it stays on the gripper's side of the seating plane. Decided in the part
        frame, where the place orientation only fixes the seating plane: `axis` . x =
        `offset` (the place's; a station placement's when given)."""
        axis = self.geometry.place_axis if axis is None else axis
        offset = self.geometry.seat_offset if offset is None else offset
        n, count = frames.shape[:2]
        relative = (np.swapaxes(rotations, 1, 2)[:, None] @ frames).reshape(-1, 3, 3)
        points = np.stack([g.point for g in self.geometry.grasps])[grasp_index]
        origin = np.repeat(points, count, axis=0)
        clear = np.ones(n * count, dtype=bool)
        for g in np.unique(grasp_index):
            sel = np.repeat(grasp_index == g, count)
            for shape in self.geometry.gripper_shapes[g]:
                r, c = place(shape, relative[sel], origin[sel])
                clear[sel] &= support(shape, r, c, axis) < offset
        return clear.reshape(n, count)

    def _station_ok(self) -> np.ndarray:
        """(P,) bool, per station placement (regrasp.py): the part resting on it, its
        nearest usable grasp within the tolerance picks it at a tilt within the approach cone
        that keeps the gripper clear of the station and places it as required."""
        found = self.geometry.placements
        if not found:
            return np.zeros(0, dtype=bool)
        down = np.array([0.0, 0.0, -1.0])
        rotations = np.stack([turn_onto(p.normal, down) for p in found])
        angles, turns = self.turned(rotations)
        angles = np.where(self.geometry.usable, angles, math.pi)
        best = nearest_grasp(angles, turns)
        frames = self.approach_frames(rotations, best, turns)
        ok = (angles[np.arange(len(found)), best] <= self.geometry.config.tolerance)[:, None] \
            & self._approachable(frames) & self._placeable(rotations, frames, best)
        for k, p in enumerate(found):
            ok[k] &= self._placeable(rotations[k:k + 1], frames[k:k + 1], best[k:k + 1],
                                     p.normal, p.offset)[0]
        return ok.any(axis=1)

    def _put_down(self, rotations: np.ndarray, frames: np.ndarray,
                  grasp_index: np.ndarray) -> np.ndarray:
        """(n, T) bool: the gripper, holding the part as it picked it, can put it down on a
        station placement it can be picked from again (station_ok) without reaching past the
        station's surface."""
        out = np.zeros(frames.shape[:2], dtype=bool)
        for p, ok in zip(self.geometry.placements, self.geometry.station_ok, strict=True):
            if ok:
                out |= self._placeable(rotations, frames, grasp_index, p.normal, p.offset)
        return out

    # ----------------------------------------------------------------------------- check
    def check(self, container: ContainerSpec, ids: Sequence[int], poses: np.ndarray,
              targets: Iterable[int] | None = None, neighbour_check: bool = True) -> Report:
        """Check the target parts (all when None) among `ids`/`poses` (every part in the
        container: the neighbours). Raises InvalidArgument or UnknownPart for bad input."""
        start = time.perf_counter()
        containers.check_container(container)
        ids = [int(i) for i in ids]
        poses = check_poses(ids, poses)
        rows = target_rows(ids, targets)
        rotations = quaternions_to_matrices(poses[:, 3:])
        positions = poses[:, :3]
        results: dict[int, PartResult] = {}
        queries = 0

        # 0. location.
        centres = positions[rows] + rotations[rows] @ self.geometry.part.center
        located = containers.inside(container, centres, CENTRE_TOLERANCE,
                                    self.geometry.config.rim_tolerance)
        for n in np.flatnonzero(~located):
            row = rows[n]
            results[row] = PartResult(ids[row], STAGE_OUTSIDE, _outside_reason(
                container, centres[n], self.geometry.config.rim_tolerance))
        inner = [row for row, ok in zip(rows, located, strict=True) if ok]

        # 1. candidacy, vectorised over targets and grasps (turned on round bodies); a
        # suction grasp that does not seal or hold is never chosen.
        angles, turns = self.turned(rotations[inner])                   # (n, G)
        geo = self.geometry
        unusable = angles[:, ~geo.usable]
        angles = np.where(geo.usable, angles, math.pi)
        best = nearest_grasp(angles, turns)
        frames = self.approach_frames(rotations[inner], best, turns)    # (n, T, 3, 3)
        approach = self._approachable(frames)
        placeable = self._placeable(rotations[inner], frames, best) & approach
        station = np.zeros_like(approach)     # only for parts no tilt places as picked
        if self.geometry.station_ok is not None:
            need = np.flatnonzero(~placeable.any(axis=1) & approach.any(axis=1))
            station[need] = self._put_down(rotations[inner][need], frames[need],
                                           best[need]) & approach[need]
        kept: dict[int, np.ndarray] = {}
        world_frames: dict[int, np.ndarray] = {}
        for n, row in enumerate(inner):
            g, angle = int(best[n]), float(angles[n, best[n]])
            result = PartResult(ids[row], STAGE_CANDIDACY, '', g, angle,
                                jaw_opening=geo.gripper.width(geo.grasps[g]))
            results[row] = result
            if angle > geo.config.tolerance:
                result.grasp_index = -1
                result.reason = (f'no grasp pose within {_deg(geo.config.tolerance)} of +Z: '
                                 f'the nearest, {geo.grasps[g].name!r}, is at {_deg(angle)}')
                if (unusable[n] <= geo.config.tolerance).any():
                    result.reason += self._unusable_near(unusable[n])
                continue
            if not approach[n].any():
                rise = math.asin(min(1.0, abs(float(frames[n, 0, 2, 0]))))
                result.reason = (f'grasp {geo.grasps[g].name!r}: no wrist tilt approaches '
                                 f'within {_deg(geo.config.approach_cone)} of +Z (the '
                                 f'closing axis rises {_deg(rise)})')
                continue
            # 2. placeability of the tilts within the approach cone; with a station, the
            # tilts that put the part down there to be picked again
            if not placeable[n].any() and station[n].any():
                result.regrasp = True
                kept[row] = station[n].copy()
                world_frames[row] = frames[n]
                continue
            if not placeable[n].any():
                result.stage = STAGE_PLACEABILITY
                result.reason = (f'grasp {geo.grasps[g].name!r}: held as it lies, the part '
                                 f'cannot be placed: the gripper hits the placing surface at '
                                 f'each of the {int(approach[n].sum())} tilts within the '
                                 f'approach cone')
                continue
            kept[row] = placeable[n].copy()
            world_frames[row] = frames[n]

        # 3. container, 4. neighbours: vectorised over every (part, tilt) pair left.
        pairs = Pairs(self.geometry, kept, {row: results[row].grasp_index for row in kept},
                      world_frames, rotations, positions)
        hit, asked = pairs.container(container)
        queries += asked
        self._close(pairs, hit, kept, results, STAGE_CONTAINER, 'grasp {name!r}: the gripper '
                    'hits the container at each of the {n} placeable tilts')
        if neighbour_check:
            hit, touched, asked = pairs.neighbours(ids, rotations, positions)
            queries += asked
            self._close(pairs, hit, kept, results, STAGE_NEIGHBOUR, 'grasp {name!r}: the '
                        'gripper hits other parts at each of the {n} remaining tilts', touched)
        for row, mask in kept.items():
            if mask.any():
                self._finish_valid(results[row], mask, world_frames[row], rotations[row],
                                   positions[row])
        return Report([results[row] for row in rows], neighbour_check, queries,
                      time.perf_counter() - start)

    def _unusable_near(self, angles: np.ndarray) -> str:
        """Why the suction grasps within the tolerance (`angles` over the unusable ones, in
        their order) were not used."""
        geo = self.geometry
        return ''.join(
            f'; {geo.grasps[k].name!r} at {_deg(a)} does not '
            + ('seal' if not geo.seals[k].ok else 'hold')
            for k, a in zip(np.flatnonzero(~geo.usable), angles, strict=True)
            if a <= geo.config.tolerance)

    def _close(self, pairs: Pairs, hit: np.ndarray, kept: dict[int, np.ndarray],
               results: dict[int, PartResult], stage: int, why: str,
               touched: dict[int, set[int]] | None = None) -> None:
        """After a pair stage: the tilts it hit (`hit`, over `pairs`) leave `kept`; a part with
        no tilt left stops at `stage`, its reason `why` with the grasp's name and the tilts
        that were left, and the parts its gripper hit (`touched`: row -> part ids)."""
        for q in np.flatnonzero(hit):
            kept[pairs.row[q]][pairs.k[q]] = False
        for row, mask in kept.items():
            result = results[row]
            if result.stage == STAGE_CANDIDACY and not mask.any():
                result.stage = stage
                result.reason = why.format(name=self.geometry.grasps[result.grasp_index].name,
                                           n=int((pairs.row == row).sum()))
                if touched and row in touched:
                    result.reason += f' (parts {sorted(touched[row])})'
        pairs.drop(hit)

    def _finish_valid(self, result: PartResult, mask: np.ndarray, frames: np.ndarray,
                      rotation: np.ndarray, position: np.ndarray) -> None:
        g = result.grasp_index
        valid = np.flatnonzero(mask)
        result.stage = STAGE_VALID
        result.valid_tilts = tuple(float(self.geometry.tilts[k]) for k in valid)
        k = valid[np.abs(self.geometry.tilts[valid]).argmin()]
        origin = position + rotation @ self.geometry.grasps[g].point
        result.gripper_pose = np.concatenate([origin, matrix_to_quaternion(frames[k])])
        result.reason = (f'valid with grasp {self.geometry.grasps[g].name!r} at {len(valid)} of '
                         f'{len(self.geometry.tilts)} tilts'
                         + (', placed after a regrasp on the station' if result.regrasp else ''))


def nearest_grasp(angles: np.ndarray, turns: np.ndarray) -> np.ndarray:
    """Per part (rows of (n, G)), the grasp whose up axis is nearest +Z, and among those as
    near (within TIE, rad: on a round body lying flat, every side grasp turns to vertical)
    the one turned least; then the first."""
    if not len(angles):
        return np.zeros(0, dtype=int)
    near = angles <= angles.min(axis=1, keepdims=True) + TIE
    return np.where(near, np.abs(turns), np.inf).argmin(axis=1)


def _outside_reason(container: ContainerSpec, centre: np.ndarray, rim: float) -> str:
    x, y, z = container.inner_size
    mm = ', '.join(f'{1000 * c:.1f}' for c in centre)
    if centre[2] < -CENTRE_TOLERANCE:
        where = 'below the floor'
    elif abs(centre[0]) > x / 2 + CENTRE_TOLERANCE or abs(centre[1]) > y / 2 + CENTRE_TOLERANCE:
        where = f'beside the container (inner {1000 * x:g} x {1000 * y:g} mm)'
    else:
        where = f'more than {1000 * rim:g} mm (check.rim_tolerance) above its {1000 * z:g} mm rim'
    return f'not in the container: its centre ({mm}) mm lies {where}; not checked'
