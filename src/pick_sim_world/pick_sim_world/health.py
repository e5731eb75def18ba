"""The physics health of an operation (a drop, a vibration, a removal, a settle), told once at
its end: where the parts ended (outside their containers; tunnelled: a centre in or under the
floor or in a wall), the deepest penetration, the fastest part and the parts thrown faster than
the speed a fall and a tray's bounce can give (stepping.speed_limit). Pure core: the engine's
contact query, numpy; no rclpy."""

from collections.abc import Sequence

import numpy as np
from pick_common import containers
from pick_common.containers import ContainerSpec
from pick_common.parts.geometry import PartGeometry
from pick_common.states import PartStates, SettleReport

from . import bodies, stepping
from .engine import Engine


def finished(last: SettleReport, before: Sequence[SettleReport], engine: Engine,
             container: ContainerSpec, part: PartGeometry, state: PartStates,
             peaks: dict[int, float], tray_speed: float,
             landed: dict[int, tuple[np.ndarray, float]]) -> SettleReport:
    """`last` (how the operation ended) with the times and steps of its earlier runs `before`
    added in, and its health: `state`, the parts as they ended; `peaks`, each part's peak
    speed in the operation (m/s, removed parts too); `tray_speed`, the tray's peak speed,
    m/s; `landed`, the parts that came down beside their container and were taken out (part
    id: where, in its instance frame, m, and how fast, m/s): escaped, and so spilled unless
    thrown."""
    for r in before:
        last.sim_time += r.sim_time
        last.wall_time += r.wall_time
        last.steps += r.steps
    last.landed_ids = sorted(landed)
    last.landed_at = [(float(landed[i][0][0]), float(landed[i][0][1]),
                       -container.floor_thickness) for i in last.landed_ids]
    last.landed_speeds = [float(landed[i][1]) for i in last.landed_ids]
    last.escaped_ids = last.landed_ids + [int(i) for i in state.ids[~state.inside]]
    if len(state.ids):
        gone = containers.tunnelled(container, bodies.part_centres(state.poses, part))
        last.tunnelled_ids = [int(i) for i in state.ids[gone]]
    last.max_penetration = bodies.max_penetration(engine)
    limit = stepping.speed_limit(container, part, tray_speed)
    last.max_speed = max(peaks.values(), default=0.0)
    last.thrown_ids = sorted(pid for pid, v in peaks.items() if v > limit)
    return last
