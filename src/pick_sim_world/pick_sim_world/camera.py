"""Pictures of a PyBullet world with its CPU renderer (no GPU), with shapes drawn for the
picture only (a gripper, say)."""

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from pick_common.errors import check_int

from .engine import Engine


@dataclass(frozen=True)
class Overlay:
    """A shape drawn in a picture only (no physics). kind: 'box' (size = half extents x, y, z)
    or 'cylinder' (size = radius, length, along its z); pose: (7,) xyz + xyzw, world frame, m;
    rgba: colour, 0..1."""

    kind: str
    size: tuple[float, ...]
    pose: tuple[float, ...]
    rgba: tuple[float, float, float, float] = (0.2, 0.8, 0.2, 0.6)


def render(engine: Engine, width: int, height: int, distance: float, yaw: float = 30.0,
           pitch: float = -60.0, target: Sequence[float] = (0.0, 0.0, 0.0),
           overlays: Sequence[Overlay] = ()) -> np.ndarray:
    """A picture from a camera orbiting `target` (world frame, m) at `distance` m, `yaw` and
    `pitch` in degrees. `overlays` are drawn for this picture only. Returns (height, width, 3)
    uint8 RGB."""
    width = check_int('width', width, low=16, high=4096)
    height = check_int('height', height, low=16, high=4096)
    drawn = []
    try:
        for o in overlays:
            drawn.append(engine.visual(o.kind, o.size, o.pose, o.rgba))
        return engine.image(width, height, target, distance, yaw, pitch)
    finally:
        for body in drawn:
            engine.remove(body)
