"""The hopper that feeds a tray, metering a dose as a flexible feeder's does.

A feed of `count` parts (the shortfall the feeder controller asks for) runs the hopper for
count / rate s, the rate being what the hopper lets out per second: the smart feeding of
Asyril's Asycube (its EF command sets the feeding's duration from the parts on the platform,
falling in proportion to none at the optimum) and of Epson's part feeding (PF_QtyAdjHopperTime:
the time from the parts the hopper supplies in a measured time). While it runs, one part
leaves the outlet every 1 / rate s: at a random point across the outlet, in a random
orientation, its lowest point at the outlet's height (never above it), moving onto the tray
at the hopper's exit speed. Where that place is taken (the pile under the outlet stands at
the outlet, or the part before has not moved on), the part waits for the next tick, and what
the run's time did not let out stays in the hopper: the feed then brings fewer than asked.

The outlet is the tray's feeder zone's edge farther from the tray's centre along x, as wide
as the zone (containers.ContainerSpec). Pure: numpy only; poses as spawning.py's.
"""

from dataclasses import dataclass

import numpy as np
from pick_common import containers
from pick_common.containers import ContainerSpec
from pick_common.parts.geometry import PartGeometry
from pick_common.states import rotate

from .spawning import drop_region, random_quaternions, SPAWN_GAP

TRIES = 8       # points across the outlet tried for one part before it waits for the next tick


@dataclass(frozen=True)
class Outlet:
    """lip: x of the outlet's edge over the tray, m; centre_y, half_width: across it, m;
    inward: +1 or -1, the way along x parts leave it; height: of its lip over the floor, m;
    speed: of the parts leaving it, m/s; rate: parts it lets out per second while it runs."""

    lip: float
    centre_y: float
    half_width: float
    inward: float
    height: float
    speed: float
    rate: float

    @property
    def velocity(self) -> tuple[float, float, float]:
        """A part's velocity as it leaves the outlet, m/s, instance frame."""
        return (self.inward * self.speed, 0.0, 0.0)


def outlet(spec: ContainerSpec, instance: int = 0) -> Outlet:
    """The outlet of a tray's hopper (module docstring). Raises InvalidArgument naming
    `instance` when its container is a bin, which has no feeder."""
    drop_region(spec, 'feeder', instance)
    (cx, cy), (sx, sy) = spec.feeder_zone_center, spec.feeder_zone_size
    inward = 1.0 if cx <= 0.0 else -1.0
    rate, speed = containers.hopper(spec)
    return Outlet(cx - inward * sx / 2.0, cy, sy / 2.0, inward, containers.drop_height(spec),
                  speed, rate)


def release(rng: np.random.Generator, part: PartGeometry, points: np.ndarray, out: Outlet,
            poses: np.ndarray) -> np.ndarray | None:
    """The pose (7,) of the next part leaving the outlet, or None where each of TRIES points
    across it is taken. `points`: the part's convex hull vertices (M, 3) in its frame;
    `poses`: the instance's parts (N, 7). The part lies wholly at or above the outlet's
    height, its bounding sphere's centre one radius inside the lip. A place is taken by a
    part that reaches above that height (the pile under the outlet stands at it, or a part
    just let out) and whose sphere comes within SPAWN_GAP of the new part's across: the
    spheres' rule of a drop's spawn (spawning.spawn_poses), with the parts wholly below the
    outlet left out, since they cannot touch a part above it."""
    r = part.radius + SPAWN_GAP
    slack = max(out.half_width - r, 0.0)
    up = [p[:2] + rotate(p[None, 3:], part.center)[0, :2] for p in poses
          if p[2] + rotate(p[None, 3:], points)[:, 2].max() > out.height]
    quats = random_quaternions(rng, TRIES)
    across = out.centre_y + rng.uniform(-slack, slack, TRIES)
    for q, y in zip(quats, across, strict=True):
        offset = rotate(q[None], part.center)[0]
        lowest = rotate(q[None], points)[:, 2].min()     # the points by the one turn
        centre = np.array([out.lip + out.inward * r, y, out.height - lowest + offset[2]])
        if up and np.min(np.linalg.norm(np.array(up) - centre[:2], axis=1)) < 2.0 * r:
            continue
        return np.concatenate([centre - offset, q])
    return None
