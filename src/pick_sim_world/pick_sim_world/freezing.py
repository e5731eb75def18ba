"""Freezing rested parts while the parts fall and settle: what rests costs nothing to step.

A frozen part is made static (mass 0, asleep): Bullet neither integrates it nor tests it
against other static bodies, so a pile whose parts come to rest one by one steps ever cheaper
(on the tray, 80 of 85 resting capacitors frozen: 0.16 ms a step against 2.2 ms). A part is
frozen once it stayed within the settle tolerances (settle.linear_tolerance,
settle.angular_tolerance) of one pose for a settle window. A frozen part still holds up the
parts on it, and wakes (its mass, inertia and sleep setting restored, at rest) when a part
that moved more than the tolerance since the last check comes within that distance of it;
a woken part must rest a whole window again before it freezes. Every part is thawed when the
operation ends, so between operations the scene is as it always was: dynamic bodies, at rest
by the settle criterion.

The trays are static while a Freezer is in use too: it serves only while the drive holds them
at their origins (drops and settles, never a vibration), and a dynamic tray would be tested
against every frozen part on it, every step.
"""

from collections.abc import Iterable, Sequence

import numpy as np
from pick_common.states import quaternion_angles

from .engine import Engine, Mass


class Freezer:
    """Freezes and wakes part bodies of one part model and holds the `trays` static for one
    operation (a drop, a vibration's settle, a removal's settle); use it as a context manager:
    leaving it thaws every part and restores the trays, whatever happened inside. Parts enter
    it as `check` first sees them, so a drop's stream can add them layer by layer."""

    def __init__(self, engine: Engine, trays: Sequence[int], linear_tolerance: float,
                 angular_tolerance: float, window: float) -> None:
        self._engine = engine
        self._trays = list(trays)
        self._linear, self._angular, self._window = linear_tolerance, angular_tolerance, window
        self.frozen: set[int] = set()               # bodies
        self._anchor: dict[int, np.ndarray] = {}    # body -> the pose it has stayed near
        self._since: dict[int, float] = {}          # body -> time it has stayed near it, s
        self._last: dict[int, np.ndarray] = {}      # body -> its pose at the last check
        self._part_mass: Mass | None = None
        self._tray_mass: Mass | None = None

    def __enter__(self) -> 'Freezer':
        if self._trays:
            self._tray_mass = self._engine.mass(self._trays[0])
            for tray in self._trays:
                self._engine.set_mass(tray, None)
        return self

    def __exit__(self, *exc) -> None:
        self.thaw(list(self.frozen))
        for tray in self._trays:
            self._engine.set_mass(tray, self._tray_mass)

    def abandon(self) -> None:
        """Forget every body: the scene they were in is gone (rebuilt after a fault)."""
        self.frozen, self._trays = set(), []

    def freeze(self, bodies: Iterable[int]) -> None:
        """Make `bodies` static and asleep, at rest."""
        e = self._engine
        for body in bodies:
            if body in self.frozen:
                continue
            if self._part_mass is None:
                self._part_mass = e.mass(body)
            e.set_velocity(body, (0.0, 0.0, 0.0))
            e.set_mass(body, None)
            e.sleep(body)
            self.frozen.add(body)

    def thaw(self, bodies: Iterable[int]) -> None:
        """Give frozen `bodies` their mass and inertia back, at rest and with sleeping
        disabled again (as bodies.create_part makes them); they must rest a whole window
        before they freeze again."""
        e = self._engine
        for body in bodies:
            if body not in self.frozen:
                continue
            e.set_mass(body, self._part_mass)
            e.set_velocity(body, (0.0, 0.0, 0.0))
            e.wake(body)
            self.frozen.discard(body)
            self._since.pop(body, None)      # anchored afresh at the next check

    def thawed(self, bodies: Sequence[int]) -> list[int]:
        """The indices into `bodies` of those not frozen."""
        return [i for i, b in enumerate(bodies) if b not in self.frozen]

    def movers(self, bodies: Sequence[int], poses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Which of `bodies` (poses (N, 7), world frame) moved or turned more than the
        tolerance since the last check (a part new to the checks: none), and how far each
        moved (m)."""
        last = np.array([self._last.get(b, p) for b, p in zip(bodies, poses, strict=True)])
        shift = np.linalg.norm(poses[:, :3] - last[:, :3], axis=1)
        turn = quaternion_angles(poses[:, 3:], last[:, 3:])
        return (shift > self._linear) | (turn > self._angular), shift

    def check(self, bodies: Sequence[int], poses: np.ndarray, elapsed: float) -> None:
        """At a rest check, `elapsed` s after the last (poses (N, 7) of `bodies`, world frame):
        wake the frozen parts within reach of a part that moved more than the tolerance since
        the last check (movers; its reach: how far it moved), then freeze the parts that
        stayed near their anchor pose for a window."""
        if not len(bodies):
            return
        if self.frozen:
            woken = set()
            movers, shift = self.movers(bodies, poses)
            for i in np.flatnonzero(movers):
                woken.update(b for b in self._engine.near(bodies[i], shift[i])
                             if b in self.frozen)
            self.thaw(woken)
        frozen = np.array([b in self.frozen for b in bodies], dtype=bool)
        anchor = np.array([self._anchor.get(b, p) for b, p in zip(bodies, poses, strict=True)])
        since = np.array([self._since.get(b, -1.0) for b in bodies])
        stayed = (since >= 0.0) \
            & (np.linalg.norm(poses[:, :3] - anchor[:, :3], axis=1) <= self._linear) \
            & (quaternion_angles(poses[:, 3:], anchor[:, 3:]) <= self._angular)
        rested = []
        for i, body in enumerate(bodies):
            self._last[body] = poses[i]
            if frozen[i]:
                continue
            if stayed[i]:
                self._since[body] = since[i] + elapsed
                if self._since[body] >= self._window - 1e-9:
                    rested.append(body)
            else:
                self._anchor[body], self._since[body] = poses[i], 0.0
        self.freeze(rested)
