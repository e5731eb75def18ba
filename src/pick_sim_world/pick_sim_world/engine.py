"""The one module that speaks to PyBullet: a client in DIRECT mode that simulates in the length
unit its engine is made for and is spoken to in SI units.

Bullet assumes moving objects of 0.05 to 10 of its length units ("Scaling The World", Bullet's
wiki: a pool game's 4 cm balls ran better in centimetres), and several of its settings are
fixed numbers in those units. A 5 mm part in metres is 0.005 units, and the margin pybullet
gives every convex hull of a compound, 0.001 units, is a fifth of it. So the world simulates
in `length_unit` metres per unit (PhysicsConfig; centimetres by default, in which parts of
0.5 to 100 mm measure 0.05 to 10 units), and everything crosses this module in SI. As the
wiki's rules say: shapes, positions, linear velocities, gravity, forces and the rolling and
spinning friction arms are divided by the unit, inertias by its square; times, masses, angles,
angular velocities, friction coefficients and restitutions are kept.

Bullet's own tolerances stay at their values in its units, which is what scaling the world
is for. In centimetres: a hull's margin 0.001 units = 0.01 mm (pick_common.parts.insets
takes it off each hull); the linear slop pybullet sets, 1e-5 units = 0.1 um; the depth past
which Bullet resolves a contact by split impulses instead of a velocity bias, 0.04 units =
0.4 mm (btContactSolverInfo's default, which pybullet leaves). The contact-breaking
threshold is a factor of each shape's bounding radius (btCollisionDispatcher's relative
threshold; measured: at 0.001, a 10 mm hull cube reports the floor within 0.009 mm in either
unit), so it needs no scaling. One velocity is a
physical one and is kept in SI: Bullet gives no restitution below 0.2 units/s of approach
(btContactSolverInfo's restitution velocity threshold); at 0.2 cm/s a part resting on the
floor, which gravity gives 9.81 m/s^2 x 1/480 s = 20 mm/s each step, would bounce every step,
so the threshold is Bullet's 0.2 m/s (RESTITUTION_THRESHOLD), as in metres.
"""

from collections.abc import Sequence
from dataclasses import dataclass
import hashlib
import math
import os

import numpy as np
from pick_common.parts.materials import BodyValues
from pick_common.parts.primitives import Box, Hull, IDENTITY, Primitive
import pybullet as pb
import trimesh

# pybullet's margin of every convex hull of a compound, in its length units (URDF and shape
# importers' fixed default; changeDynamics' collisionMargin reaches only the compound)
HULL_MARGIN_UNITS = 1e-3
RESTITUTION_THRESHOLD = 0.2     # m/s: Bullet's default, as a velocity in SI (module docstring)
MAX_ARRAY = 16                  # pybullet's MAX_COMPOUND_COLLISION_SHAPES: an array's shapes


def _placed(hull: Hull) -> np.ndarray:
    """A hull's vertices (K, 3) placed by its position and orientation, m."""
    x, y, z, w = hull.orientation
    rotation = trimesh.transformations.quaternion_matrix([w, x, y, z])[:3, :3]
    return np.asarray(hull.vertices, dtype=float) @ rotation.T + np.asarray(hull.position)


@dataclass(frozen=True)
class Mass:
    """A body's mass, kg, and its inertia diagonal in the engine's units, as `mass` reads
    them and `set_mass` restores them exactly."""

    kg: float
    inertia: tuple[float, float, float]


class Engine:
    """One PyBullet client, in SI units (module docstring). `length_unit`: metres per engine
    unit. Not thread-safe, as the World that owns it."""

    def __init__(self, length_unit: float) -> None:
        self.unit = float(length_unit)
        self._scale = 1.0 / self.unit            # engine units per metre
        self.client = pb.connect(pb.DIRECT)

    @property
    def hull_margin(self) -> float:
        """pybullet's margin of a compound's convex hull, m."""
        return HULL_MARGIN_UNITS * self.unit

    def close(self) -> None:
        """Disconnect. Idempotent."""
        if self.client is not None and self.client >= 0:
            try:
                pb.disconnect(physicsClientId=self.client)
            except pb.error:
                pass
            self.client = None

    # ------------------------------------------------------------------------- settings
    def reset(self, gravity: float, time_step: float, solver_iterations: int,
              warm_starting_factor: float, contact_breaking_threshold: float) -> None:
        """Empty the simulation and set gravity (m/s^2, along -z), the step (s), the solver's
        iterations and warm start, and the contact-breaking threshold (a factor of each
        shape's bounding radius)."""
        c = self.client
        pb.resetSimulation(physicsClientId=c)
        pb.setGravity(0.0, 0.0, -gravity * self._scale, physicsClientId=c)
        pb.setPhysicsEngineParameter(
            fixedTimeStep=time_step, numSolverIterations=solver_iterations,
            warmStartingFactor=warm_starting_factor,
            contactBreakingThreshold=contact_breaking_threshold,
            restitutionVelocityThreshold=RESTITUTION_THRESHOLD * self._scale,
            deterministicOverlappingPairs=1, physicsClientId=c)

    def set_time_step(self, time_step: float) -> None:
        pb.setPhysicsEngineParameter(fixedTimeStep=time_step, physicsClientId=self.client)

    def parameters(self) -> dict:
        """pybullet's engine parameters as it reports them (in its units)."""
        return pb.getPhysicsEngineParameters(physicsClientId=self.client)

    # ------------------------------------------------------------------------- bodies
    def shape(self, primitives: Sequence[Primitive], directory: str = '') -> int:
        """One collision shape of `primitives` (boxes, cylinders, hulls; each placed in the
        body's frame, m). Hulls are collided as given, grown by hull_margin (pick_common's
        insets take it off first).

        pybullet keeps only the first MAX_ARRAY shapes of an array and drops the rest without
        a word (measured: a row of 24 boxes collides as its first 16), and a mesh part has up
        to 32 pieces. So every hull goes into one OBJ file, an object each, which pybullet
        loads as one compound of hulls with no such limit; the file is written into
        `directory` (needed only with hulls) and named by its content: pybullet keeps a
        file's mesh by its path for the life of the process, resets included, so a reused
        name would bring back an old shape. Raises ValueError past MAX_ARRAY boxes and
        cylinders."""
        s = self._scale
        solids = [p for p in primitives if not isinstance(p, Hull)]
        hulls = [p for p in primitives if isinstance(p, Hull)]
        if len(solids) + bool(hulls) > MAX_ARRAY:
            raise ValueError(f'{len(solids)} boxes and cylinders: pybullet collides at most '
                             f'{MAX_ARRAY - bool(hulls)} beside the hulls')
        kinds, radii, lengths, halves, files, positions, orientations = [], [], [], [], [], [], []
        for p in solids:
            box = isinstance(p, Box)
            kinds.append(pb.GEOM_BOX if box else pb.GEOM_CYLINDER)
            halves.append([h * s for h in p.half] if box else [0.0, 0.0, 0.0])
            radii.append(0.0 if box else p.radius * s)
            lengths.append(0.0 if box else p.length * s)
            files.append('')
            positions.append([v * s for v in p.position])
            orientations.append(list(p.orientation))
        if hulls:
            kinds.append(pb.GEOM_MESH)
            halves.append([0.0, 0.0, 0.0])
            radii.append(0.0)
            lengths.append(0.0)
            files.append(self._hull_file(hulls, directory))
            positions.append([0.0, 0.0, 0.0])
            orientations.append(list(IDENTITY))
        return pb.createCollisionShapeArray(
            kinds, radii=radii, lengths=lengths, halfExtents=halves, fileNames=files,
            meshScales=[[1.0, 1.0, 1.0]] * len(kinds), collisionFramePositions=positions,
            collisionFrameOrientations=orientations, physicsClientId=self.client)

    def _hull_file(self, hulls: Sequence[Hull], directory: str) -> str:
        """An OBJ file of `hulls` (each placed by its position and orientation, m) in the
        engine's units, an object each (shape's docstring)."""
        lines, first = [], 1
        for k, p in enumerate(hulls):
            vertices = _placed(p) * self._scale
            lines.append(f'o hull_{k}')
            lines += [f'v {x!r} {y!r} {z!r}' for x, y, z in vertices.tolist()]
            lines += [f'f {a + first} {b + first} {c + first}' for a, b, c in p.faces.tolist()]
            first += len(vertices)
        text = '\n'.join(lines) + '\n'
        digest = hashlib.sha256(text.encode()).hexdigest()[:20]
        path = os.path.join(directory, f'hulls_{digest}.obj')
        if not os.path.exists(path):
            with open(path, 'w') as f:
                f.write(text)
        return path

    def body(self, mass: float, shape: int, position: Sequence[float],
             orientation: Sequence[float] = IDENTITY,
             moments: Sequence[float] | None = None) -> int:
        """A rigid body of `mass` kg (0: static) and `shape` at `position` (3,) m and
        `orientation` (4,) xyzw, its mass centre at its frame's origin and its principal axes
        along the frame's axes, with principal moments of inertia `moments` (3,) kg m^2, or
        else Bullet's estimate from the shape's bounds. Never asleep."""
        s = self._scale
        body = pb.createMultiBody(mass, shape, basePosition=[v * s for v in position],
                                  baseOrientation=list(orientation),
                                  useMaximalCoordinates=True, physicsClientId=self.client)
        # pybullet sets the mass to 0 when it gets an inertia alone: both, always
        inertia = {} if moments is None else {
            'mass': mass, 'localInertiaDiagonal': [m * s * s for m in moments]}
        pb.changeDynamics(body, -1, activationState=pb.ACTIVATION_STATE_DISABLE_SLEEPING,
                          physicsClientId=self.client, **inertia)
        return body

    def set_contact(self, body: int, values: BodyValues, damping: float | None = None) -> None:
        """A body's contact coefficients (materials.body_values: friction, rolling and
        spinning arms in m, restitution) and, when given, its linear and angular damping."""
        s = self._scale
        extra = {} if damping is None else {'linearDamping': damping, 'angularDamping': damping}
        pb.changeDynamics(body, -1, lateralFriction=values.lateral_friction,
                          rollingFriction=values.rolling_friction * s,
                          spinningFriction=values.spinning_friction * s,
                          restitution=values.restitution, physicsClientId=self.client, **extra)

    def park(self, body: int) -> None:
        """Make a body static where it is, at rest: out of the dynamics, never moved again."""
        pb.resetBaseVelocity(body, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0],
                             physicsClientId=self.client)
        pb.changeDynamics(body, -1, mass=0.0, physicsClientId=self.client)

    def remove(self, body: int) -> None:
        pb.removeBody(body, physicsClientId=self.client)

    def mass(self, body: int) -> Mass:
        """The body's mass and inertia (Mass)."""
        info = pb.getDynamicsInfo(body, -1, physicsClientId=self.client)
        return Mass(info[0], tuple(info[2]))

    def set_mass(self, body: int, mass: Mass | None) -> None:
        """Make a body static (None: mass 0) or give it `mass` back."""
        if mass is None:
            pb.changeDynamics(body, -1, mass=0.0, physicsClientId=self.client)
        else:
            pb.changeDynamics(body, -1, mass=mass.kg, localInertiaDiagonal=list(mass.inertia),
                              physicsClientId=self.client)

    def sleep(self, body: int) -> None:
        pb.changeDynamics(body, -1, activationState=pb.ACTIVATION_STATE_SLEEP,
                          physicsClientId=self.client)

    def wake(self, body: int) -> None:
        """Wake a body and keep it from sleeping (as `body` makes it)."""
        c = self.client
        pb.changeDynamics(body, -1, activationState=pb.ACTIVATION_STATE_WAKE_UP,
                          physicsClientId=c)
        pb.changeDynamics(body, -1, activationState=pb.ACTIVATION_STATE_DISABLE_SLEEPING,
                          physicsClientId=c)

    # ------------------------------------------------------------------------- state
    def poses(self, bodies: Sequence[int]) -> np.ndarray:
        """World-frame poses (N, 7) of bodies' bases (their mass centres' frames), xyz m +
        xyzw."""
        out = np.empty((len(bodies), 7))
        get, c = pb.getBasePositionAndOrientation, self.client
        for row, body in enumerate(bodies):
            position, orientation = get(body, physicsClientId=c)
            out[row, :3] = position
            out[row, 3:] = orientation
        out[:, :3] *= self.unit
        return out

    def position(self, body: int) -> np.ndarray:
        """The body's base position (3,), m."""
        return np.multiply(pb.getBasePositionAndOrientation(
            body, physicsClientId=self.client)[0], self.unit)

    def set_pose(self, body: int, position: Sequence[float],
                 orientation: Sequence[float] = IDENTITY) -> None:
        s = self._scale
        pb.resetBasePositionAndOrientation(body, [v * s for v in position], list(orientation),
                                           physicsClientId=self.client)

    def velocity(self, body: int) -> tuple[np.ndarray, np.ndarray]:
        """The body's linear (3,) m/s and angular (3,) rad/s velocity."""
        linear, angular = pb.getBaseVelocity(body, physicsClientId=self.client)
        return np.multiply(linear, self.unit), np.asarray(angular)

    def speed(self, body: int) -> float:
        """The speed of the body's mass centre, m/s."""
        return math.hypot(*pb.getBaseVelocity(body, physicsClientId=self.client)[0]) * self.unit

    def set_velocity(self, body: int, linear: Sequence[float],
                     angular: Sequence[float] = (0.0, 0.0, 0.0)) -> None:
        s = self._scale
        pb.resetBaseVelocity(body, [v * s for v in linear], list(angular),
                             physicsClientId=self.client)

    def push(self, body: int, force: Sequence[float]) -> None:
        """Apply `force` (3,) N at the body's mass centre for the next step."""
        s = self._scale
        pb.applyExternalForce(body, -1, [f * s for f in force], (0.0, 0.0, 0.0), pb.LINK_FRAME,
                              physicsClientId=self.client)

    def step(self) -> None:
        pb.stepSimulation(physicsClientId=self.client)

    # ------------------------------------------------------------------------- contacts
    def near(self, body: int, reach: float) -> list[int]:
        """The bodies whose bounding boxes come within `reach` (m) of `body`'s (itself
        included)."""
        s, c = self._scale, self.client
        low, high = pb.getAABB(body, physicsClientId=c)
        r = reach * s
        found = pb.getOverlappingObjects([v - r for v in low], [v + r for v in high],
                                         physicsClientId=c)
        return [b for b, _ in found or ()]

    def contacts(self, body: int | None = None) -> list[tuple[int, int, float]]:
        """The contacts of the last step (within the contact-breaking threshold), of `body`
        or of every body: (body A, body B, distance m, negative where they overlap)."""
        kwargs = {} if body is None else {'bodyA': body}
        return [(p[1], p[2], p[8] * self.unit)
                for p in pb.getContactPoints(physicsClientId=self.client, **kwargs)]

    def closest(self, a: int, b: int, distance: float) -> list[float]:
        """The distances (m, negative where they overlap) of the closest points of `a` and `b`
        within `distance` m, as the collision detection sees them now."""
        return [p[8] * self.unit for p in pb.getClosestPoints(
            a, b, distance * self._scale, physicsClientId=self.client)]

    # ------------------------------------------------------------------------- pictures
    def visual(self, kind: str, size: Sequence[float], pose: Sequence[float],
               rgba: Sequence[float]) -> int:
        """A body with no mass or collision, drawn only: a 'box' (size: half extents, m) or a
        'cylinder' (size: radius, length, m, along its z) at `pose` (7,) m + xyzw."""
        s, c = self._scale, self.client
        if kind == 'box':
            shape = pb.createVisualShape(pb.GEOM_BOX, halfExtents=[v * s for v in size],
                                         rgbaColor=list(rgba), physicsClientId=c)
        else:
            shape = pb.createVisualShape(pb.GEOM_CYLINDER, radius=size[0] * s,
                                         length=size[1] * s, rgbaColor=list(rgba),
                                         physicsClientId=c)
        return pb.createMultiBody(0.0, -1, shape, [v * s for v in pose[:3]], list(pose[3:]),
                                  physicsClientId=c)

    def image(self, width: int, height: int, target: Sequence[float], distance: float,
              yaw: float, pitch: float) -> np.ndarray:
        """A picture (height, width, 3) uint8 RGB with the CPU renderer, from a camera
        orbiting `target` (3,) m at `distance` m, `yaw` and `pitch` in degrees, 40 degrees
        across."""
        s, c = self._scale, self.client
        view = pb.computeViewMatrixFromYawPitchRoll([v * s for v in target], distance * s,
                                                    yaw, pitch, 0.0, 2, physicsClientId=c)
        projection = pb.computeProjectionMatrixFOV(40.0, width / height, 0.01 * s,
                                                   10.0 * distance * s, physicsClientId=c)
        _, _, rgba, _, _ = pb.getCameraImage(width, height, view, projection,
                                             renderer=pb.ER_TINY_RENDERER, physicsClientId=c)
        return np.asarray(rgba, dtype=np.uint8).reshape(height, width, 4)[:, :, :3]
