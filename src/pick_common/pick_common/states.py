"""The state types a world reports and its callers read: a snapshot of the parts, how a physics
operation ended, and its progress. Shared by the world, its conversions and the experiments.

Pure: numpy only. Poses are (N, 7) float64, xyz in metres then an xyzw unit quaternion.
"""

from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Progress:
    """Sent once per settle check. phase: 'dropping', 'vibrating' or 'settling'.

    sim_time: s since the operation started. parts_moving: parts not at rest over the settle
    window. max_displacement: largest position change of a part over the window, m.
    """

    phase: str
    sim_time: float
    parts_moving: int
    max_displacement: float


@dataclass
class SettleReport:
    """How an operation ended. Times in s; ids of parts still moving and outside containers."""

    settled: bool
    sim_time: float
    wall_time: float
    steps: int
    unsettled_ids: list[int] = field(default_factory=list)
    escaped_ids: list[int] = field(default_factory=list)
    canceled: bool = False


@dataclass(frozen=True, eq=False)
class PartStates:
    """A snapshot. ids, instances: (N,) int64; poses: (N, 7) float64 in each part's instance
    frame; inside: (N,) bool, the part's origin is in its container; sim_time: s."""

    ids: np.ndarray
    instances: np.ndarray
    poses: np.ndarray
    inside: np.ndarray
    sim_time: float

    def select(self, instances: Iterable[int]) -> 'PartStates':
        """The parts of the given instances only."""
        return self.masked(np.isin(self.instances, np.fromiter(instances, dtype=np.int64)))

    def masked(self, mask: np.ndarray) -> 'PartStates':
        """The parts where `mask` (N,) is true."""
        return PartStates(self.ids[mask], self.instances[mask], self.poses[mask],
                          self.inside[mask], self.sim_time)


def rotate(quaternions: np.ndarray, vector: np.ndarray) -> np.ndarray:
    """Rotate one vector (3,) by each quaternion (n, 4) xyzw; returns (n, 3)."""
    xyz, w = quaternions[:, :3], quaternions[:, 3:4]
    t = 2.0 * np.cross(xyz, vector)
    return vector + w * t + np.cross(xyz, t)
