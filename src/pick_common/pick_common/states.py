"""The state types a world reports and its callers read: a snapshot of the parts, how a physics
operation ended, and its progress. Shared by the world, its conversions and the experiments.

Pure: numpy only. Poses are (N, 7) float64, xyz in metres then an xyzw unit quaternion.
"""

from collections.abc import Callable, Iterable
from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class TrayMotion:
    """The motion a vibration commanded and the one the tray delivered: peak displacement
    (m) and peak velocity (m/s) of the sinusoid at the vibration's frequency, the delivered
    ones fitted to the tray's states after each physics step. With several trays, the one
    that tracked its command worst."""

    amplitude: float
    delivered_amplitude: float
    peak_velocity: float
    delivered_peak_velocity: float

    @property
    def error(self) -> float:
        """The larger relative error of the delivered amplitude and peak velocity (0.05: 5 %)."""
        return max(abs(self.delivered_amplitude / self.amplitude - 1.0),
                   abs(self.delivered_peak_velocity / self.peak_velocity - 1.0))


@dataclass(frozen=True)
class Progress:
    """Made at each settle check (the world node sends one at most every FEEDBACK_PERIOD
    of wall time). phase: 'dropping', 'vibrating' or 'settling'.

    sim_time: s since the operation started. parts_moving: parts not at rest over the settle
    window. max_displacement: largest position change of a part over the window, m. tray: while
    vibrating, the motion the tray delivered so far (None otherwise), fitted to every step so far
    when read (`delivered`): read it at the check, as the world node does for the one check in
    many it sends, and no other check pays for the fit.
    """

    phase: str
    sim_time: float
    parts_moving: int
    max_displacement: float
    delivered: Callable[[], TrayMotion | None] | None = field(default=None, repr=False)

    @property
    def tray(self) -> TrayMotion | None:
        return None if self.delivered is None else self.delivered()


@dataclass
class SettleReport:
    """How an operation ended and the health of its physics. Times in s.

    unsettled_ids: parts still moving at the end. escaped_ids: parts whose centre is outside
    their container's inner volume; of them, tunnelled_ids are in or under the floor or inside
    a wall (a physics fault: solid bodies passed through each other), and the rest spilled over
    a wall. thrown_ids: parts that moved faster than gravity and the tray can move them
    (stepping.speed_limit): a physics fault (the solver gave them energy), wherever they ended.
    max_penetration: the deepest overlap of two bodies at the end, m. max_speed: the fastest
    any part's centre moved during the operation while above its container's floor, m/s.
    tray: for a vibration, the motion the trays delivered (TrayMotion), else None.
    landed_ids: of the spilled parts, those that came down on the cell's table beside their
    container (containers.beside) and were taken out of the simulation; landed_at: where each
    landed, in its instance frame, m (on the table, z = -floor_thickness; found within one
    settle check of landing); landed_speeds: how fast each was moving then, m/s.
    """

    settled: bool
    sim_time: float
    wall_time: float
    steps: int
    unsettled_ids: list[int] = field(default_factory=list)
    escaped_ids: list[int] = field(default_factory=list)
    canceled: bool = False
    tunnelled_ids: list[int] = field(default_factory=list)
    max_penetration: float = 0.0
    tray: TrayMotion | None = None
    thrown_ids: list[int] = field(default_factory=list)
    max_speed: float = 0.0
    landed_ids: list[int] = field(default_factory=list)
    landed_at: list[tuple[float, float, float]] = field(default_factory=list)
    landed_speeds: list[float] = field(default_factory=list)

    @property
    def spilled_ids(self) -> list[int]:
        """Parts outside their container that neither tunnelled nor were thrown: they went over
        a wall."""
        faults = set(self.tunnelled_ids) | set(self.thrown_ids)
        return [i for i in self.escaped_ids if i not in faults]


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


def quaternion_angles(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Rotation angle between quaternion pairs (n, 4) and (n, 4) xyzw, rad."""
    dot = np.abs(np.einsum('ij,ij->i', a, b))
    return 2.0 * np.arccos(np.clip(dot, 0.0, 1.0))


def perpendicular(up: np.ndarray) -> np.ndarray:
    """A unit vector at right angles to `up` (a unit vector): the frame axis least along it,
    made square."""
    axis = np.eye(3)[int(np.argmin(np.abs(up)))]
    axis = axis - (axis @ up) * up
    return axis / np.linalg.norm(axis)


def rotate(quaternions: np.ndarray, vector: np.ndarray) -> np.ndarray:
    """Rotate one vector (3,) by each quaternion (n, 4) xyzw; returns (n, 3)."""
    xyz, w = quaternions[:, :3], quaternions[:, 3:4]
    t = 2.0 * np.cross(xyz, vector)
    return vector + w * t + np.cross(xyz, t)


def quaternion_multiply(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The products a * b (n, 4) of quaternions (n, 4) and one (4,) or (n, 4), xyzw: rotate by
    b, then by a."""
    b = np.broadcast_to(b, a.shape)
    ax, ay, az, aw = a.T
    bx, by, bz, bw = b.T
    return np.stack([aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw,
                     aw * bw - ax * bx - ay * by - az * bz], axis=1)
