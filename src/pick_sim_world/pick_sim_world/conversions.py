"""The one place that maps pick_msgs messages to and from the world core's types.

No rclpy here: messages are plain Python classes. Times are passed in as builtin Time messages.
"""

from collections.abc import Sequence

from builtin_interfaces.msg import Time
from geometry_msgs.msg import Point, Pose, Quaternion, Transform, Vector3
import numpy as np
from pick_msgs.action import Vibrate
from pick_msgs.msg import ContainerGeometry, Part, PartArray, PartModel, PhysicsProgress, Scene
from pick_msgs.msg import Instance as InstanceMsg
from pick_msgs.msg import SettleReport as SettleReportMsg
from pick_msgs.srv import GetParts
from shape_msgs.msg import Mesh, MeshTriangle, SolidPrimitive
from std_msgs.msg import ColorRGBA, Header
from visualization_msgs.msg import Marker, MarkerArray

from . import containers
from .config import FIXED, RANDOM
from .containers import ContainerSpec
from .errors import (
    check_inside,
    check_number,
    InvalidArgument,
    PhysicsFault,
    UnknownInstance,
    UnknownPart,
    WorldError,
)
from .parts import PartGeometry, PartSpec
from .world import PartStates, Progress, rotate, SettleReport, World

# Error codes are the same in every pick_msgs service and action.
ERROR_NONE = GetParts.Response.NONE
ERROR_INVALID_ARGUMENT = GetParts.Response.INVALID_ARGUMENT
ERROR_UNKNOWN_INSTANCE = GetParts.Response.UNKNOWN_INSTANCE
ERROR_UNKNOWN_PART = GetParts.Response.UNKNOWN_PART
ERROR_BUSY = GetParts.Response.BUSY
ERROR_PHYSICS_FAULT = GetParts.Response.PHYSICS_FAULT
ERROR_CANCELED = GetParts.Response.CANCELED
ERROR_INTERNAL = GetParts.Response.INTERNAL

PHASES = {'dropping': PhysicsProgress.PHASE_DROPPING,
          'vibrating': PhysicsProgress.PHASE_VIBRATING,
          'settling': PhysicsProgress.PHASE_SETTLING}
KIND_TO_MSG = {containers.BIN: ContainerGeometry.TYPE_BIN,
               containers.TRAY: ContainerGeometry.TYPE_TRAY}
MSG_TO_KIND = {v: k for k, v in KIND_TO_MSG.items()}


def error_code(exc: WorldError) -> int:
    """The error code of a core exception."""
    if isinstance(exc, InvalidArgument):
        return ERROR_INVALID_ARGUMENT
    if isinstance(exc, UnknownInstance):
        return ERROR_UNKNOWN_INSTANCE
    if isinstance(exc, UnknownPart):
        return ERROR_UNKNOWN_PART
    if isinstance(exc, PhysicsFault):
        return ERROR_PHYSICS_FAULT
    return ERROR_INTERNAL


def instance_frame(prefix: str, index: int) -> str:
    """Name of instance `index`'s frame."""
    return f'{prefix}instance_{index}'


# ----------------------------------------------------------------------------- containers
def container_from_msg(msg: ContainerGeometry) -> ContainerSpec:
    """A ContainerSpec from a message (checked later by the core)."""
    if msg.type not in MSG_TO_KIND:
        raise InvalidArgument('container.type', msg.type,
                              f'must be {ContainerGeometry.TYPE_BIN} (bin) or '
                              f'{ContainerGeometry.TYPE_TRAY} (tray)')
    size = msg.inner_size
    return ContainerSpec(
        kind=MSG_TO_KIND[msg.type], inner_size=(size.x, size.y, size.z),
        wall_thickness=msg.wall_thickness, floor_thickness=msg.floor_thickness,
        feeder_zone_center=(msg.feeder_zone_center.x, msg.feeder_zone_center.y),
        feeder_zone_size=(msg.feeder_zone_size.x, msg.feeder_zone_size.y))


def container_to_msg(spec: ContainerSpec) -> ContainerGeometry:
    x, y, z = spec.inner_size
    return ContainerGeometry(
        type=KIND_TO_MSG[spec.kind], inner_size=Vector3(x=x, y=y, z=z),
        wall_thickness=spec.wall_thickness, floor_thickness=spec.floor_thickness,
        feeder_zone_center=Point(x=spec.feeder_zone_center[0], y=spec.feeder_zone_center[1]),
        feeder_zone_size=Vector3(x=spec.feeder_zone_size[0], y=spec.feeder_zone_size[1]))


# ----------------------------------------------------------------------------- parts
def part_spec_from_msg(msg: PartModel, mesh_dirs: Sequence[str] = ()) -> PartSpec:
    """A PartSpec from a message. 0 in mass, scale or a friction field means the default.
    A mesh file must lie in one of `mesh_dirs` (the node's parameter of that name): a request
    cannot make a node read elsewhere."""
    mesh = msg.mesh_path and check_inside('part_model.mesh_path', msg.mesh_path, mesh_dirs,
                                          'mesh_dirs')     # the file checked is the one read
    names, values = list(msg.dimension_names), list(msg.dimension_values)
    if len(names) != len(values):
        raise InvalidArgument('part_model.dimension_values', len(values),
                              f'values for {len(names)} dimension_names')
    if len(set(names)) != len(names):
        raise InvalidArgument('part_model.dimension_names', names, 'has a name twice')
    defaults = PartSpec()
    return PartSpec(
        model=msg.name, dimensions=dict(zip(names, values, strict=True)),
        mass=or_default('part_model.mass', msg.mass, None),
        lateral_friction=or_default('part_model.lateral_friction', msg.lateral_friction,
                                    defaults.lateral_friction),
        rolling_friction=or_default('part_model.rolling_friction', msg.rolling_friction,
                                    defaults.rolling_friction),
        spinning_friction=or_default('part_model.spinning_friction', msg.spinning_friction,
                                     defaults.spinning_friction),
        restitution=or_default('part_model.restitution', msg.restitution,
                               defaults.restitution),
        mesh_path=mesh, scale=or_default('part_model.scale', msg.scale, 1.0))


def part_spec_to_msg(spec: PartSpec) -> PartModel:
    """A PartModel carrying what a user says about the part (no derived geometry), for
    reset_scene and check_parts requests. A default mass (None) goes as 0."""
    names = sorted(spec.dimensions)
    return PartModel(name=spec.model, mesh_path=spec.mesh_path, scale=float(spec.scale),
                     dimension_names=names,
                     dimension_values=[float(spec.dimensions[n]) for n in names],
                     mass=float(spec.mass or 0.0), lateral_friction=float(spec.lateral_friction),
                     rolling_friction=float(spec.rolling_friction),
                     spinning_friction=float(spec.spinning_friction),
                     restitution=float(spec.restitution))


def _pose(position: Sequence[float], orientation: Sequence[float]) -> Pose:
    return Pose(position=Point(x=float(position[0]), y=float(position[1]),
                               z=float(position[2])),
                orientation=Quaternion(x=float(orientation[0]), y=float(orientation[1]),
                                       z=float(orientation[2]), w=float(orientation[3])))


def _mesh_msg(vertices: np.ndarray, faces: np.ndarray) -> Mesh:
    return Mesh(vertices=[Point(x=float(x), y=float(y), z=float(z)) for x, y, z in vertices],
                triangles=[MeshTriangle(vertex_indices=[int(a), int(b), int(c)])
                           for a, b, c in faces])


def part_model_to_msg(part: PartGeometry) -> PartModel:
    """The full part model: parameters, collision compound and visual mesh."""
    spec = part.spec
    msg = PartModel(
        name=spec.model, mesh_path=spec.mesh_path, scale=float(spec.scale),
        dimension_names=list(part.dimensions), dimension_values=[
            float(v) for v in part.dimensions.values()],
        mass=float(part.mass), lateral_friction=float(spec.lateral_friction),
        rolling_friction=float(spec.rolling_friction),
        spinning_friction=float(spec.spinning_friction), restitution=float(spec.restitution),
        bounding_radius=float(part.radius + np.linalg.norm(part.center)))
    for p in part.primitives:
        if p.kind == 'box':
            msg.primitives.append(SolidPrimitive(
                type=SolidPrimitive.BOX, dimensions=[2.0 * s for s in p.size]))
            msg.primitive_poses.append(_pose(p.position, p.orientation))
        elif p.kind == 'cylinder':
            radius, length = p.size
            msg.primitives.append(SolidPrimitive(type=SolidPrimitive.CYLINDER,
                                                 dimensions=[length, radius]))
            msg.primitive_poses.append(_pose(p.position, p.orientation))
        else:
            msg.hulls.append(_mesh_msg(p.vertices, p.faces))
    msg.visual = _mesh_msg(part.visual.vertices, part.visual.faces)
    return msg


# ----------------------------------------------------------------------------- scene
def scene_to_msg(world: World, stamp: Time, frame_id: str, prefix: str) -> Scene:
    """The scene description of a world: part model and every instance with its frame."""
    msg = Scene(header=Header(stamp=stamp, frame_id=frame_id),
                part_model=part_model_to_msg(world.part))
    container = container_to_msg(world.scene.container)
    for inst in world.instances:
        x, y, z = (float(v) for v in inst.origin)
        msg.instances.append(InstanceMsg(
            id=inst.id, seed=inst.seed, frame_id=instance_frame(prefix, inst.id),
            transform=Transform(translation=Vector3(x=x, y=y, z=z),
                                rotation=Quaternion(w=1.0)),
            container=container, part_count=len(inst.part_ids)))
    return msg


def states_to_msg(states: PartStates, stamp: Time, frame_id: str, prefix: str) -> PartArray:
    """A PartArray from a snapshot; each pose is stamped in its instance frame."""
    msg = PartArray(header=Header(stamp=stamp, frame_id=frame_id), sim_time=states.sim_time)
    frames = {}
    for pid, inst, pose, inside in zip(states.ids.tolist(), states.instances.tolist(),
                                       states.poses.tolist(), states.inside.tolist(),
                                       strict=True):
        frame = frames.setdefault(inst, instance_frame(prefix, inst))
        part = Part(id=pid, instance=inst, inside=inside)
        part.pose.header = Header(stamp=stamp, frame_id=frame)
        part.pose.pose = _pose(pose[:3], pose[3:])
        msg.parts.append(part)
    return msg


def parts_to_arrays(parts: Sequence[Part]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ids (N,) int64, instances (N,) int64 and poses (N, 7) float64 of Part messages."""
    ids = np.array([p.id for p in parts], dtype=np.int64)
    instances = np.array([p.instance for p in parts], dtype=np.int64)
    poses = np.array([[p.pose.pose.position.x, p.pose.pose.position.y, p.pose.pose.position.z,
                       p.pose.pose.orientation.x, p.pose.pose.orientation.y,
                       p.pose.pose.orientation.z, p.pose.pose.orientation.w]
                      for p in parts], dtype=np.float64).reshape(-1, 7)
    return ids, instances, poses


def states_from_msg(msg: PartArray) -> PartStates:
    """A snapshot from a PartArray (the inverse of states_to_msg)."""
    ids, instances, poses = parts_to_arrays(msg.parts)
    inside = np.array([p.inside for p in msg.parts], dtype=bool)
    return PartStates(ids, instances, poses, inside, msg.sim_time)


def settle_from_msg(msg: SettleReportMsg) -> SettleReport:
    return SettleReport(settled=msg.settled, sim_time=msg.sim_time, wall_time=msg.wall_time,
                        steps=msg.steps, unsettled_ids=list(msg.unsettled_ids),
                        escaped_ids=list(msg.escaped_ids))


def settle_to_msg(report: SettleReport) -> SettleReportMsg:
    return SettleReportMsg(settled=report.settled, sim_time=report.sim_time,
                           wall_time=report.wall_time, steps=report.steps,
                           unsettled_ids=list(report.unsettled_ids),
                           escaped_ids=list(report.escaped_ids))


def progress_to_msg(progress: Progress) -> PhysicsProgress:
    return PhysicsProgress(phase=PHASES[progress.phase], sim_time=progress.sim_time,
                           parts_moving=progress.parts_moving,
                           max_displacement=progress.max_displacement)


def or_default(field: str, value: float, default: float | None) -> float | None:
    """A message field where 0 means the default (ROS fields cannot be unset).

    NaN and inf are rejected here, naming the field: they must not pass as "not zero".
    """
    check_number(field, value)
    return default if value == 0.0 else value


_DIRECTION_NAMES = {Vibrate.Goal.DIRECTION_FIXED: FIXED, Vibrate.Goal.DIRECTION_RANDOM: RANDOM}
_DIRECTION_VALUES = {name: value for value, name in _DIRECTION_NAMES.items()}


def direction_from_msg(value: int, default: str) -> str:
    """A Vibrate/FeedCycle `direction` field as the core's name; DIRECTION_DEFAULT gives
    `default`. Raises InvalidArgument for a value that is no DIRECTION_* constant."""
    if value == Vibrate.Goal.DIRECTION_DEFAULT:
        return default
    if value not in _DIRECTION_NAMES:
        raise InvalidArgument('direction', value, 'must be 0 (default), 1 (fixed) or 2 '
                              '(random)')
    return _DIRECTION_NAMES[value]


def direction_to_msg(direction: str) -> int:
    """The core's direction name as a DIRECTION_* value."""
    return _DIRECTION_VALUES[direction]


# ----------------------------------------------------------------------------- markers
_CONTAINER_COLOR = ColorRGBA(r=0.6, g=0.6, b=0.65, a=0.4)
_PART_COLOR = ColorRGBA(r=0.1, g=0.3, b=0.8, a=1.0)
_ESCAPED_COLOR = ColorRGBA(r=0.9, g=0.1, b=0.1, a=1.0)


def _quat_mul(a: np.ndarray, b: Sequence[float]) -> np.ndarray:
    """Quaternion products a * b: a (N, 4), b (4,), xyzw; returns (N, 4)."""
    ax, ay, az, aw = a.T
    bx, by, bz, bw = b
    return np.stack([aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz],
                    axis=1)


def markers_msg(world: World, states: PartStates, stamp: Time, prefix: str) -> MarkerArray:
    """Containers and parts as markers in their instance frames: one marker per collision
    primitive (CUBE, CYLINDER) or hull (TRIANGLE_LIST). Starts with DELETEALL.

    The world publishes this after every operation, so the primitives' poses are computed for
    all parts at once and the shapes (scale, hull points) are built once per call."""
    out = MarkerArray(markers=[Marker(action=Marker.DELETEALL)])
    headers = {}
    marker_id = 0
    for inst in world.instances:
        header = headers[inst.id] = Header(stamp=stamp, frame_id=instance_frame(prefix, inst.id))
        for half, center in containers.wall_boxes(world.scene.container):
            out.markers.append(Marker(
                header=header, ns='container', id=marker_id, type=Marker.CUBE,
                pose=_pose(center, (0.0, 0.0, 0.0, 1.0)),
                scale=Vector3(x=2 * half[0], y=2 * half[1], z=2 * half[2]),
                color=_CONTAINER_COLOR))
            marker_id += 1
    if not len(states.ids):
        return out
    primitives = world.part.primitives
    shapes = []     # per primitive: marker type, scale and points, shared by every part
    for p in primitives:
        if p.kind == 'box':
            shapes.append((Marker.CUBE, Vector3(x=2 * p.size[0], y=2 * p.size[1],
                                                z=2 * p.size[2]), []))
        elif p.kind == 'cylinder':
            shapes.append((Marker.CYLINDER, Vector3(x=2 * p.size[0], y=2 * p.size[0],
                                                    z=p.size[1]), []))
        else:
            shapes.append((Marker.TRIANGLE_LIST, Vector3(x=1.0, y=1.0, z=1.0),
                           [Point(x=float(x), y=float(y), z=float(z))
                            for x, y, z in p.vertices[p.faces.reshape(-1)]]))
    q = states.poses[:, 3:]
    # (N, K, 3) positions and (N, K, 4) orientations of primitive k of part n.
    positions = np.stack([states.poses[:, :3] + rotate(q, np.asarray(p.position, dtype=float))
                          for p in primitives], axis=1).tolist()
    orientations = np.stack([_quat_mul(q, p.orientation) for p in primitives], axis=1).tolist()
    for pid, inst, inside, part_positions, part_orientations in zip(
            states.ids.tolist(), states.instances.tolist(), states.inside.tolist(), positions,
            orientations, strict=True):
        header, ns = headers[inst], f'part_{pid}'
        color = _PART_COLOR if inside else _ESCAPED_COLOR
        for k, ((kind, scale, points), position, orientation) in enumerate(zip(
                shapes, part_positions, part_orientations, strict=True)):
            out.markers.append(Marker(
                header=header, ns=ns, id=k, type=kind, scale=scale, color=color, points=points,
                pose=_pose(position, orientation)))
    return out
