"""Stepping the physics until the parts rest: the settle criterion and its loop.

A part rests when, over the settle window, its position changed by at most the linear tolerance
and its orientation by at most the angular tolerance; the scene is settled when at most the
moving fraction of its parts do not rest. Bullet's sleeping is not used for this: it does not
trigger for a jittering pile, and it wakes a whole touching group at once. Parts that rest may
be frozen instead (freezing.py), which this loop does when given a Freezer.
"""

from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
import math
import time

import numpy as np
from pick_common import containers
from pick_common.containers import ContainerSpec
from pick_common.errors import PhysicsFault
from pick_common.parts.geometry import PartGeometry
from pick_common.states import Progress, quaternion_angles

from .config import GRAVITY, PhysicsConfig
from .engine import Engine
from .freezing import Freezer

ProgressCallback = Callable[[Progress], bool]


def speed_limit(container: ContainerSpec, part: PartGeometry,
                tray_speed: float = 0.0) -> float:
    """The fastest gravity and the tray can move a part's centre, m/s: a free fall from the
    highest a part can be and still count as in its container (twice the walls' height,
    containers.inside) or the drop height parts arrive from, whichever is higher, plus a
    part's bounding diameter (where a drop's next layer spawns) to the floor's underside, plus
    twice the tray's peak speed (a bounce off a moving wall). A part faster than this got its
    energy from the solver (world README, "Thrown parts")."""
    height = (max(2.0 * container.inner_size[2], containers.drop_height(container))
              + 2.0 * part.radius + container.floor_thickness)
    return math.sqrt(2.0 * GRAVITY * height) + 2.0 * tray_speed


@dataclass(frozen=True)
class Outcome:
    """How a run of steps ended: settled (or, without a stop at rest, not canceled), canceled
    by the progress callback, steps taken, wall time (s), the ids still moving and each part's
    peak speed over the run (m/s of its centre of mass, read after every step while the part
    was above `floor`, one per part), and the parts that landed beside their container (part
    id: its body's position in the world frame, m, and its speed, m/s, at the check that
    found it; parked there, `step`)."""

    settled: bool
    canceled: bool
    steps: int
    wall_time: float
    moving_ids: list[int]
    peak_speeds: list[float]
    landed: dict[int, tuple[np.ndarray, float]] = field(default_factory=dict)


def raise_peak_speeds(engine: Engine, bodies: Sequence[int], floor: float,
                      peaks: list[float], indices: Sequence[int]) -> None:
    """Raise peaks[i] to body i's linear speed (m/s, of its centre of mass) where that is
    higher and the body's origin is at or above `floor` (world z, m), for each i of `indices`
    (a frozen part does not move): a part falling beside or under its container gains speed
    until it is found on the table (`landed`) or under the floor (tunnelled). The position is
    read only for a speed that would raise the peak, which most steps' speeds do not."""
    for i in indices:
        b = bodies[i]
        speed = engine.speed(b)
        if speed > peaks[i] and engine.position(b)[2] >= floor:
            peaks[i] = speed


def landed(container: ContainerSpec, origins: np.ndarray, reach: float,
           poses: np.ndarray) -> np.ndarray:
    """Which bodies' poses (N, 7, world frame), of parts whose instances' origins are
    `origins` (N, 3), have come down on the cell's table beside their container
    (containers.beside, within `reach`, the part's bounding radius, of the table): `step`'s
    `beside` with its first three arguments given."""
    return containers.beside(container, poses[:, :3] - origins, reach)


def step(engine: Engine, ids: Sequence[int], bodies: Sequence[int], cfg: PhysicsConfig,
         phase: str, duration: float, progress: ProgressCallback | None,
         before_step: Callable[[], None] | None = None,
         stop_when_settled: bool = True, floor: float = 0.0,
         freezer: Freezer | None = None,
         beside: Callable[[np.ndarray], np.ndarray] | None = None) -> Outcome:
    """Step for up to `duration` s of simulated time, checking rest every check period; the
    parts are `ids` with their `bodies`. progress() is called once per check and cancels by
    returning False. With a `freezer`, it freezes and wakes parts at every check
    (Freezer.check). Every part's speed is read after every step (a solver blow-up lasts a
    step or two: a check period would miss it). `beside` (the bodies' poses (N, 7) in the
    world frame -> (N,) bool) tells the parts that have come down on the cell's table beside
    their container: at the check that finds one, its position and speed are kept and it is
    parked (Engine.park: static where it is), so no part falls on without end. Raises
    PhysicsFault naming the parts whose poses became non-finite."""
    dt = cfg.time_step
    per_check = max(1, int(round(cfg.settle_check_period / dt)))
    window = max(1, int(round(cfg.settle_window / cfg.settle_check_period)))
    total_steps = max(1, int(math.ceil(duration / dt - 1e-9)))
    bodies = list(bodies)
    tolerated = int(cfg.settle_moving_fraction * len(ids))
    history: deque[np.ndarray] = deque(maxlen=window + 1)
    history.append(engine.poses(bodies))
    awake = range(len(bodies))     # indices of the bodies not frozen
    if freezer is not None:
        freezer.check(bodies, history[0], 0.0)     # where the parts start from
        awake = freezer.thawed(bodies)
    start = time.perf_counter()
    steps = checked = 0
    moving = np.ones(len(ids), dtype=bool)
    peaks = [0.0] * len(ids)
    found: dict[int, tuple[np.ndarray, float]] = {}     # the parts that landed
    parked = np.zeros(len(ids), dtype=bool)
    settled = canceled = False
    while steps < total_steps:
        for _ in range(min(per_check, total_steps - steps)):
            if before_step is not None:
                before_step()
            engine.step()
            steps += 1
            raise_peak_speeds(engine, bodies, floor, peaks, awake)
        poses = engine.poses(bodies)
        if not np.isfinite(poses).all():
            bad = [ids[i] for i in np.flatnonzero(~np.isfinite(poses).all(axis=1))]
            raise PhysicsFault(f'parts {bad[:10]} got non-finite poses after '
                               f'{steps * dt:.3f} s of {phase}; the scene was reset')
        if beside is not None and len(ids):
            for i in np.flatnonzero(beside(poses) & ~parked):
                found[ids[i]] = (poses[i, :3].copy(), engine.speed(bodies[i]))
                engine.park(bodies[i])
                parked[i] = True
        history.append(poses)
        old = history[0]
        shift = np.linalg.norm(poses[:, :3] - old[:, :3], axis=1)
        turn = quaternion_angles(poses[:, 3:], old[:, 3:])
        moving = (shift > cfg.settle_linear_tolerance) | (turn > cfg.settle_angular_tolerance)
        moving &= ~parked           # a part that landed beside its container is out
        full = len(history) == history.maxlen
        if progress is not None and not progress(Progress(
                phase, steps * dt, int(moving.sum()) if full else len(ids),
                float(shift.max()) if len(ids) else 0.0)):
            canceled = True
            break
        if stop_when_settled and full and moving.sum() <= tolerated:
            settled = True
            break
        if freezer is not None:
            freezer.check(bodies, poses, (steps - checked) * dt)
            checked = steps
            awake = freezer.thawed(bodies)
    wall = time.perf_counter() - start
    return Outcome(settled, canceled, steps, wall, [ids[i] for i in np.flatnonzero(moving)],
                   peaks, found)
