"""The `world` node: a thin ROS 2 wrapper around `pick_sim_world.world.World`.

Topics `parts`, `scene` (latched), `markers` (latched, in the parts' frames on /tf); actions
`drop_parts`, `vibrate`, `remove_parts`; services `reset_scene`, `get_parts`. Names are
relative: run it under a namespace (`--ros-args -r __ns:=/worker_1`) to make a worker.

One physics operation runs at a time. A goal or reset that arrives while one runs is answered
at once with error BUSY (not queued); `get_parts` answers from the last settled snapshot and
never waits for physics.
"""

from collections.abc import Callable
import threading
import time

from pick_common import containers, specs
from pick_common import conversions as common
from pick_common.containers import BIN, ContainerSpec, TRAY
from pick_common.errors import InvalidArgument
from pick_common.node_runner import (
    answer_error,
    declare,
    declare_mesh_dirs,
    LATCHED,
    RESULT_KEEP,
    run,
)
from pick_common.parts.materials import Contact
from pick_common.parts.materials import LIMITS as CONTACT_LIMITS
from pick_common.parts.models import BUILTIN_MODELS
from pick_common.parts.spec import LIMITS as PART_LIMITS
from pick_common.parts.spec import PartSpec
from pick_common.specs import CENTRE, check_vibration, FIXED, RANDOM, SceneSpec, Vibration
from pick_common.states import Progress, SettleReport
from pick_msgs.action import DropParts, RemoveParts, Vibrate
from pick_msgs.msg import PartArray, Scene
from pick_msgs.msg import SettleReport as SettleReportMsg
from pick_msgs.srv import GetParts, ResetScene
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from rclpy.qos_overriding_options import QoSOverridingOptions
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import MarkerArray

from . import conversions as conv
from .config import LIMITS, PhysicsConfig
from .world import World

ZONES = {DropParts.Goal.ZONE_CONTAINER: 'container', DropParts.Goal.ZONE_FEEDER: 'feeder'}
SHUTDOWN_WAIT = 10.0   # s a shutdown waits for a running physics operation
# s of wall time at least between an action's feedback messages (the first check's goes at
# once): tqdm's mininterval, a progress display's redraw. Settle checks come hundreds a second
# on a few parts, each message a round of the world's and its client's executors.
FEEDBACK_PERIOD = 0.1


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
        self._reports_pub = self.create_publisher(SettleReportMsg, 'settle_reports', 10,
                                                  qos_overriding_options=qos_options)
        # Absolute, as tf2_ros's broadcasters: every worker's frames on the one topic each.
        self._tf_static_pub = self.create_publisher(TFMessage, '/tf_static', LATCHED)
        self._tf_pub = self.create_publisher(TFMessage, '/tf', 100)   # tf2_ros's depth
        self._drawn = None          # what the last markers showed (conversions.drawn)
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
            f'{scene.part.model} parts; frames {common.instance_frame(self._prefix, 0)}...')

    # ----------------------------------------------------------------------------- parameters
    def _declare_parameters(self) -> tuple[SceneSpec, PhysicsConfig, Vibration]:
        """Declare every parameter with a descriptor that states the core's limit (one table
        per core: LIMITS of config, containers, parts and specs) and build the frozen configs,
        which the core checks again as a whole."""
        def get(name, default, text, limit=None):
            return declare(self, name, default, text, limit)

        self._frame_id = get('frame_id', 'world', 'frame of the scene and of instance frames')
        prefix = get('frame_prefix', '', 'prefix of instance frame names; empty: the node '
                     'namespace, e.g. worker_1/instance_0')
        namespace = self.get_namespace().strip('/')
        self._prefix = prefix or (f'{namespace}/' if namespace else '')

        kind = get('container.kind', BIN, f'{BIN} or {TRAY}')
        base = ContainerSpec.tray() if kind == TRAY else ContainerSpec()
        walls = containers.LIMITS
        container = ContainerSpec(
            kind=kind,
            inner_size=tuple(get('container.inner_size', list(base.inner_size),
                                 'inner length, width, height, m')),
            wall_thickness=get('container.wall_thickness', base.wall_thickness, 'm',
                               walls['container.wall_thickness']),
            floor_thickness=get('container.floor_thickness', base.floor_thickness, 'm',
                                walls['container.floor_thickness']),
            feeder_zone_center=tuple(get('container.feeder_zone_center',
                                         list(base.feeder_zone_center),
                                         'centre x, y of the tray feeder zone, m')),
            feeder_zone_size=tuple(get('container.feeder_zone_size',
                                       list(base.feeder_zone_size),
                                       'x, y extent of the tray feeder zone, m')),
            drop_height=get('container.drop_height', containers.DROP_HEIGHT.get(kind, 0.0),
                            "how high over the floor parts arrive from, m (a bin's pour, a "
                            "tray's hopper lip)", walls['container.drop_height']),
            hopper_rate=get('container.hopper_rate', containers.HOPPER_RATE,
                            "parts a tray's hopper lets out per second while it runs",
                            walls['container.hopper_rate']),
            hopper_speed=get('container.hopper_speed', containers.HOPPER_SPEED,
                             "speed of the parts leaving a tray's hopper, m/s",
                             walls['container.hopper_speed']))
        model = get('part.model', 'radial_capacitor',
                    f'built-in model ({", ".join(BUILTIN_MODELS)}) or mesh')
        dims, default_mass = {}, 0.0
        if model in BUILTIN_MODELS:
            defaults, default_mass, _ = BUILTIN_MODELS[model]
            dims = {name: get(f'part.{name}', value, f'{model} dimension, m'
                              if name != 'pins_per_row' else 'pins per row')
                    for name, value in defaults.items()}
        mass = get('part.mass', default_mass, 'kg; 0 for the model default (checked when the '
                   'part is built)')
        spec = PartSpec()

        def contact(pair: str, default: Contact) -> Contact:
            texts = {'lateral_friction': 'Coulomb coefficient',
                     'rolling_friction': 'rolling resistance arm, m',
                     'spinning_friction': 'torsional friction arm, m', 'restitution': '1'}
            return Contact(**{name: get(f'materials.{pair}.{name}', getattr(default, name),
                                        f'{texts[name]}, the part {pair.replace("_", " ")}',
                                        CONTACT_LIMITS[name]) for name in texts})

        part = PartSpec(
            model=model, dimensions=dims, mass=mass or None,
            part_on_surface=contact('part_on_surface', spec.part_on_surface),
            part_on_part=contact('part_on_part', spec.part_on_part),
            mesh_path=get('part.mesh_path', '', 'STL/OBJ/PLY file for part.model mesh'),
            scale=get('part.scale', 1.0, 'mesh scale to metres', PART_LIMITS['part.scale']))
        scene = SceneSpec(container, part,
                          get('instances', 1, 'independent instances',
                              specs.LIMITS['instance_count']),
                          get('seed', 0, 'base seed of the instances', specs.LIMITS['seed']))
        cfg = PhysicsConfig()

        def setting(name: str, default, text: str):
            return get(name, default, text, LIMITS[name])

        physics = PhysicsConfig(
            time_step=setting('physics.time_step', cfg.time_step, 's'),
            solver_iterations=setting('physics.solver_iterations', cfg.solver_iterations,
                                      'solver iterations per step in a bin'),
            tray_solver_iterations=setting('physics.tray_solver_iterations',
                                           cfg.tray_solver_iterations,
                                           'solver iterations per step on a tray'),
            warm_starting_factor=setting('physics.warm_starting_factor',
                                         cfg.warm_starting_factor,
                                         "share of the last step's contact impulses the "
                                         'solver starts from'),
            contact_breaking_threshold=setting('physics.contact_breaking_threshold',
                                               cfg.contact_breaking_threshold,
                                               "contact distance, a factor of each shape's "
                                               'bounding radius'),
            length_unit=setting('physics.length_unit', cfg.length_unit,
                                "m per length unit the engine simulates in (0.01: cm, Bullet's "
                                'scale for small parts)'),
            settle_check_period=setting('settle.check_period', cfg.settle_check_period,
                                        'simulated s between rest checks'),
            settle_window=setting('settle.window', cfg.settle_window,
                                  'simulated s over which a part must stay put'),
            settle_linear_tolerance=setting('settle.linear_tolerance',
                                            cfg.settle_linear_tolerance,
                                            'largest position change at rest over the '
                                            'window, m'),
            settle_angular_tolerance=setting('settle.angular_tolerance',
                                             cfg.settle_angular_tolerance,
                                             'largest rotation at rest over the window, rad'),
            settle_moving_fraction=setting('settle.moving_fraction', cfg.settle_moving_fraction,
                                           'largest fraction of parts still moving when '
                                           'settled'),
            max_settle_time=setting('settle.max_time', cfg.max_settle_time,
                                    'cap on simulated settle time, s'),
            settle_freeze=get('settle.freeze', cfg.settle_freeze,
                              'freeze parts that rest while a settle runs (false: step every '
                              'part to the end)'))
        vib = Vibration()
        vibration = Vibration(
            amplitude=tuple(get('vibration.amplitude', list(vib.amplitude),
                                'default peak tray displacement x, y, z, m')),
            frequency=get('vibration.frequency', vib.frequency, 'default frequency, Hz',
                          specs.LIMITS['vibration.frequency']),
            duration=get('vibration.duration', vib.duration, 'default duration, s',
                         specs.LIMITS['vibration.duration']),
            direction=get('vibration.direction', vib.direction,
                          f'default direction: {FIXED} (the amplitude as given), {RANDOM} '
                          '(its horizontal part turned by a random angle per vibration) or '
                          f'{CENTRE} (its horizontal part toward the tray centre from the '
                          "parts' centroid)"))
        self._publish_markers = get('publish_markers', True, 'publish `markers` when the '
                                    'parts change, their frames on /tf after each operation')
        self._mesh_dirs = declare_mesh_dirs(self)
        return scene, physics, check_vibration(vibration)

    # ----------------------------------------------------------------------------- publish
    def _publish(self, scene_changed: bool = False) -> PartArray:
        """Publish the current snapshot (and the scene when it changed); return the parts."""
        stamp = self.get_clock().now().to_msg()
        if scene_changed:
            self._scene_msg = conv.scene_to_msg(self._world, stamp, self._frame_id, self._prefix)
            self._scene_pub.publish(self._scene_msg)
            self._tf_static_pub.publish(conv.tf_static_msg(self._scene_msg))
        parts = common.states_to_msg(self._states, stamp, self._frame_id, self._prefix)
        self._parts_pub.publish(parts)
        if self._publish_markers:
            self._tf_pub.publish(conv.parts_tf_msg(self._states, stamp, self._prefix))
            if scene_changed or conv.drawn(self._states) != self._drawn:
                self._drawn = conv.drawn(self._states)
                self._markers_pub.publish(conv.markers_msg(self._world, self._states, stamp,
                                                           self._prefix))
        return parts

    def _parts_msg(self, instances) -> PartArray:
        states = self._states if instances is None else self._states.select(instances)
        return common.states_to_msg(states, self.get_clock().now().to_msg(), self._frame_id,
                                  self._prefix)

    # ----------------------------------------------------------------------------- services
    def _get_parts(self, request: GetParts.Request,
                   response: GetParts.Response) -> GetParts.Response:
        wanted = list(request.instances)
        count = self._world.scene.instance_count
        unknown = [k for k in wanted if k >= count]
        if unknown:
            response.error_code = common.ERROR_UNKNOWN_INSTANCE
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
                part = common.part_spec_from_msg(request.part_model, self._mesh_dirs)
                self._world.reset(SceneSpec(common.container_from_msg(request.container), part,
                                            request.instance_count, request.seed))

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
            response.error_code = common.ERROR_BUSY
            response.error_msg = ('another physics operation is running; requests are not '
                                  'queued: retry when it ends')
            return False
        try:
            operation()
            return True
        except Exception as exc:  # core errors get their code, bugs INTERNAL (answer_error)
            answer_error(response, exc, self.get_logger(), 'request')
        finally:
            if response.error_code == common.ERROR_PHYSICS_FAULT:
                self._states = self._world.snapshot()
                self._publish(scene_changed=True)
            self._lock.release()
        return False

    # ----------------------------------------------------------------------------- actions
    def _execute(self, action_type, goal_handle, result,
                 operation: Callable[[Callable], SettleReport], instances) -> object:
        """Run a physics action: feedback at settle checks (at most one a FEEDBACK_PERIOD),
        cancel at every one, errors, publishing."""
        settle: list[SettleReport] = []
        last: list[float | None] = [None]   # when the last feedback went out (monotonic)

        def progress(p: Progress) -> bool:
            if self._stopping:   # shutting down: end the operation at this settle check
                return False
            now = time.monotonic()
            if last[0] is None or now - last[0] >= FEEDBACK_PERIOD:
                last[0] = now
                goal_handle.publish_feedback(action_type.Feedback(
                    progress=common.progress_to_msg(p)))
            return not goal_handle.is_cancel_requested

        ok = self._guarded(lambda: settle.append(operation(progress)), result)
        if self._stopping:
            # shutting down: the context and its publishers may be gone (rclpy aborts the goal)
            return result
        if ok:
            report = settle[0]
            result.settle = common.settle_to_msg(report)
            self._reports_pub.publish(result.settle)
            self._states = self._world.snapshot()
            published = self._publish()
            result.parts = published if instances is None else self._parts_msg(instances)
            if report.canceled:
                result.error_code = common.ERROR_CANCELED
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
                common.or_default('max_settle_time', goal.max_settle_time, None), progress)
            result.part_ids = ids
            return report

        return self._execute(DropParts, goal_handle, result, drop, instances)

    def _vibrate(self, goal_handle) -> Vibrate.Result:
        goal = goal_handle.request
        instances = list(goal.instances) or None

        def vibrate(progress) -> SettleReport:
            vibration = common.vibration_from_msg(goal.vibration, self._vibration)
            return self._world.vibrate(vibration, instances, common.or_default(
                'max_settle_time', goal.max_settle_time, None), progress)

        return self._execute(Vibrate, goal_handle, Vibrate.Result(), vibrate, instances)

    def _remove_parts(self, goal_handle) -> RemoveParts.Result:
        goal = goal_handle.request
        result = RemoveParts.Result()

        def remove(progress) -> SettleReport:
            removed, report = self._world.remove(
                list(goal.part_ids), not goal.skip_settle,
                common.or_default('max_settle_time', goal.max_settle_time, None), progress)
            result.removed_ids = removed
            return report

        return self._execute(RemoveParts, goal_handle, result, remove, None)

    def destroy_node(self) -> None:
        """End a running operation at its next settle check and wait for it, then destroy
        the node's endpoints, then close PyBullet: endpoints destroyed under a callback that
        still publishes, or a disconnect under a running step, fail or crash."""
        self._stopping = True
        idle = self._lock.acquire(timeout=SHUTDOWN_WAIT)
        super().destroy_node()
        if not idle:
            # PyBullet is still stepping (an operation with no settle check yet, such as
            # adding thousands of parts): closing it now would crash; the process exit does.
            self.get_logger().error(f'a physics operation still ran after {SHUTDOWN_WAIT:g} s; '
                                    'PyBullet is left to the process exit')
            return
        self._world.close()
        self._lock.release()


def main(args=None) -> None:
    run('world', WorldNode, lambda: MultiThreadedExecutor(num_threads=3), args)
