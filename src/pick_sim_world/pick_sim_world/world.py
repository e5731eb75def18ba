"""The physics world: containers, parts, dropping, settling, vibrating, feeding and removing.

Pure core: PyBullet (DIRECT mode), numpy and trimesh; no rclpy. One `World` owns one PyBullet
client holding N independent instances side by side, each with its own container, parts and
random generator (the paper's "demo instances", figure 10).

Poses are (N, 7) float64 arrays, xyz in metres then an xyzw unit quaternion, expressed in the
instance frame (origin at the centre of the container's inner floor, +Z up).
"""

from collections import deque
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
import math
import os
import shutil
import tempfile
import time

import numpy as np
import pybullet as pb
import trimesh

from . import containers
from .config import (
    check_physics,
    check_scene,
    check_vibration,
    MAX_PARTS_PER_INSTANCE,
    PhysicsConfig,
    RANDOM,
    SceneSpec,
    Vibration,
)
from .errors import (
    check_int,
    check_number,
    InvalidArgument,
    PhysicsFault,
    UnknownInstance,
    UnknownPart,
)
from .parts import build_part, PartGeometry

GRAVITY = 9.81                  # m/s^2
INSTANCE_GAP = 0.05             # m between the outer walls of neighbouring instances
SPAWN_GAP = 0.0005              # m of clearance between spawn spheres
PACKING_LIMIT = 0.4             # largest fraction of a container's inner volume parts may fill
TRAY_MASS = 3.0                 # kg; the tray is a dynamic body held by a driven constraint
TRAY_MAX_FORCE = 5000.0         # N the constraint may apply to hold the tray on its trajectory

ProgressCallback = Callable[['Progress'], bool]


@dataclass(frozen=True)
class Progress:
    """Sent once per settle check. phase: 'dropping', 'vibrating' or 'settling'.

    sim_time: s since the operation started. parts_moving: parts not at rest over the settle
    window. max_displacement: largest position change of a part over the window, m.
    """

    phase: str
    sim_time: float
    parts_moving: int
    max_displacement: float


@dataclass
class SettleReport:
    """How an operation ended. Times in s; ids of parts still moving and outside containers."""

    settled: bool
    sim_time: float
    wall_time: float
    steps: int
    unsettled_ids: list[int] = field(default_factory=list)
    escaped_ids: list[int] = field(default_factory=list)
    canceled: bool = False


@dataclass(frozen=True)
class Overlay:
    """A shape drawn in a picture only (no physics). kind: 'box' (size = half extents x, y, z)
    or 'cylinder' (size = radius, length, along its z); pose: (7,) xyz + xyzw, world frame, m;
    rgba: colour, 0..1."""

    kind: str
    size: tuple[float, ...]
    pose: tuple[float, ...]
    rgba: tuple[float, float, float, float] = (0.2, 0.8, 0.2, 0.6)


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


@dataclass
class Instance:
    """One instance: container body, origin in the world (m), its generator and its parts."""

    id: int
    seed: int
    origin: np.ndarray
    body: int
    constraint: int | None
    rng: np.random.Generator
    part_ids: list[int] = field(default_factory=list)


def instance_seed(seed: int, index: int) -> int:
    """The seed of instance `index` derived from the scene's base seed (stable across runs)."""
    return int(np.random.SeedSequence([seed, index]).generate_state(1, np.uint64)[0])


def random_quaternions(rng: np.random.Generator, n: int) -> np.ndarray:
    """n uniformly distributed unit quaternions, (n, 4) xyzw."""
    q = rng.normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def rotate(quaternions: np.ndarray, vector: np.ndarray) -> np.ndarray:
    """Rotate one vector (3,) by each quaternion (n, 4) xyzw; returns (n, 3)."""
    xyz, w = quaternions[:, :3], quaternions[:, 3:4]
    t = 2.0 * np.cross(xyz, vector)
    return vector + w * t + np.cross(xyz, t)


def vibration_amplitude(vibration: Vibration, rng: np.random.Generator) -> np.ndarray:
    """The peak displacement (3,) of one vibration, m: as given (FIXED), or with its horizontal
    part turned about +Z by an angle drawn uniformly from `rng` (RANDOM)."""
    x, y, z = vibration.amplitude
    if vibration.direction == RANDOM:
        angle = rng.uniform(0.0, 2.0 * math.pi)
        cos, sin = math.cos(angle), math.sin(angle)
        x, y = cos * x - sin * y, sin * x + cos * y
    return np.array([x, y, z])


def quaternion_angles(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Rotation angle between quaternion pairs (n, 4) and (n, 4), rad."""
    dot = np.abs(np.einsum('ij,ij->i', a, b))
    return 2.0 * np.arccos(np.clip(dot, 0.0, 1.0))


class World:
    """A PyBullet world of N instances. Not thread-safe: one caller at a time."""

    def __init__(self, scene: SceneSpec | None = None,
                 physics: PhysicsConfig | None = None) -> None:
        self._physics = check_physics(physics or PhysicsConfig())
        self._client = pb.connect(pb.DIRECT)
        self._tmp = tempfile.mkdtemp(prefix='pick_sim_world_')
        self._instances: list[Instance] = []
        self._bodies: dict[int, int] = {}        # part id -> body
        self._owner: dict[int, int] = {}         # part id -> instance id
        self._next_id = 0
        self._sim_time = 0.0
        try:
            self.reset(scene or SceneSpec())
        except BaseException:
            self.close()
            raise

    # ----------------------------------------------------------------------------- scene
    @property
    def scene(self) -> SceneSpec:
        return self._scene

    @property
    def physics(self) -> PhysicsConfig:
        return self._physics

    @property
    def part(self) -> PartGeometry:
        return self._part

    @property
    def instances(self) -> Sequence[Instance]:
        return tuple(self._instances)

    @property
    def sim_time(self) -> float:
        """Simulated time since the last reset, s."""
        return self._sim_time

    def reset(self, scene: SceneSpec | None = None, seed: int | None = None) -> None:
        """Build `scene` (or rebuild the current one) with no parts; `seed` overrides its seed.

        Everything is checked before the current world is touched: a bad scene raises and leaves
        the world as it was.
        """
        scene = scene or self._scene
        if seed is not None:
            scene = SceneSpec(scene.container, scene.part, scene.instance_count, seed)
        check_scene(scene)
        part = build_part(scene.part)
        self._build(scene, part)

    def _build(self, scene: SceneSpec, part: PartGeometry) -> None:
        c = self._client
        cfg = self._physics
        pb.resetSimulation(physicsClientId=c)
        pb.setGravity(0.0, 0.0, -GRAVITY, physicsClientId=c)
        pb.setPhysicsEngineParameter(
            fixedTimeStep=cfg.time_step, numSolverIterations=cfg.solver_iterations,
            contactBreakingThreshold=cfg.contact_breaking_threshold,
            deterministicOverlappingPairs=1, physicsClientId=c)
        self._scene, self._part = scene, part
        self._instances, self._bodies, self._owner = [], {}, {}
        self._next_id, self._sim_time = 0, 0.0
        self._at_rest = True     # the last step run ended settled (the settle criterion)
        self._part_shape = self._create_part_shape(part)
        pitch = containers.outer_size(scene.container)[0] + INSTANCE_GAP
        for k in range(scene.instance_count):
            origin = np.array([k * pitch, 0.0, 0.0])
            body, constraint = self._create_container(scene.container, origin)
            seed = instance_seed(scene.seed, k)
            self._instances.append(Instance(k, seed, origin, body, constraint,
                                            np.random.default_rng(seed)))

    def _create_part_shape(self, part: PartGeometry) -> int:
        shutil.rmtree(self._tmp, ignore_errors=True)
        os.makedirs(self._tmp)
        kinds, radii, lengths, halves, files, positions, orientations = [], [], [], [], [], [], []
        for i, p in enumerate(part.primitives):
            radius = length = 0.0
            half = [0.0, 0.0, 0.0]
            path = ''
            if p.kind == 'box':
                kind, half = pb.GEOM_BOX, list(p.size)
            elif p.kind == 'cylinder':
                kind, (radius, length) = pb.GEOM_CYLINDER, p.size
            else:
                # pybullet takes convex hull vertices only from a file, one hull per file.
                kind = pb.GEOM_MESH
                path = os.path.join(self._tmp, f'hull_{i}.obj')
                trimesh.Trimesh(p.vertices, p.faces, process=False).export(path)
            kinds.append(kind)
            radii.append(radius)
            lengths.append(length)
            halves.append(half)
            files.append(path)
            positions.append(list(p.position))
            orientations.append(list(p.orientation))
        return pb.createCollisionShapeArray(
            kinds, radii=radii, lengths=lengths, halfExtents=halves, fileNames=files,
            meshScales=[[1.0, 1.0, 1.0]] * len(kinds), collisionFramePositions=positions,
            collisionFrameOrientations=orientations, physicsClientId=self._client)

    def _create_container(self, spec: containers.ContainerSpec,
                          origin: np.ndarray) -> tuple[int, int | None]:
        c = self._client
        boxes = containers.wall_boxes(spec)
        shape = pb.createCollisionShapeArray(
            [pb.GEOM_BOX] * len(boxes), halfExtents=[list(h) for h, _ in boxes],
            collisionFramePositions=[list(p) for _, p in boxes], physicsClientId=c)
        if spec.kind == containers.BIN:
            body = pb.createMultiBody(0.0, shape, basePosition=origin.tolist(),
                                      useMaximalCoordinates=True, physicsClientId=c)
            pb.changeDynamics(body, -1, lateralFriction=0.5, physicsClientId=c)
            return body, None
        # The tray is dynamic and held on its trajectory by a fixed constraint whose pivot we
        # drive: parts then feel its real velocity (a static body moved by resets does not
        # push them). pybullet's constraints need a multibody base here.
        body = pb.createMultiBody(TRAY_MASS, shape, basePosition=origin.tolist(),
                                  physicsClientId=c)
        pb.changeDynamics(body, -1, lateralFriction=0.5, linearDamping=0.0,
                          angularDamping=0.0, physicsClientId=c)
        constraint = pb.createConstraint(body, -1, -1, -1, pb.JOINT_FIXED, [0, 0, 0],
                                         [0, 0, 0], origin.tolist(), physicsClientId=c)
        pb.changeConstraint(constraint, maxForce=TRAY_MAX_FORCE, physicsClientId=c)
        return body, constraint

    def close(self) -> None:
        """Disconnect from PyBullet and remove temporary files. Idempotent."""
        if self._client is not None and self._client >= 0:
            try:
                pb.disconnect(physicsClientId=self._client)
            except pb.error:
                pass
            self._client = None
        shutil.rmtree(self._tmp, ignore_errors=True)

    def render(self, width: int, height: int, distance: float, yaw: float = 30.0,
               pitch: float = -60.0, target: Sequence[float] = (0.0, 0.0, 0.0),
               overlays: Sequence[Overlay] = ()) -> np.ndarray:
        """A picture of the world from a camera orbiting `target` (world frame, m) at
        `distance` m, `yaw` and `pitch` in degrees, with PyBullet's CPU renderer (no GPU).
        `overlays` are drawn for this picture only (e.g. a gripper). Returns (height, width, 3)
        uint8 RGB."""
        width = check_int('width', width, low=16, high=4096)
        height = check_int('height', height, low=16, high=4096)
        c = self._client
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
                                                 renderer=pb.ER_TINY_RENDERER,
                                                 physicsClientId=c)
        finally:
            for body in bodies:
                pb.removeBody(body, physicsClientId=c)
        return np.asarray(rgba, dtype=np.uint8).reshape(height, width, 4)[:, :, :3]

    def __enter__(self) -> 'World':
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # ----------------------------------------------------------------------------- queries
    def _instance_ids(self, instances: Iterable[int] | None) -> list[int]:
        if instances is None:
            return [inst.id for inst in self._instances]
        ids = []
        for value in instances:
            k = check_int('instances[]', value, low=0, high=2**32 - 1)
            if k >= len(self._instances):
                raise UnknownInstance(f'instances: {k} does not exist (the scene has '
                                      f'{len(self._instances)}: 0..{len(self._instances) - 1})')
            if k not in ids:
                ids.append(k)
        return ids

    def snapshot(self, instances: Iterable[int] | None = None) -> PartStates:
        """Poses of the parts of `instances` (all when None), in their instance frames."""
        wanted = self._instance_ids(instances)
        ids = [pid for k in wanted for pid in self._instances[k].part_ids]
        owners = np.array([self._owner[i] for i in ids], dtype=np.int64)
        poses = self._world_poses(ids)
        if len(ids):
            poses[:, :3] -= np.array([self._instances[k].origin for k in owners])
        inside = np.zeros(len(ids), dtype=bool)
        for k in wanted:
            mask = owners == k
            inside[mask] = containers.inside(self._scene.container, poses[mask, :3])
        return PartStates(np.array(ids, dtype=np.int64), owners, poses, inside, self._sim_time)

    def _world_poses(self, ids: Sequence[int]) -> np.ndarray:
        poses = np.empty((len(ids), 7))
        c = self._client
        for row, pid in enumerate(ids):
            position, orientation = pb.getBasePositionAndOrientation(self._bodies[pid],
                                                                     physicsClientId=c)
            poses[row, :3] = position
            poses[row, 3:] = orientation
        return poses

    # ----------------------------------------------------------------------------- drop
    def drop_region(self, instance: int, zone: str) -> tuple[float, float, float, float]:
        """Centre x, y and half extents x, y of where parts spawn, in the instance frame, m."""
        spec = self._scene.container
        if zone == 'container':
            return 0.0, 0.0, spec.inner_size[0] / 2, spec.inner_size[1] / 2
        if zone == 'feeder':
            if spec.kind != containers.TRAY:
                raise InvalidArgument('zone', zone, f'needs a tray; instance {instance} has a '
                                      f'{spec.kind}, which has no feeder')
            (cx, cy), (sx, sy) = spec.feeder_zone_center, spec.feeder_zone_size
            return cx, cy, sx / 2, sy / 2
        raise InvalidArgument('zone', zone, 'must be container or feeder')

    def spawn_poses(self, instance: int, count: int, zone: str = 'container') -> np.ndarray:
        """Random, non-overlapping spawn poses (count, 7) in the instance frame.

        Parts spawn in layers of a grid of cells as wide as the part's bounding sphere, above
        the parts already there, each with a uniformly random orientation. The grid is shifted
        at random within its slack and each layer takes a random subset of cells. No two
        spawn spheres overlap, so nothing is blown apart (the paper's first problem).
        """
        cx, cy, hx, hy = self.drop_region(instance, zone)
        inst = self._instances[instance]
        rng = inst.rng
        r = self._part.radius + SPAWN_GAP
        cell = 2.0 * r
        span_x, span_y = 2.0 * (hx - r), 2.0 * (hy - r)
        if span_x < 0 or span_y < 0:
            raise InvalidArgument(
                'container.inner_size' if zone == 'container' else 'container.feeder_zone_size',
                (2 * hx, 2 * hy), f'is smaller than the part ({2 * r:.4g} m across in any '
                'orientation): parts cannot be dropped into it')
        nx, ny = int(span_x // cell) + 1, int(span_y // cell) + 1
        per_layer = nx * ny
        state = self.snapshot([instance])
        top = 0.0
        if len(state.ids):
            top = float(state.poses[:, 2].max()) + self._part.radius + np.linalg.norm(
                self._part.center)
        centers = np.empty((count, 3))
        for start in range(0, count, per_layer):
            layer = start // per_layer
            n = min(per_layer, count - start)
            shift_x = rng.uniform(0.0, span_x - (nx - 1) * cell)
            shift_y = rng.uniform(0.0, span_y - (ny - 1) * cell)
            cells = rng.permutation(per_layer)[:n]
            ix, iy = np.divmod(cells, ny)
            centers[start:start + n, 0] = cx - hx + r + shift_x + ix * cell
            centers[start:start + n, 1] = cy - hy + r + shift_y + iy * cell
            centers[start:start + n, 2] = top + r + layer * cell
        quats = random_quaternions(rng, count)
        # The spawn sphere is centred on the compound's bounding-box centre, not the origin.
        origins = centers - rotate(quats, self._part.center)
        return np.hstack([origins, quats])

    def drop(self, count: int, instances: Iterable[int] | None = None, zone: str = 'container',
             max_settle_time: float | None = None,
             progress: ProgressCallback | None = None) -> tuple[list[int], SettleReport]:
        """Drop `count` parts into each instance (or its feeder zone), then settle.

        Returns the new part ids and the settle report. Raises InvalidArgument when the count
        is out of range or the parts do not fit, UnknownInstance for a bad instance id.
        """
        targets = self._instance_ids(instances)
        count = check_int('count', count, low=1, high=MAX_PARTS_PER_INSTANCE)
        inner = float(np.prod(self._scene.container.inner_size))
        for k in targets:
            total = count + len(self._instances[k].part_ids)
            if total > MAX_PARTS_PER_INSTANCE:
                raise InvalidArgument('count', count, f'would put {total} parts in instance {k}'
                                      f' (limit {MAX_PARTS_PER_INSTANCE})')
            if total * self._part.volume > PACKING_LIMIT * inner:
                most = int(PACKING_LIMIT * inner / self._part.volume)
                raise InvalidArgument(
                    'count', count, f'does not fit: {total} parts of {self._part.volume * 1e9:.4g}'
                    f' mm^3 in a container of {inner * 1e9:.4g} mm^3 exceed the packing limit '
                    f'{PACKING_LIMIT:g} (at most {most} parts)')
        spawns = {k: self.spawn_poses(k, count, zone) for k in targets}
        new_ids = []
        for k, poses in spawns.items():
            new_ids += self._add_parts(self._instances[k], poses)
        return new_ids, self._settle('dropping', max_settle_time, progress)

    def _add_parts(self, inst: Instance, poses: np.ndarray) -> list[int]:
        c = self._client
        spec = self._part.spec
        ids = []
        self._at_rest = False
        for pose in poses:
            body = pb.createMultiBody(
                self._part.mass, self._part_shape, basePosition=(pose[:3] + inst.origin).tolist(),
                baseOrientation=pose[3:].tolist(), useMaximalCoordinates=True,
                physicsClientId=c)
            pb.changeDynamics(
                body, -1, lateralFriction=spec.lateral_friction,
                rollingFriction=spec.rolling_friction, spinningFriction=spec.spinning_friction,
                restitution=spec.restitution, ccdSweptSphereRadius=self._part.thinnest,
                activationState=pb.ACTIVATION_STATE_DISABLE_SLEEPING, physicsClientId=c)
            pid = self._next_id
            self._next_id += 1
            self._bodies[pid] = body
            self._owner[pid] = inst.id
            inst.part_ids.append(pid)
            ids.append(pid)
        return ids

    # ----------------------------------------------------------------------------- vibrate
    def vibrate(self, vibration: Vibration, instances: Iterable[int] | None = None,
                max_settle_time: float | None = None,
                progress: ProgressCallback | None = None) -> SettleReport:
        """Move each tray along x(t) = amplitude sin(2 pi f t) for the duration, then settle.

        With direction RANDOM, each tray's horizontal amplitude is first turned about the
        vertical by an angle drawn from its instance's generator (so a seed gives the same
        motions). Raises InvalidArgument for a bad vibration or an instance whose container is
        a bin.
        """
        targets = self._instance_ids(instances)
        check_vibration(vibration)
        omega = 2.0 * math.pi * vibration.frequency
        for k in targets:
            if self._instances[k].constraint is None:
                raise InvalidArgument('instances', k, f'is a {self._scene.container.kind}: '
                                      'only trays vibrate')
        c = self._client
        trays = [self._instances[k] for k in targets]
        amplitudes = np.array([vibration_amplitude(vibration, inst.rng) for inst in trays])
        dt = self._physics.time_step
        steps = max(1, int(round(vibration.duration / dt)))
        step = 0

        def drive() -> None:
            nonlocal step
            step += 1
            phase = math.sin(omega * step * dt)
            for inst, amplitude in zip(trays, amplitudes, strict=True):
                pb.changeConstraint(inst.constraint, jointChildPivot=(
                    inst.origin + amplitude * phase).tolist(), maxForce=TRAY_MAX_FORCE,
                    physicsClientId=c)

        try:
            report = self._run('vibrating', steps * dt, progress, before_step=drive,
                               stop_when_settled=False)
        finally:
            for inst in trays:
                pb.changeConstraint(inst.constraint, jointChildPivot=inst.origin.tolist(),
                                    maxForce=TRAY_MAX_FORCE, physicsClientId=c)
        if report.canceled:
            return report
        settle = self._settle('settling', max_settle_time, progress)
        settle.sim_time += report.sim_time
        settle.wall_time += report.wall_time
        settle.steps += report.steps
        return settle

    # ----------------------------------------------------------------------------- remove
    def remove(self, part_ids: Iterable[int], settle: bool = True,
               max_settle_time: float | None = None,
               progress: ProgressCallback | None = None) -> tuple[list[int], SettleReport]:
        """Remove parts by id (all or none), then settle unless `settle` is False.

        The settle is skipped (a report of 0 steps) when the scene rested after the last
        step run and no removed part touched a part that stays (by the last step's contacts,
        within the contact-breaking threshold): lifting such a part out moves nothing else.
        """
        ids = []
        for value in part_ids:
            pid = check_int('part_ids[]', value, low=0, high=2**32 - 1)
            if pid not in self._bodies:
                raise UnknownPart(f'part_ids: {pid} is not a part of this scene')
            if pid not in ids:
                ids.append(pid)
        if not ids:
            raise InvalidArgument('part_ids', [], 'is empty: name at least one part')
        touched = self._touch_other_parts(ids)
        for pid in ids:
            pb.removeBody(self._bodies.pop(pid), physicsClientId=self._client)
            self._instances[self._owner.pop(pid)].part_ids.remove(pid)
        if settle and (touched or not self._at_rest):
            return ids, self._settle('settling', max_settle_time, progress)
        self._at_rest = self._at_rest and not touched
        return ids, SettleReport(True, 0.0, 0.0, 0, escaped_ids=self._escaped())

    def _touch_other_parts(self, ids: list[int]) -> bool:
        """Whether a part of `ids` touches (is within the contact-breaking threshold of) a part
        not in `ids`, by the contacts of the last step."""
        removed = {self._bodies[pid] for pid in ids}
        containers_ = {inst.body for inst in self._instances}
        for body in removed:
            for contact in pb.getContactPoints(bodyA=body, physicsClientId=self._client):
                other = contact[2]
                if other not in removed and other not in containers_:
                    return True
        return False

    # ----------------------------------------------------------------------------- settle
    def settle(self, max_settle_time: float | None = None,
               progress: ProgressCallback | None = None) -> SettleReport:
        """Step until every part rests or the time cap is hit."""
        return self._settle('settling', max_settle_time, progress)

    def _settle(self, phase: str, max_settle_time: float | None,
                progress: ProgressCallback | None) -> SettleReport:
        cap = self._physics.max_settle_time if not max_settle_time else check_number(
            'max_settle_time', max_settle_time, low=self._physics.settle_window, high=600.0)
        return self._run(phase, cap, progress)

    def _escaped(self) -> list[int]:
        state = self.snapshot()
        return [int(i) for i in state.ids[~state.inside]]

    def _run(self, phase: str, duration: float, progress: ProgressCallback | None,
             before_step: Callable[[], None] | None = None,
             stop_when_settled: bool = True) -> SettleReport:
        """Step for up to `duration` s of simulated time, checking rest every check period.

        A part rests when, over the settle window, its position changed by at most the linear
        tolerance and its orientation by at most the angular tolerance; the scene is settled when
        at most the moving fraction of its parts do not rest. Bullet's sleeping is not used for
        this: it does not trigger for a jittering pile.
        """
        cfg = self._physics
        c = self._client
        dt = cfg.time_step
        per_check = max(1, int(round(cfg.settle_check_period / dt)))
        window = max(1, int(round(cfg.settle_window / cfg.settle_check_period)))
        total_steps = max(1, int(math.ceil(duration / dt - 1e-9)))
        ids = [pid for inst in self._instances for pid in inst.part_ids]
        tolerated = int(cfg.settle_moving_fraction * len(ids))
        history: deque[np.ndarray] = deque(maxlen=window + 1)
        history.append(self._world_poses(ids))
        start = time.perf_counter()
        steps = 0
        moving = np.ones(len(ids), dtype=bool)
        settled = canceled = False
        while steps < total_steps:
            for _ in range(min(per_check, total_steps - steps)):
                if before_step is not None:
                    before_step()
                pb.stepSimulation(physicsClientId=c)
                steps += 1
            poses = self._world_poses(ids)
            if not np.isfinite(poses).all():
                bad = [ids[i] for i in np.flatnonzero(~np.isfinite(poses).all(axis=1))]
                self._build(self._scene, self._part)
                raise PhysicsFault(f'parts {bad[:10]} got non-finite poses after '
                                   f'{steps * dt:.3f} s of {phase}; the scene was reset')
            history.append(poses)
            old = history[0]
            shift = np.linalg.norm(poses[:, :3] - old[:, :3], axis=1)
            turn = quaternion_angles(poses[:, 3:], old[:, 3:])
            moving = (shift > cfg.settle_linear_tolerance) | (turn > cfg.settle_angular_tolerance)
            full = len(history) == history.maxlen
            if progress is not None and not progress(Progress(
                    phase, steps * dt, int(moving.sum()) if full else len(ids),
                    float(shift.max()) if len(ids) else 0.0)):
                canceled = True
                break
            if stop_when_settled and full and moving.sum() <= tolerated:
                settled = True
                break
        self._sim_time += steps * dt
        wall = time.perf_counter() - start
        self._at_rest = settled
        if not stop_when_settled:
            settled = not canceled
        unsettled = [ids[i] for i in np.flatnonzero(moving)]
        return SettleReport(settled, steps * dt, wall, steps, unsettled, self._escaped(),
                            canceled)
