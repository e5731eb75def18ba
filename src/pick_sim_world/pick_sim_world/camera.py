"""Pictures of a PyBullet world with its CPU renderer (no GPU), with shapes drawn for the
picture only (a gripper, say)."""

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from pick_common.errors import check_int
import pybullet as pb


@dataclass(frozen=True)
class Overlay:
    """A shape drawn in a picture only (no physics). kind: 'box' (size = half extents x, y, z)
    or 'cylinder' (size = radius, length, along its z); pose: (7,) xyz + xyzw, world frame, m;
    rgba: colour, 0..1."""

    kind: str
    size: tuple[float, ...]
    pose: tuple[float, ...]
    rgba: tuple[float, float, float, float] = (0.2, 0.8, 0.2, 0.6)


def render(client: int, width: int, height: int, distance: float, yaw: float = 30.0,
           pitch: float = -60.0, target: Sequence[float] = (0.0, 0.0, 0.0),
           overlays: Sequence[Overlay] = ()) -> np.ndarray:
    """A picture from a camera orbiting `target` (world frame, m) at `distance` m, `yaw` and
    `pitch` in degrees. `overlays` are drawn for this picture only. Returns (height, width, 3)
    uint8 RGB."""
    width = check_int('width', width, low=16, high=4096)
    height = check_int('height', height, low=16, high=4096)
    c = client
    bodies = []
    try:
        for o in overlays:
            if o.kind == 'box':
                shape = pb.createVisualShape(pb.GEOM_BOX, halfExtents=list(o.size),
                                             rgbaColor=list(o.rgba), physicsClientId=c)
            else:
                shape = pb.createVisualShape(pb.GEOM_CYLINDER, radius=o.size[0],
                                             length=o.size[1], rgbaColor=list(o.rgba),
                                             physicsClientId=c)
            bodies.append(pb.createMultiBody(0.0, -1, shape, list(o.pose[:3]),
                                             list(o.pose[3:]), physicsClientId=c))
        view = pb.computeViewMatrixFromYawPitchRoll(list(target), distance, yaw, pitch, 0.0,
                                                    2, physicsClientId=c)
        projection = pb.computeProjectionMatrixFOV(40.0, width / height, 0.01,
                                                   10.0 * distance, physicsClientId=c)
        _, _, rgba, _, _ = pb.getCameraImage(width, height, view, projection,
                                             renderer=pb.ER_TINY_RENDERER, physicsClientId=c)
    finally:
        for body in bodies:
            pb.removeBody(body, physicsClientId=c)
    return np.asarray(rgba, dtype=np.uint8).reshape(height, width, 4)[:, :, :3]
