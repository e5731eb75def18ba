"""What a check answers: the stage each part stopped at, its result, the report of one check,
and the checks of the poses and targets a check is given. Shared by the validator
(`validity`), its pair stages (`pairs`) and the reference (`naive`).

Poses are (N, 7) float64, xyz m + xyzw unit quaternion, in the container frame (origin at the
centre of the inner floor, +Z up).
"""

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
import math

import numpy as np
from pick_common.errors import InvalidArgument, UnknownPart

# The stage a check stopped at (the one that failed), or VALID; values as in PartValidity.msg.
STAGE_NONE, STAGE_CANDIDACY, STAGE_PLACEABILITY, STAGE_CONTAINER, STAGE_NEIGHBOUR, \
    STAGE_VALID, STAGE_OUTSIDE = range(7)
# The stages a part in the container passed, in order (OUTSIDE is not among them: its part
# was not checked).
ORDER = (STAGE_CANDIDACY, STAGE_PLACEABILITY, STAGE_CONTAINER, STAGE_NEIGHBOUR, STAGE_VALID)
CENTRE_TOLERANCE = 0.001      # m beyond the inner walls and floor a part's centre may lie
TIE = 1e-6                    # rad: grasps whose up axes are this near in angle tie (acos near 0
#                               is only good to about 1e-8 rad)
QUATERNION_TOLERANCE = 1e-3   # |norm - 1| accepted (and normalised); larger is refused
MAX_PARTS = 20000
MAX_POSITION = 10.0           # m from the instance frame; a container is at most 2 m wide


@dataclass
class PartResult:
    """One part's check. gripper_pose: (7,) xyz + xyzw in the container frame at the valid tilt
    nearest 0, None unless valid. Angles in rad, jaw_opening in m."""

    part_id: int
    stage: int
    reason: str
    grasp_index: int = -1
    candidacy_angle: float = math.nan
    gripper_pose: np.ndarray | None = None
    jaw_opening: float = 0.0
    valid_tilts: tuple[float, ...] = ()
    regrasp: bool = False       # placed only after a regrasp on the station

    @property
    def valid(self) -> bool:
        return self.stage == STAGE_VALID

    def key(self) -> tuple:
        """What two checks must agree on."""
        return self.part_id, self.stage, self.grasp_index, self.valid_tilts, self.regrasp


@dataclass
class Report:
    """The results of one check, in the order of the targets, with counts per stage (a part
    outside the container counts as checked and in none of the stages)."""

    results: list[PartResult]
    neighbour_check: bool
    queries: int = 0            # FCL narrowphase queries issued
    wall_time: float = 0.0      # s
    counts: dict[str, int] = field(default_factory=dict)

    def __post_init__(self) -> None:
        passed = [ORDER.index(r.stage) if r.stage in ORDER else -1 for r in self.results]
        self.counts = {
            'checked': len(passed),
            'outside': sum(r.stage == STAGE_OUTSIDE for r in self.results),
            'candidates': sum(p > 0 for p in passed),
            'placeable': sum(p > 1 for p in passed),
            'container_free': sum(p > 2 for p in passed),
            'valid': sum(p == 4 for p in passed)}


def check_poses(ids: Sequence[int], poses: np.ndarray) -> np.ndarray:
    """Refuse NaN/inf and non-unit quaternions (beyond float noise, which is normalised) and
    duplicate ids; return the poses with unit quaternions. A NaN must never reach FCL: it
    reports no collision for a NaN transform."""
    poses = np.asarray(poses, dtype=np.float64)
    if poses.ndim != 2 or poses.shape[1] != 7 or len(poses) != len(ids):
        raise InvalidArgument('parts', poses.shape, f'must be ({len(ids)}, 7) poses')
    if not len(ids):
        raise InvalidArgument('parts', [], 'is empty: send every part of the container')
    if len(ids) > MAX_PARTS:
        raise InvalidArgument('parts', len(ids), f'holds more than {MAX_PARTS} parts')
    bad = np.flatnonzero(~np.isfinite(poses).all(axis=1))
    if len(bad):
        i = int(bad[0])
        raise InvalidArgument(f'parts[{i}] (id {ids[i]}).pose', poses[i].tolist(),
                              'must be finite (no NaN or inf)')
    bad = np.flatnonzero((np.abs(poses[:, :3]) > MAX_POSITION).any(axis=1))
    if len(bad):     # found by fuzzing: 1e154 overflowed in the neighbour search
        i = int(bad[0])
        raise InvalidArgument(f'parts[{i}] (id {ids[i]}).pose.position', poses[i, :3].tolist(),
                              f'must be within {MAX_POSITION:g} m of the instance frame')
    norms = np.linalg.norm(poses[:, 3:], axis=1)
    bad = np.flatnonzero(np.abs(norms - 1.0) > QUATERNION_TOLERANCE)
    if len(bad):
        i = int(bad[0])
        raise InvalidArgument(f'parts[{i}] (id {ids[i]}).pose.orientation', poses[i, 3:].tolist(),
                              f'has norm {norms[i]:.6g}; must be a unit quaternion (within '
                              f'{QUATERNION_TOLERANCE:g}, which is normalised)')
    if len(set(ids)) != len(ids):
        seen = set()
        dup = next(i for i in ids if i in seen or seen.add(i))
        raise InvalidArgument('parts', dup, 'id appears twice')
    out = poses.copy()
    out[:, 3:] /= norms[:, None]
    return out


def target_rows(ids: Sequence[int], targets: Iterable[int] | None) -> list[int]:
    """The rows of `ids` to check: those of `targets` in their order (all when None).
    Raises UnknownPart for a target that is not among the ids."""
    index = {pid: i for i, pid in enumerate(ids)}
    if targets is None:
        return list(range(len(ids)))
    rows = []
    for pid in targets:
        if pid not in index:
            raise UnknownPart(f'target_ids: {pid} is not among the parts sent')
        rows.append(index[pid])
    return rows
