"""The `world` node: a thin ROS 2 wrapper around `pick_sim_world.world.World`.

Topics `parts`, `scene` (latched), `markers` (latched); actions `drop_parts`, `vibrate`,
`remove_parts`; services `reset_scene`, `get_parts`. All names are relative: run it under a
namespace (`--ros-args -r __ns:=/worker_1`) to make a worker.

One physics operation runs at a time. A goal or reset that arrives while one runs is answered
at once with error BUSY (not queued); `get_parts` answers from the last settled snapshot and
never waits for physics.
"""

from collections.abc import Callable
import threading
import traceback

from pick_msgs.action import DropParts, RemoveParts, Vibrate
from pick_msgs.msg import PartArray, Scene
from pick_msgs.srv import GetParts, ResetScene
from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from rclpy.qos_overriding_options import QoSOverridingOptions
from visualization_msgs.msg import MarkerArray

from . import conversions as conv
from .config import check_vibration, FIXED, PhysicsConfig, RANDOM, SceneSpec, Vibration
from .containers import BIN, ContainerSpec, TRAY
from .errors import InvalidArgument, WorldError
from .node_runner import declare_mesh_dirs, LATCHED, RESULT_KEEP, run
from .parts import BUILTIN_MODELS, PartSpec
from .world import Progress, SettleReport, World

ZONES = {DropParts.Goal.ZONE_CONTAINER: 'container', DropParts.Goal.ZONE_FEEDER: 'feeder'}
SHUTDOWN_WAIT = 10.0   # s a shutdown waits for a running physics operation


def _describe(text: str, low: float | None = None, high: float | None = None,
              integer: bool = False) -> ParameterDescriptor:
    descriptor = ParameterDescriptor(description=text, read_only=True)
    if low is not None and integer:
        descriptor.integer_range = [IntegerRange(from_value=int(low), to_value=int(high))]
    elif low is not None:
        descriptor.floating_point_range = [FloatingPointRange(from_value=float(low),
                                                              to_value=float(high))]
    return descriptor


class WorldNode(Node):
    """Translates messages to core calls and back; owns one World."""

    def __init__(self) -> None:
        super().__init__('world')
        scene, physics, self._vibration = self._declare_parameters()
        self._world = World(scene, physics)
        self._lock = threading.Lock()
        self._stopping = False
        group = ReentrantCallbackGroup()
        qos_options = QoSOverridingOptions.with_default_policies()
        self._parts_pub = self.create_publisher(PartArray, 'parts', 10,
                                                qos_overriding_options=qos_options)
        self._scene_pub = self.create_publisher(Scene, 'scene', LATCHED,
                                                qos_overriding_options=qos_options)
        self._markers_pub = self.create_publisher(MarkerArray, 'markers', LATCHED,
                                                  qos_overriding_options=qos_options)
        self.create_service(ResetScene, 'reset_scene', self._reset_scene, callback_group=group)
        self.create_service(GetParts, 'get_parts', self._get_parts, callback_group=group)
        for action_type, name, execute in ((DropParts, 'drop_parts', self._drop_parts),
                                           (Vibrate, 'vibrate', self._vibrate),
                                           (RemoveParts, 'remove_parts', self._remove_parts)):
            ActionServer(self, action_type, name, execute_callback=execute,
                         goal_callback=lambda _goal: GoalResponse.ACCEPT,
                         cancel_callback=lambda _handle: CancelResponse.ACCEPT,
                         callback_group=group, result_timeout=RESULT_KEEP)
        self._states = self._world.snapshot()
        self._publish(scene_changed=True)
        self.get_logger().info(
            f'{scene.instance_count} instance(s) of a {scene.container.kind} with '
            f'{scene.part.model} parts; frames {conv.instance_frame(self._prefix, 0)}...')

    # ----------------------------------------------------------------------------- parameters
    def _declare_parameters(self) -> tuple[SceneSpec, PhysicsConfig, Vibration]:
        """Declare every parameter with a descriptor and build the frozen configs.

        The values are checked by the core (one place); declare only enforces ranges that ROS
        can express.
        """
        def get(name, default, text, low=None, high=None, integer=False):
            return self.declare_parameter(name, default,
                                          _describe(text, low, high, integer)).value

        self._frame_id = get('frame_id', 'world', 'frame of the scene and of instance frames')
        prefix = get('frame_prefix', '', 'prefix of instance frame names; empty: the node '
                     'namespace, e.g. worker_1/instance_0')
        namespace = self.get_namespace().strip('/')
        self._prefix = prefix or (f'{namespace}/' if namespace else '')

        kind = get('container.kind', BIN, f'{BIN} or {TRAY}')
        base = ContainerSpec.tray() if kind == TRAY else ContainerSpec()
        container = ContainerSpec(
            kind=kind,
            inner_size=tuple(get('container.inner_size', list(base.inner_size),
                                 'inner length, width, height, m')),
            wall_thickness=get('container.wall_thickness', base.wall_thickness, 'm',
                               0.0005, 0.1),
            floor_thickness=get('container.floor_thickness', base.floor_thickness, 'm',
                                0.001, 0.2),
            feeder_zone_center=tuple(get('container.feeder_zone_center',
                                         list(base.feeder_zone_center),
                                         'centre x, y of the tray feeder zone, m')),
            feeder_zone_size=tuple(get('container.feeder_zone_size',
                                       list(base.feeder_zone_size),
                                       'x, y extent of the tray feeder zone, m')))
        model = get('part.model', 'radial_capacitor',
                    f'built-in model ({", ".join(BUILTIN_MODELS)}) or mesh')
        dims, default_mass = {}, 0.0
        if model in BUILTIN_MODELS:
            defaults, default_mass, _ = BUILTIN_MODELS[model]
            dims = {name: get(f'part.{name}', value, f'{model} dimension, m'
                              if name != 'pins_per_row' else 'pins per row')
                    for name, value in defaults.items()}
        mass = get('part.mass', default_mass, 'kg (0 for the model default)', 0.0, 10.0)
        spec = PartSpec()
        part = PartSpec(
            model=model, dimensions=dims, mass=mass or None,
            lateral_friction=get('part.lateral_friction', spec.lateral_friction,
                                 'Coulomb coefficient', 0.0, 10.0),
            rolling_friction=get('part.rolling_friction', spec.rolling_friction,
                                 'rolling resistance arm, m', 0.0, 0.1),
            spinning_friction=get('part.spinning_friction', spec.spinning_friction,
                                  'torsional friction arm, m', 0.0, 0.1),
            restitution=get('part.restitution', spec.restitution, '1', 0.0, 1.0),
            mesh_path=get('part.mesh_path', '', 'STL/OBJ/PLY file for part.model mesh'),
            scale=get('part.scale', 1.0, 'mesh scale to metres', 1e-6, 1e3))
        scene = SceneSpec(container, part,
                          get('instances', 1, 'independent instances', 1, 64, integer=True),
                          get('seed', 0, 'base seed of the instances', 0, 2**62, integer=True))
        cfg = PhysicsConfig()
        physics = PhysicsConfig(
            time_step=get('physics.time_step', cfg.time_step, 's', 1e-5, 0.01),
            solver_iterations=get('physics.solver_iterations', cfg.solver_iterations,
                                  'solver iterations per step', 1, 500, integer=True),
            contact_breaking_threshold=get('physics.contact_breaking_threshold',
                                           cfg.contact_breaking_threshold, 'm', 1e-5, 0.1),
            settle_check_period=get('settle.check_period', cfg.settle_check_period,
                                    'simulated s between rest checks', 1e-5, 1.0),
            settle_window=get('settle.window', cfg.settle_window,
                              'simulated s over which a part must stay put', 1e-5, 10.0),
            settle_linear_tolerance=get('settle.linear_tolerance', cfg.settle_linear_tolerance,
                                        'largest position change at rest over the window, m',
                                        1e-7, 0.1),
            settle_angular_tolerance=get('settle.angular_tolerance',
                                         cfg.settle_angular_tolerance,
                                         'largest rotation at rest over the window, rad',
                                         1e-6, 3.2),
            settle_moving_fraction=get('settle.moving_fraction', cfg.settle_moving_fraction,
                                       'largest fraction of parts still moving when settled',
                                       0.0, 0.5),
            max_settle_time=get('settle.max_time', cfg.max_settle_time,
                                'cap on simulated settle time, s', 1e-3, 600.0))
        vib = Vibration()
        vibration = Vibration(
            amplitude=tuple(get('vibration.amplitude', list(vib.amplitude),
                                'default peak tray displacement x, y, z, m')),
            frequency=get('vibration.frequency', vib.frequency, 'default frequency, Hz',
                          0.1, 500.0),
            duration=get('vibration.duration', vib.duration, 'default duration, s',
                         1e-3, 60.0),
            direction=get('vibration.direction', vib.direction,
                          f'default direction: {FIXED} (the amplitude as given) or {RANDOM} '
                          '(its horizontal part turned by a random angle per vibration)'))
        self._publish_markers = get('publish_markers', True, 'publish `markers` after each '
                                    'operation')
        self._mesh_dirs = declare_mesh_dirs(self)
        return scene, physics, check_vibration(vibration)

    # ----------------------------------------------------------------------------- publish
    def _publish(self, scene_changed: bool = False) -> PartArray:
        """Publish the current snapshot (and the scene when it changed); return the parts."""
        stamp = self.get_clock().now().to_msg()
        if scene_changed:
            self._scene_msg = conv.scene_to_msg(self._world, stamp, self._frame_id,
                                                self._prefix)
            self._scene_pub.publish(self._scene_msg)
        parts = conv.states_to_msg(self._states, stamp, self._frame_id, self._prefix)
        self._parts_pub.publish(parts)
        if self._publish_markers:
            self._markers_pub.publish(conv.markers_msg(self._world, self._states, stamp,
                                                       self._prefix))
        return parts

    def _parts_msg(self, instances) -> PartArray:
        states = self._states if instances is None else self._states.select(instances)
        return conv.states_to_msg(states, self.get_clock().now().to_msg(), self._frame_id,
                                  self._prefix)

    # ----------------------------------------------------------------------------- services
    def _get_parts(self, request: GetParts.Request,
                   response: GetParts.Response) -> GetParts.Response:
        wanted = list(request.instances)
        count = self._world.scene.instance_count
        unknown = [k for k in wanted if k >= count]
        if unknown:
            response.error_code = conv.ERROR_UNKNOWN_INSTANCE
            response.error_msg = (f'instances: {unknown[0]} does not exist (the scene has '
                                  f'{count}: 0..{count - 1})')
            return response
        response.parts = self._parts_msg(wanted or None)
        return response

    def _reset_scene(self, request: ResetScene.Request,
                     response: ResetScene.Response) -> ResetScene.Response:
        def reset() -> None:
            if request.keep_scene:
                self._world.reset(seed=request.seed)
            else:
                self._world.reset(SceneSpec(
                    conv.container_from_msg(request.container),
                    conv.part_spec_from_msg(request.part_model, self._mesh_dirs),
                    request.instance_count,
                    request.seed))

        if self._guarded(reset, response):
            self._states = self._world.snapshot()
            self._publish(scene_changed=True)
            response.scene = self._scene_msg
        return response

    def _guarded(self, operation: Callable[[], object], response) -> bool:
        """Run one world operation under the lock; on failure fill error_code/error_msg.

        Returns True on success. Core errors become their code and are logged once; anything
        else is a bug, logged with its traceback and answered INTERNAL: the node keeps serving.
        """
        if not self._lock.acquire(blocking=False):
            response.error_code = conv.ERROR_BUSY
            response.error_msg = ('another physics operation is running; requests are not '
                                  'queued: retry when it ends')
            return False
        try:
            operation()
            return True
        except WorldError as exc:
            response.error_code = conv.error_code(exc)
            response.error_msg = str(exc)
            self.get_logger().warning(f'request refused: {exc}')
        except Exception as exc:  # a bug: answer, log, keep serving
            response.error_code = conv.ERROR_INTERNAL
            response.error_msg = f'internal error: {type(exc).__name__}: {exc}'
            self.get_logger().error(f'{response.error_msg}\n{traceback.format_exc()}')
        finally:
            if response.error_code == conv.ERROR_PHYSICS_FAULT:
                self._states = self._world.snapshot()
                self._publish(scene_changed=True)
            self._lock.release()
        return False

    # ----------------------------------------------------------------------------- actions
    def _execute(self, action_type, goal_handle, result,
                 operation: Callable[[Callable], SettleReport], instances) -> object:
        """Run a physics action: feedback per settle check, cancel, errors, publishing."""
        settle: list[SettleReport] = []

        def progress(p: Progress) -> bool:
            if self._stopping:   # shutting down: end the operation at this settle check
                return False
            goal_handle.publish_feedback(action_type.Feedback(progress=conv.progress_to_msg(p)))
            return not goal_handle.is_cancel_requested

        ok = self._guarded(lambda: settle.append(operation(progress)), result)
        if ok:
            report = settle[0]
            result.settle = conv.settle_to_msg(report)
            self._states = self._world.snapshot()
            published = self._publish()
            result.parts = published if instances is None else self._parts_msg(instances)
            if report.canceled:
                result.error_code = conv.ERROR_CANCELED
                result.error_msg = 'canceled: parts are where they stopped'
                goal_handle.canceled()
                return result
            goal_handle.succeed()
        else:
            goal_handle.abort()
        return result

    def _drop_parts(self, goal_handle) -> DropParts.Result:
        goal = goal_handle.request
        result = DropParts.Result()
        instances = list(goal.instances) or None

        def drop(progress) -> SettleReport:
            if goal.zone not in ZONES:
                raise InvalidArgument('zone', goal.zone, f'must be one of {sorted(ZONES)}')
            ids, report = self._world.drop(
                goal.count, instances, ZONES[goal.zone],
                conv.or_default('max_settle_time', goal.max_settle_time, None), progress)
            result.part_ids = ids
            return report

        return self._execute(DropParts, goal_handle, result, drop, instances)

    def _vibrate(self, goal_handle) -> Vibrate.Result:
        goal = goal_handle.request
        instances = list(goal.instances) or None

        def vibrate(progress) -> SettleReport:
            a = goal.amplitude
            amplitude = (a.x, a.y, a.z) if (a.x, a.y, a.z) != (0.0, 0.0, 0.0) \
                else self._vibration.amplitude
            vibration = Vibration(
                amplitude=amplitude,
                frequency=conv.or_default('frequency', goal.frequency,
                                          self._vibration.frequency),
                duration=conv.or_default('duration', goal.duration, self._vibration.duration),
                direction=conv.direction_from_msg(goal.direction, self._vibration.direction))
            return self._world.vibrate(
                vibration, instances,
                conv.or_default('max_settle_time', goal.max_settle_time, None), progress)

        return self._execute(Vibrate, goal_handle, Vibrate.Result(), vibrate, instances)

    def _remove_parts(self, goal_handle) -> RemoveParts.Result:
        goal = goal_handle.request
        result = RemoveParts.Result()

        def remove(progress) -> SettleReport:
            removed, report = self._world.remove(
                list(goal.part_ids), not goal.skip_settle,
                conv.or_default('max_settle_time', goal.max_settle_time, None), progress)
            result.removed_ids = removed
            return report

        return self._execute(RemoveParts, goal_handle, result, remove, None)

    def destroy_node(self) -> None:
        """Stop serving first, then close PyBullet once no operation holds it: a disconnect
        under a running step is a native crash."""
        self._stopping = True
        super().destroy_node()
        if not self._lock.acquire(timeout=SHUTDOWN_WAIT):
            # PyBullet is still stepping (an operation with no settle check yet, such as
            # adding thousands of parts): closing it now would crash; the process exit does.
            self.get_logger().error(f'a physics operation still ran after {SHUTDOWN_WAIT:g} s; '
                                    'PyBullet is left to the process exit')
            return
        self._world.close()
        self._lock.release()


def main(args=None) -> None:
    run('world', WorldNode, lambda: MultiThreadedExecutor(num_threads=3), args)
