"""The vibrating table's motion: the displacement of one vibration and the drive that moves
each tray's constraint along it, step by step."""

from collections.abc import Sequence
import math

import numpy as np
from pick_common.specs import RANDOM, Vibration
import pybullet as pb

from .bodies import TRAY_MAX_FORCE


def vibration_amplitude(vibration: Vibration, rng: np.random.Generator) -> np.ndarray:
    """The peak displacement (3,) of one vibration, m: as given (FIXED), or with its horizontal
    part turned about +Z by an angle drawn uniformly from `rng` (RANDOM)."""
    x, y, z = vibration.amplitude
    if vibration.direction == RANDOM:
        angle = rng.uniform(0.0, 2.0 * math.pi)
        cos, sin = math.cos(angle), math.sin(angle)
        x, y = cos * x - sin * y, sin * x + cos * y
    return np.array([x, y, z])


class TrayDrive:
    """Moves each tray's constraint pivot to origin + amplitude * sin(2 pi f t), one call per
    physics step (the World's `before_step`); `home` puts every pivot back at its origin.

    constraints, origins: the trays' constraints and origins (world frame, m); amplitudes:
    (N, 3) peak displacements, m; frequency: Hz; time_step: s.
    """

    def __init__(self, client: int, constraints: Sequence[int], origins: Sequence[np.ndarray],
                 amplitudes: np.ndarray, frequency: float, time_step: float) -> None:
        self._client = client
        self._trays = list(zip(constraints, origins, amplitudes, strict=True))
        self._omega = 2.0 * math.pi * frequency
        self._dt = time_step
        self._step = 0

    def __call__(self) -> None:
        self._step += 1
        phase = math.sin(self._omega * self._step * self._dt)
        for constraint, origin, amplitude in self._trays:
            pb.changeConstraint(constraint, jointChildPivot=(origin + amplitude * phase).tolist(),
                                maxForce=TRAY_MAX_FORCE, physicsClientId=self._client)

    def home(self) -> None:
        for constraint, origin, _ in self._trays:
            pb.changeConstraint(constraint, jointChildPivot=origin.tolist(),
                                maxForce=TRAY_MAX_FORCE, physicsClientId=self._client)
