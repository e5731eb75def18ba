"""The physics world: one PyBullet client holding N independent instances side by side, each
with its own container, parts and random generator (the paper's "demo instances", figure 10).
It drops and feeds parts, vibrates trays, removes parts, and settles.

Pure core: PyBullet (DIRECT mode), numpy and trimesh; no rclpy. `World` keeps the scene's
state and delegates: bodies.py builds the scene, spawning.py places new parts, tray.py moves
the trays, stepping.py steps until the parts rest, camera.py takes pictures.

Poses are (N, 7) float64 arrays, xyz in metres then an xyzw unit quaternion, expressed in the
instance frame (origin at the centre of the container's inner floor, +Z up).
"""

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
import os
import shutil
import tempfile

import numpy as np
from pick_common import containers
from pick_common.containers import check_fits
from pick_common.errors import (
    check_int,
    check_number,
    InvalidArgument,
    PhysicsFault,
    UnknownInstance,
    UnknownPart,
)
from pick_common.parts import build_part, PartGeometry
from pick_common.specs import (
    check_scene,
    check_vibration,
    MAX_PARTS_PER_INSTANCE,
    SceneSpec,
    Vibration,
)
from pick_common.states import PartStates, SettleReport
import pybullet as pb

from . import bodies, camera, spawning, stepping
from .camera import Overlay
from .config import check_physics, PhysicsConfig
from .stepping import ProgressCallback
from .tray import TrayDrive, vibration_amplitude


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
        bodies.configure(c, self._physics)
        self._scene, self._part = scene, part
        self._instances, self._bodies, self._owner = [], {}, {}
        self._next_id, self._sim_time = 0, 0.0
        self._at_rest = True     # the last step run ended settled (the settle criterion)
        shutil.rmtree(self._tmp, ignore_errors=True)
        os.makedirs(self._tmp)
        self._part_shape = bodies.create_part_shape(c, part, self._tmp)
        pitch = bodies.instance_pitch(scene.container)
        for k in range(scene.instance_count):
            origin = np.array([k * pitch, 0.0, 0.0])
            body, constraint = bodies.create_container(c, scene.container, origin)
            seed = bodies.instance_seed(scene.seed, k)
            self._instances.append(Instance(k, seed, origin, body, constraint,
                                            np.random.default_rng(seed)))

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
        """A picture of the world (camera.render): (height, width, 3) uint8 RGB."""
        return camera.render(self._client, width, height, distance, yaw, pitch, target,
                             overlays)

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
        poses = bodies.base_poses(self._client, [self._bodies[i] for i in ids])
        if len(ids):
            poses[:, :3] -= np.array([self._instances[k].origin for k in owners])
        inside = np.zeros(len(ids), dtype=bool)
        for k in wanted:
            mask = owners == k
            inside[mask] = containers.inside(self._scene.container, poses[mask, :3])
        return PartStates(np.array(ids, dtype=np.int64), owners, poses, inside, self._sim_time)

    # ----------------------------------------------------------------------------- drop
    def drop_region(self, instance: int, zone: str) -> tuple[float, float, float, float]:
        """Centre x, y and half extents x, y of where parts spawn, in the instance frame, m."""
        return spawning.drop_region(self._scene.container, zone, instance)

    def spawn_poses(self, instance: int, count: int, zone: str = 'container') -> np.ndarray:
        """Random, non-overlapping spawn poses (count, 7) in the instance frame, above the parts
        already in the instance (spawning.spawn_poses)."""
        region = self.drop_region(instance, zone)
        state = self.snapshot([instance])
        top = 0.0
        if len(state.ids):
            top = float(state.poses[:, 2].max()) + self._part.radius + np.linalg.norm(
                self._part.center)
        return spawning.spawn_poses(self._instances[instance].rng, self._part, region, top,
                                    count, zone)

    def drop(self, count: int, instances: Iterable[int] | None = None, zone: str = 'container',
             max_settle_time: float | None = None,
             progress: ProgressCallback | None = None) -> tuple[list[int], SettleReport]:
        """Drop `count` parts into each instance (or its feeder zone), then settle.

        Returns the new part ids and the settle report. Raises InvalidArgument when the count
        is out of range or the parts do not fit, UnknownInstance for a bad instance id.
        """
        targets = self._instance_ids(instances)
        count = check_int('count', count, low=1, high=MAX_PARTS_PER_INSTANCE)
        for k in targets:
            total = count + len(self._instances[k].part_ids)
            if total > MAX_PARTS_PER_INSTANCE:
                raise InvalidArgument('count', count, f'would put {total} parts in instance {k}'
                                      f' (limit {MAX_PARTS_PER_INSTANCE})')
            # The rule is on the instance's total: name what the number is when parts are there.
            held = total - count
            check_fits('count' if not held else f'count + the {held} parts in instance {k}',
                       total, self._part.volume, self._scene.container)
        spawns = {k: self.spawn_poses(k, count, zone) for k in targets}
        new_ids = []
        for k, poses in spawns.items():
            new_ids += self._add_parts(self._instances[k], poses)
        return new_ids, self._settle('dropping', max_settle_time, progress)

    def _add_parts(self, inst: Instance, poses: np.ndarray) -> list[int]:
        ids = []
        self._at_rest = False
        for pose in poses:
            world_pose = np.concatenate([pose[:3] + inst.origin, pose[3:]])
            body = bodies.create_part(self._client, self._part_shape, self._part, world_pose)
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
        for k in targets:
            if self._instances[k].constraint is None:
                raise InvalidArgument('instances', k, f'is a {self._scene.container.kind}: '
                                      'only trays vibrate')
        trays = [self._instances[k] for k in targets]
        amplitudes = np.array([vibration_amplitude(vibration, inst.rng) for inst in trays])
        dt = self._physics.time_step
        steps = max(1, int(round(vibration.duration / dt)))
        drive = TrayDrive(self._client, [inst.constraint for inst in trays],
                          [inst.origin for inst in trays], amplitudes, vibration.frequency, dt)
        try:
            report = self._run('vibrating', steps * dt, progress, before_step=drive,
                               stop_when_settled=False)
        finally:
            drive.home()
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
        """Step every part of the scene for up to `duration` s (stepping.step); a fault resets
        the scene before it is raised."""
        ids = [pid for inst in self._instances for pid in inst.part_ids]
        try:
            out = stepping.step(self._client, ids, [self._bodies[i] for i in ids],
                                self._physics, phase, duration, progress, before_step,
                                stop_when_settled)
        except PhysicsFault:
            self._build(self._scene, self._part)
            raise
        self._sim_time += out.steps * self._physics.time_step
        self._at_rest = out.settled
        settled = out.settled if stop_when_settled else not out.canceled
        return SettleReport(settled, out.steps * self._physics.time_step, out.wall_time,
                            out.steps, out.moving_ids, self._escaped(), out.canceled)
