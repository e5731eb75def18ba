"""The physics world: one PyBullet client holding N independent instances side by side, each
with its own container, parts and random generator (the paper's "demo instances", figure 10).
It drops and feeds parts, vibrates trays, removes parts, and settles.

Pure core: PyBullet (DIRECT mode, through engine.py, which simulates in centimetres and
speaks SI), numpy and trimesh; no rclpy. `World` keeps the scene's state and delegates:
bodies.py builds the scene, selection.py checks what a request names, spawning.py and
hopper.py place new parts, tray.py moves the trays, stepping.py steps until the parts rest,
health.py tells how an operation ended, camera.py takes pictures.

Poses are (N, 7) float64 arrays, xyz in metres then an xyzw unit quaternion, expressed in the
instance frame (origin at the centre of the container's inner floor, +Z up).
"""

from collections.abc import Callable, Iterable, Sequence
from contextlib import nullcontext
from dataclasses import replace
from functools import partial
import math
import os
import shutil
import tempfile

import numpy as np
from pick_common import containers
from pick_common.errors import check_number, InvalidArgument, PhysicsFault
from pick_common.parts.geometry import build_part, PartGeometry
from pick_common.parts.materials import body_values
from pick_common.specs import CENTRE, check_scene, check_vibration, SceneSpec, Vibration
from pick_common.states import PartStates, Progress, SettleReport

from . import bodies, camera, health, hopper, selection, spawning, stepping
from .bodies import Instance
from .camera import Overlay
from .config import check_physics, PhysicsConfig
from .engine import Engine
from .freezing import Freezer
from .stepping import ProgressCallback
from .tray import to_centre_of, TrayDrive, vibration_plan


class World:
    """A PyBullet world of N instances. Not thread-safe: one caller at a time."""

    def __init__(self, scene: SceneSpec | None = None,
                 physics: PhysicsConfig | None = None) -> None:
        self._physics = check_physics(physics or PhysicsConfig())
        self._engine = Engine(self._physics.length_unit)
        self._tmp = tempfile.mkdtemp(prefix='pick_sim_world_')
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
    def engine(self) -> Engine:
        """The engine the world steps (engine.py): its bodies' states in SI units."""
        return self._engine

    def body(self, part_id: int) -> int:
        """The engine's body of a part. Raises UnknownPart for an id not in the scene."""
        return self._bodies[selection.part_ids([part_id], self._bodies)[0]]

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
        All is checked first: a bad scene raises and leaves the world as it was."""
        scene = scene or self._scene
        if seed is not None:
            scene = SceneSpec(scene.container, scene.part, scene.instance_count, seed)
        check_scene(scene)
        part = build_part(scene.part)
        self._build(scene, part)

    def _build(self, scene: SceneSpec, part: PartGeometry) -> None:
        c = self._engine
        bodies.configure(c, self._physics, scene.container.kind)
        self._scene, self._part = scene, part
        self._hull = part.visual.convex_hull.vertices     # a part's lowest point (hopper.py)
        self._bodies: dict[int, int] = {}        # part id -> body
        self._owner: dict[int, int] = {}         # part id -> instance id
        self._next_id, self._sim_time = 0, 0.0
        self._at_rest = True     # the last step run ended settled (the settle criterion)
        self._peaks: dict[int, float] = {}   # part id -> peak speed in this operation, m/s
        # part id -> (world position, m; speed, m/s): parts landed beside their container in
        # this operation, parked until its end (stepping.step)
        self._landed: dict[int, tuple[np.ndarray, float]] = {}
        self._tray_speed = 0.0               # the tray's peak speed in this operation, m/s
        shutil.rmtree(self._tmp, ignore_errors=True)
        os.makedirs(self._tmp)
        self._part_shape = bodies.create_part_shape(c, part, self._tmp)
        self._part_values, surface = body_values(part.spec.part_on_surface,
                                                 part.spec.part_on_part)
        self._instances = bodies.create_instances(c, scene, surface)
        self._drive = None
        if scene.container.kind == containers.TRAY:
            self._drive = TrayDrive(c, [i.body for i in self._instances],
                                    [i.origin for i in self._instances], bodies.TRAY_MASS)

    def close(self) -> None:
        """Disconnect from PyBullet and remove temporary files. Idempotent."""
        self._engine.close()
        shutil.rmtree(self._tmp, ignore_errors=True)

    def render(self, width: int, height: int, distance: float, yaw: float = 30.0,
               pitch: float = -60.0, target: Sequence[float] = (0.0, 0.0, 0.0),
               overlays: Sequence[Overlay] = ()) -> np.ndarray:
        """A picture of the world (camera.render): (height, width, 3) uint8 RGB."""
        return camera.render(self._engine, width, height, distance, yaw, pitch, target,
                             overlays)

    def __enter__(self) -> 'World':
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # ----------------------------------------------------------------------------- queries
    def _instance_ids(self, instances: Iterable[int] | None) -> list[int]:
        return selection.instance_ids(instances, len(self._instances))

    def _centres(self, k: int) -> np.ndarray:
        """The bounding-sphere centres (N, 3) of instance k's parts, in its frame, m."""
        return bodies.part_centres(self.snapshot([k]).poses, self._part)

    def snapshot(self, instances: Iterable[int] | None = None) -> PartStates:
        """Poses of the parts of `instances` (all when None), in their instance frames."""
        wanted = self._instance_ids(instances)
        ids = [pid for k in wanted for pid in self._instances[k].part_ids]
        owners = np.array([self._owner[i] for i in ids], dtype=np.int64)
        base = self._engine.poses([self._bodies[i] for i in ids])
        if len(ids):
            base[:, :3] -= np.array([self._instances[k].origin for k in owners])
        inside = np.zeros(len(ids), dtype=bool)
        for k in wanted:     # judged at the mass centre (a built-in's frame origin)
            mask = owners == k
            inside[mask] = containers.inside(self._scene.container, base[mask, :3])
        poses = bodies.part_frame_poses(base, self._part)
        return PartStates(np.array(ids, dtype=np.int64), owners, poses, inside, self._sim_time)

    # ----------------------------------------------------------------------------- drop
    def drop(self, count: int, instances: Iterable[int] | None = None, zone: str = 'container',
             max_settle_time: float | None = None,
             progress: ProgressCallback | None = None) -> tuple[list[int], SettleReport]:
        """Drop `count` parts into each instance as a stream of spawn layers (spawning.layer,
        each when the last has landed: never a tall column, which sent parts through a 10 mm
        floor), or feed them from the tray's hopper (zone 'feeder', `_feed`); then settle.
        The new part ids and the operation's report. Raises InvalidArgument for a count out
        of range or parts that do not fit, UnknownInstance for a bad instance id."""
        targets = self._instance_ids(instances)
        count = spawning.check_count(count, {k: len(self._instances[k].part_ids)
                                             for k in targets}, self._part, self._scene.container)
        if zone == 'feeder':
            return self._feed(targets, count, max_settle_time, progress)
        spec = self._scene.container
        per_layer = {k: int(np.prod(spawning.grid(self._part, spawning.drop_region(spec, zone, k),
                                                  zone))) for k in targets}
        left = dict.fromkeys(targets, count)

        def layer(_turn: int, new_ids: list[int]) -> bool:
            for k in targets:
                if n := min(per_layer[k], left[k]):
                    inst = self._instances[k]
                    new_ids += self._add_parts(inst, spawning.layer(
                        inst.rng, self._part, spec, zone, self._centres(k), n))
                    left[k] -= n
            return any(left.values())

        return self._stream(layer, spawning.layer_interval(
            self._part, containers.drop_height(spec)), max_settle_time, progress)

    def _feed(self, targets: list[int], count: int, max_settle_time: float | None,
              progress: ProgressCallback | None) -> tuple[list[int], SettleReport]:
        """Run each tray's hopper for count / rate s (hopper.py), a part leaving its outlet
        each 1 / rate s where its place is free; what the time did not let out stays in it."""
        out = hopper.outlet(self._scene.container, targets[0])

        def release(turn: int, new_ids: list[int]) -> bool:
            for k in targets if turn < count else ():
                pose = hopper.release(self._instances[k].rng, self._part, self._hull, out,
                                      self.snapshot([k]).poses)
                if pose is not None:
                    new_ids += self._add_parts(self._instances[k], pose[None], out.velocity)
            return turn < count

        return self._stream(release, 1.0 / out.rate, max_settle_time, progress)

    def _stream(self, add: Callable[[int, list[int]], bool], interval: float, max_settle_time:
                float | None, progress: ProgressCallback | None) -> tuple[list[int], SettleReport]:
        """Add parts turn by turn (`add(turn, new_ids)`: true while `interval` s are stepped
        before the next), landed parts frozen meanwhile; then settle. New ids and report."""
        new_ids: list[int] = []
        stream: list[SettleReport] = []
        with self._freezer() as freezer:
            turn = 0
            while add(turn, new_ids):
                stream.append(self._run('dropping', interval, progress, stop_when_settled=False,
                                        freezer=freezer))
                if stream[-1].canceled:
                    break
                turn += 1
            if not stream or not stream[-1].canceled:
                stream.append(self._settle('dropping', max_settle_time, progress, freezer))
        return new_ids, self._finished(stream[-1], stream[:-1])

    def _add_parts(self, inst: Instance, poses: np.ndarray,
                   velocity: Sequence[float] | None = None) -> list[int]:
        """New parts at `poses` (instance frame), moving at `velocity` (m/s) or at rest."""
        self._at_rest = False
        ids = list(range(self._next_id, self._next_id + len(poses)))
        self._next_id += len(poses)
        for pid, pose in zip(ids, poses, strict=True):
            self._bodies[pid] = bodies.create_part(
                self._engine, self._part_shape, self._part,
                np.concatenate([pose[:3] + inst.origin, pose[3:]]), self._part_values)
            self._owner[pid] = inst.id
            if velocity is not None:
                self._engine.set_velocity(self._bodies[pid], velocity)
        inst.part_ids += ids
        return ids

    # ----------------------------------------------------------------------------- vibrate
    def vibrate(self, vibration: Vibration, instances: Iterable[int] | None = None,
                max_settle_time: float | None = None,
                progress: ProgressCallback | None = None) -> SettleReport:
        """Move each tray along x(t) = amplitude sin(2 pi f t) for the duration (turned at
        random by the instance's generator for RANDOM, toward the tray's centre for CENTRE:
        tray.vibration_plan), then settle. Raises InvalidArgument for a bad vibration or an
        instance whose container is a bin."""
        targets = self._instance_ids(instances)
        check_vibration(vibration)
        if self._drive is None:
            raise InvalidArgument('instances', targets[0], f'is a {self._scene.container.kind}'
                                  ': only trays vibrate')
        to_centre = [to_centre_of(self.snapshot([k])) if vibration.direction == CENTRE else None
                     for k in targets]
        size = self._scene.container.inner_size
        amplitudes, dt, steps, own = vibration_plan(
            vibration, [self._instances[k].rng for k in targets], to_centre,
            self._physics.time_step, (size[0] / 2, size[1] / 2))
        self._drive.start(targets, amplitudes, vibration.frequency, dt, own)
        self._tray_speed = float(np.linalg.norm(amplitudes, axis=1).max()
                                 * 2.0 * math.pi * vibration.frequency)
        try:
            report = self._run('vibrating', steps * dt, progress and partial(
                _with_tray, progress, self._drive), stop_when_settled=False, time_step=dt)
        finally:
            delivered = self._drive.stop()
        report.tray = delivered
        if report.canceled:
            return self._finished(report)
        settle = self._finished(self._settle('settling', max_settle_time, progress), [report])
        settle.tray = delivered
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
        ids = selection.part_ids(part_ids, self._bodies)
        touching = bodies.parts_touching(self._engine, self._bodies, ids)
        # From a scene at rest only the parts the removed ones touched settle at first; the
        # rest felt no force change and start frozen, waking when a part nears (freezing.py).
        local = self._at_rest and self._physics.settle_freeze
        for pid in ids:
            self._take_out(pid)
        if settle and (touching or not self._at_rest):
            asleep = [b for p, b in self._bodies.items() if p not in touching] if local else []
            return ids, self._finished(self._settle('settling', max_settle_time, progress,
                                                    asleep=asleep))
        self._at_rest = self._at_rest and not touching
        return ids, self._finished(SettleReport(True, 0.0, 0.0, 0))

    def _take_out(self, pid: int) -> np.ndarray:
        """Take part `pid` out of the simulation; its instance's origin (world frame, m)."""
        self._engine.remove(self._bodies.pop(pid))
        inst = self._instances[self._owner.pop(pid)]
        inst.part_ids.remove(pid)
        return inst.origin

    # ----------------------------------------------------------------------------- settle
    def settle(self, max_settle_time: float | None = None,
               progress: ProgressCallback | None = None) -> SettleReport:
        """Step until every part rests or the time cap is hit."""
        return self._finished(self._settle('settling', max_settle_time, progress))

    def advance(self, duration: float, progress: ProgressCallback | None = None
                ) -> SettleReport:
        """Step every part for `duration` s of simulated time (0 < duration <= 600), whether
        the parts rest or not: how a settled pile creeps, or a scene watched over time. No
        part is frozen. The report's `settled` says whether the parts rested at its end."""
        duration = check_number('duration', duration, low=0.0, high=600.0, low_open=True)
        return self._finished(self._run('settling', duration, progress,
                                        stop_when_settled=False))

    def _settle(self, phase: str, max_settle_time: float | None,
                progress: ProgressCallback | None, freezer: Freezer | None = None,
                asleep: Iterable[int] = ()) -> SettleReport:
        """Step until the parts rest, freezing with the operation's `freezer`, or else with
        a freezer of its own in which the bodies `asleep` start frozen."""
        cap = self._physics.max_settle_time if not max_settle_time else check_number(
            'max_settle_time', max_settle_time, low=self._physics.settle_window, high=600.0)
        if freezer is not None:
            return self._run(phase, cap, progress, freezer=freezer)
        with self._freezer() as own:
            if own is not None:
                own.freeze(asleep)
            return self._run(phase, cap, progress, freezer=own)

    def _freezer(self) -> Freezer | nullcontext:
        """What holds resting parts frozen through one operation's falls and settles, the trays
        static meanwhile (freezing.py): a Freezer, or with `settle_freeze` off None's context."""
        p = self._physics
        if not p.settle_freeze:
            return nullcontext()
        trays = [inst.body for inst in self._instances] if self._drive is not None else []
        return Freezer(self._engine, trays, p.settle_linear_tolerance,
                       p.settle_angular_tolerance, p.settle_window)

    def _finished(self, last: SettleReport, before: Sequence[SettleReport] = ()) -> SettleReport:
        """The report of a whole operation, once, at its end (health.finished), with the
        operation's peak speeds: they start again from zero. The parts that landed beside
        their container in it are taken out of the simulation and reported spilled, with where
        they landed and how fast."""
        landed = {pid: (at - self._take_out(pid), v) for pid, (at, v) in self._landed.items()}
        self._landed = {}
        report = health.finished(last, before, self._engine, self._scene.container, self._part,
                                 self.snapshot(), self._peaks, self._tray_speed, landed)
        self._peaks, self._tray_speed = {}, 0.0
        return report

    def _run(self, phase: str, duration: float, progress: ProgressCallback | None,
             stop_when_settled: bool = True, time_step: float | None = None,
             freezer: Freezer | None = None) -> SettleReport:
        """Step every part of the scene for up to `duration` s (stepping.step) at `time_step`
        (the physics step when None), freezing and waking parts with `freezer`. A fault
        resets the scene before it is raised. The report has no health yet: an operation made
        of several runs gets it once (`_finished`)."""
        ids = [pid for inst in self._instances for pid in inst.part_ids
               if pid not in self._landed]
        physics = self._physics
        if time_step is not None and time_step != physics.time_step:
            physics = replace(physics, time_step=time_step)
        c = self._engine
        c.set_time_step(physics.time_step)
        origins = np.array([self._instances[self._owner[i]].origin for i in ids]).reshape(-1, 3)
        try:
            out = stepping.step(c, ids, [self._bodies[i] for i in ids], physics, phase,
                                duration, progress, self._drive, stop_when_settled,
                                floor=-self._scene.container.floor_thickness, freezer=freezer,
                                beside=partial(stepping.landed, self._scene.container,
                                               origins, self._part.radius))
        except PhysicsFault:
            if freezer is not None:
                freezer.abandon()
            self._build(self._scene, self._part)
            raise
        finally:
            c.set_time_step(self._physics.time_step)
        self._landed.update(out.landed)
        self._sim_time += out.steps * physics.time_step
        self._at_rest = out.settled
        for pid, speed in zip(ids, out.peak_speeds, strict=True):
            self._peaks[pid] = max(speed, self._peaks.get(pid, 0.0))
        settled = out.settled if stop_when_settled else not out.canceled
        return SettleReport(settled, out.steps * physics.time_step, out.wall_time, out.steps,
                            out.moving_ids, canceled=out.canceled)


def _with_tray(progress: ProgressCallback, drive: TrayDrive, p: Progress) -> bool:
    """Tell `progress` of a vibration's step with the trays' motion so far (Progress.tray)."""
    return progress(replace(p, delivered=drive.motion))
