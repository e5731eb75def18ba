"""The vibrating table's motion: the displacement of one vibration, and the drive that holds
each tray on its commanded trajectory and measures the motion it delivered.

Each tray is a dynamic body whose state is prescribed before every physics step: its pose is
set to the command at the step's start and its velocity to the command's mean velocity over
the step, and a force cancels gravity. Bullet then integrates it exactly onto the next command
point, and parts in contact feel the tray's real velocity, so the tray delivers the commanded
motion at any time step (a tray on a driven constraint lags its anchor: 1.18 mm of a 3 mm
command at 1/240 s). Between vibrations the same drive holds each tray at its origin.
"""

from collections.abc import Sequence
import math

import numpy as np
from pick_common.specs import CENTRE, RANDOM, Vibration
from pick_common.states import PartStates, TrayMotion

from .config import GRAVITY
from .engine import Engine

MIN_STEPS_PER_CYCLE = 8     # physics steps per vibration period; fewer and the world sub-steps


def vibration_amplitude(vibration: Vibration, rng: np.random.Generator,
                        to_centre: np.ndarray | None = None) -> np.ndarray:
    """The peak displacement (3,) of one vibration, m: as given (FIXED), with its horizontal
    part turned about +Z by an angle drawn uniformly from `rng` (RANDOM), or (CENTRE) its
    horizontal length laid along `to_centre`, the tray's centre less the parts' centroid (x,
    y; none when it is None or zero)."""
    x, y, z = vibration.amplitude
    if vibration.direction == CENTRE:
        length = math.hypot(x, y)
        norm = 0.0 if to_centre is None else float(np.hypot(*to_centre[:2]))
        if norm < 1e-9:
            return np.array([0.0, 0.0, z])
        return np.array([length * to_centre[0] / norm, length * to_centre[1] / norm, z])
    if vibration.direction == RANDOM:
        angle = rng.uniform(0.0, 2.0 * math.pi)
        cos, sin = math.cos(angle), math.sin(angle)
        x, y = cos * x - sin * y, sin * x + cos * y
    return np.array([x, y, z])


def to_centre_of(states: PartStates) -> np.ndarray | None:
    """From the centroid of one instance's parts on its tray (`states`, the instance's
    snapshot) to the tray's centre (its frame origin), x and y, m; None without parts on it (a
    CENTRE vibration's direction)."""
    if not states.inside.any():
        return None
    return -states.poses[states.inside, :2].mean(axis=0)


def centring_share(to_centre: np.ndarray | None, half_extents: tuple[float, float]) -> float:
    """The share of a CENTRE vibration's duration a tray runs: the parts' centroid's farthest
    coordinate from the tray's centre, normalised to the walls (0 at the centre, 1 at a
    wall), as Asyril's smart centering sets its duration from the centre of mass's farthest
    normalised coordinate and the time to cross the platform (Asycube TCP/IP commands, "EC -
    Execute centering" and "Duration of vibration for smart centering"). So the move's duration
    is the centring from a wall. 0 with no part (`to_centre` None)."""
    if to_centre is None:
        return 0.0
    return float(min(1.0, max(abs(to_centre[0]) / half_extents[0],
                              abs(to_centre[1]) / half_extents[1])))


def vibration_substeps(frequency: float, time_step: float) -> int:
    """How many sub-steps each physics step is cut into while vibrating at `frequency` (Hz), so
    that one period has at least MIN_STEPS_PER_CYCLE steps (1 when it already has)."""
    return max(1, math.ceil(MIN_STEPS_PER_CYCLE * frequency * time_step - 1e-9))


def vibration_plan(vibration: Vibration, rngs: Sequence[np.random.Generator],
                   to_centre: Sequence[np.ndarray | None], time_step: float,
                   half_extents: tuple[float, float]
                   ) -> tuple[np.ndarray, float, int, list[int] | None]:
    """How one vibration moves a set of trays: each tray's amplitude (K, 3) m (drawn from its
    generator in `rngs`; toward its centre with CENTRE, `to_centre`), the step dt, s, the
    steps to run, and with CENTRE each tray's own steps (its share of the duration,
    centring_share, in whole periods), else None. A period gets at least
    MIN_STEPS_PER_CYCLE steps: finer steps while vibrating when the physics step
    (`time_step`) is too coarse for the frequency."""
    amplitudes = np.array([vibration_amplitude(vibration, rng, c)
                           for rng, c in zip(rngs, to_centre, strict=True)])
    dt = time_step / vibration_substeps(vibration.frequency, time_step)
    steps = max(1, int(round(vibration.duration / dt)))
    own = None
    if vibration.direction == CENTRE:
        periods = [round(vibration.duration * vibration.frequency
                         * centring_share(c, half_extents)) for c in to_centre]
        own = [int(round(n / (vibration.frequency * dt))) for n in periods]
        steps = max(1, *own)
    return amplitudes, dt, steps, own


def fundamental(times: np.ndarray, samples: np.ndarray, omega: float) -> np.ndarray:
    """Amplitude (3,) of the sinusoid at `omega` (rad/s) fitted by least squares to `samples`
    (n, 3) taken at `times` (n,), per axis (a constant offset is fitted too)."""
    basis = np.column_stack([np.sin(omega * times), np.cos(omega * times), np.ones_like(times)])
    coef, *_ = np.linalg.lstsq(basis, samples, rcond=None)
    return np.hypot(coef[0], coef[1])


class TrayDrive:
    """Holds each tray (bodies, at origins in the world frame, m; mass in kg) on its trajectory:
    call it before every physics step. `start` begins a vibration of some trays, `stop` ends it
    and returns the motion they delivered, measured from their states after each step."""

    def __init__(self, engine: Engine, bodies: Sequence[int], origins: Sequence[np.ndarray],
                 mass: float) -> None:
        self._engine = engine
        self._bodies = list(bodies)
        self._origins = [np.asarray(o, dtype=float) for o in origins]
        self._lift = [0.0, 0.0, mass * GRAVITY]
        self._amplitudes = np.zeros((len(self._bodies), 3))
        self._moving: list[int] = []
        self._until = np.zeros(len(self._bodies), dtype=np.int64)
        self._omega = self._dt = 0.0
        self._step = 0
        self._positions: list[np.ndarray] = []
        self._velocities: list[np.ndarray] = []

    def start(self, trays: Sequence[int], amplitudes: np.ndarray, frequency: float,
              time_step: float, steps: Sequence[int] | None = None) -> None:
        """Move trays (indices) along amplitude[k] * sin(2 pi frequency t), t from 0 at the next
        step of `time_step` s, each for its `steps` (all of the vibration when None: each
        moves until stop()); the others, and a tray past its steps, stay at their origins."""
        self._amplitudes[:] = 0.0
        self._amplitudes[list(trays)] = amplitudes
        self._moving = list(trays)
        self._until = np.full(len(self._bodies), np.iinfo(np.int64).max)
        if steps is not None:
            self._until[list(trays)] = steps
        self._omega, self._dt = 2.0 * math.pi * frequency, time_step
        self._step = 0
        self._positions, self._velocities = [], []

    def _command(self, step: int) -> np.ndarray:
        on = (step < self._until)[:, None]
        return self._amplitudes * on * math.sin(self._omega * step * self._dt)

    def _measure(self) -> None:
        positions, velocities = [], []
        for k in self._moving:
            positions.append(self._engine.position(self._bodies[k]) - self._origins[k])
            velocities.append(self._engine.velocity(self._bodies[k])[0])
        self._positions.append(np.array(positions))
        self._velocities.append(np.array(velocities))

    def __call__(self) -> None:
        if self._moving and self._step:
            self._measure()
        if self._moving:
            here, there = self._command(self._step), self._command(self._step + 1)
            velocity = (there - here) / self._dt
            self._step += 1
        else:
            here = velocity = self._amplitudes      # zeros: held at the origins
        engine = self._engine
        for k, body in enumerate(self._bodies):
            engine.set_pose(body, (self._origins[k] + here[k]).tolist())
            engine.set_velocity(body, velocity[k].tolist())
            engine.push(body, self._lift)

    def motion(self) -> TrayMotion | None:
        """The motion delivered so far, of the tray that tracked its command worst (over its own
        steps); None before three steps of a vibration, or when no tray moved for three."""
        if len(self._positions) < 3:
            return None
        n = len(self._positions)
        times = np.arange(1, n + 1) * self._dt                 # each state is after its step
        mid = times - 0.5 * self._dt                           # a step's velocity: its middle
        positions, velocities = np.array(self._positions), np.array(self._velocities)
        worst = None
        for i, k in enumerate(self._moving):
            # the states of its own motion: a tray that stops early is brought to its origin
            # over its last step, whose state is not on the sinusoid
            own = min(n, int(self._until[k]) - 1)
            if own < 3:
                continue
            commanded = float(np.linalg.norm(self._amplitudes[k]))
            shown = TrayMotion(
                commanded,
                float(np.linalg.norm(fundamental(times[:own], positions[:own, i], self._omega))),
                commanded * self._omega,
                float(np.linalg.norm(fundamental(mid[:own], velocities[:own, i], self._omega))))
            if worst is None or shown.error > worst.error:
                worst = shown
        return worst

    def stop(self) -> TrayMotion | None:
        """End the vibration: measure the last step, hold every tray at its origin again, and
        return the delivered motion (motion())."""
        if self._moving and self._step:
            self._measure()
        delivered = self.motion()
        self._amplitudes[:] = 0.0
        self._moving = []
        return delivered
