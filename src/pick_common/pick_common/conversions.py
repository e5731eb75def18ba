"""The one place that maps the shared pick_msgs types to and from the shared core types: error
codes, containers, part specs, part snapshots, settle reports and progress, vibrations.

No rclpy here: messages are plain Python classes. Times are passed in as builtin Time messages.
Each package's own conversions (the world's scene and markers, the validity reports) build on
these.
"""

from collections.abc import Sequence

from builtin_interfaces.msg import Time
from geometry_msgs.msg import Point, Pose, Quaternion, Vector3
import numpy as np
from pick_msgs.msg import (
    ContactMaterial,
    ContainerGeometry,
    Part,
    PartArray,
    PartModel,
    PhysicsProgress,
)
from pick_msgs.msg import SettleReport as SettleReportMsg
from pick_msgs.msg import TrayMotion as TrayMotionMsg
from pick_msgs.msg import Vibration as VibrationMsg
from pick_msgs.srv import GetParts
from std_msgs.msg import Header

from . import containers
from .containers import ContainerSpec
from .errors import (
    check_inside,
    check_number,
    InvalidArgument,
    PhysicsFault,
    PickError,
    UnknownInstance,
    UnknownPart,
)
from .parts.materials import Contact
from .parts.materials import FIELDS as CONTACT_FIELDS
from .parts.spec import PartSpec
from .specs import CENTRE, FIXED, RANDOM, Vibration
from .states import PartStates, Progress, SettleReport, TrayMotion

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


def error_code(exc: PickError) -> int:
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


def or_default(field: str, value: float, default: float | None) -> float | None:
    """A message field where 0 means the default (ROS fields cannot be unset).

    NaN and inf are rejected here, naming the field: they must not pass as "not zero".
    """
    check_number(field, value)
    return default if value == 0.0 else value


def pose_msg(position: Sequence[float], orientation: Sequence[float]) -> Pose:
    """A Pose from xyz (m) and an xyzw quaternion."""
    return Pose(position=Point(x=float(position[0]), y=float(position[1]),
                               z=float(position[2])),
                orientation=Quaternion(x=float(orientation[0]), y=float(orientation[1]),
                                       z=float(orientation[2]), w=float(orientation[3])))


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
        feeder_zone_size=(msg.feeder_zone_size.x, msg.feeder_zone_size.y),
        drop_height=or_default('container.drop_height', msg.drop_height, None),
        hopper_rate=or_default('container.hopper_rate', msg.hopper_rate, None),
        hopper_speed=or_default('container.hopper_speed', msg.hopper_speed, None))


def container_to_msg(spec: ContainerSpec) -> ContainerGeometry:
    x, y, z = spec.inner_size
    return ContainerGeometry(
        type=KIND_TO_MSG[spec.kind], inner_size=Vector3(x=x, y=y, z=z),
        wall_thickness=spec.wall_thickness, floor_thickness=spec.floor_thickness,
        feeder_zone_center=Point(x=spec.feeder_zone_center[0], y=spec.feeder_zone_center[1]),
        feeder_zone_size=Vector3(x=spec.feeder_zone_size[0], y=spec.feeder_zone_size[1]),
        drop_height=float(containers.drop_height(spec)),
        hopper_rate=float(containers.hopper(spec)[0]),
        hopper_speed=float(containers.hopper(spec)[1]))


# ----------------------------------------------------------------------------- parts
def part_spec_from_msg(msg: PartModel, mesh_dirs: Sequence[str] = ()) -> PartSpec:
    """A PartSpec from a message. 0 in mass or scale means the default, and so does a contact
    material whose four fields are all 0 (contact_from_msg).
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
        part_on_surface=contact_from_msg(msg.part_on_surface, defaults.part_on_surface),
        part_on_part=contact_from_msg(msg.part_on_part, defaults.part_on_part),
        mesh_path=mesh, scale=or_default('part_model.scale', msg.scale, 1.0))


def contact_from_msg(msg: ContactMaterial, default: Contact) -> Contact:
    """A pair's contact material; `default` when all four fields are 0 (a request that leaves
    the pair out). Each value as given otherwise, 0 included (checked where the part is
    built)."""
    values = {name: float(getattr(msg, name)) for name in CONTACT_FIELDS}
    return default if not any(values.values()) else Contact(**values)


def contact_to_msg(contact: Contact) -> ContactMaterial:
    return ContactMaterial(**{name: float(getattr(contact, name)) for name in CONTACT_FIELDS})


def part_spec_to_msg(spec: PartSpec) -> PartModel:
    """A PartModel carrying what a user says about the part (no derived geometry), for
    reset_scene and check_parts requests. A default mass (None) goes as 0."""
    names = sorted(spec.dimensions)
    return PartModel(name=spec.model, mesh_path=spec.mesh_path, scale=float(spec.scale),
                     dimension_names=names,
                     dimension_values=[float(spec.dimensions[n]) for n in names],
                     mass=float(spec.mass or 0.0),
                     part_on_surface=contact_to_msg(spec.part_on_surface),
                     part_on_part=contact_to_msg(spec.part_on_part))


# ----------------------------------------------------------------------------- snapshots
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
        part.pose.pose = pose_msg(pose[:3], pose[3:])
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


def tray_from_msg(msg: TrayMotionMsg) -> TrayMotion | None:
    """None for the all-zero message of an operation that did not vibrate."""
    if not msg.amplitude:
        return None
    return TrayMotion(msg.amplitude, msg.delivered_amplitude, msg.peak_velocity,
                      msg.delivered_peak_velocity)


def tray_to_msg(motion: TrayMotion | None) -> TrayMotionMsg:
    if motion is None:
        return TrayMotionMsg()
    return TrayMotionMsg(amplitude=motion.amplitude,
                         delivered_amplitude=motion.delivered_amplitude,
                         peak_velocity=motion.peak_velocity,
                         delivered_peak_velocity=motion.delivered_peak_velocity)


def settle_from_msg(msg: SettleReportMsg) -> SettleReport:
    return SettleReport(settled=msg.settled, sim_time=msg.sim_time, wall_time=msg.wall_time,
                        steps=msg.steps, unsettled_ids=list(msg.unsettled_ids),
                        escaped_ids=list(msg.escaped_ids),
                        tunnelled_ids=list(msg.tunnelled_ids),
                        max_penetration=msg.max_penetration, tray=tray_from_msg(msg.tray),
                        thrown_ids=list(msg.thrown_ids), max_speed=msg.max_speed,
                        landed_ids=list(msg.landed_ids),
                        landed_at=[(p.x, p.y, p.z) for p in msg.landed_at],
                        landed_speeds=list(msg.landed_speeds))


def settle_to_msg(report: SettleReport) -> SettleReportMsg:
    return SettleReportMsg(settled=report.settled, sim_time=report.sim_time,
                           wall_time=report.wall_time, steps=report.steps,
                           unsettled_ids=list(report.unsettled_ids),
                           escaped_ids=list(report.escaped_ids),
                           tunnelled_ids=list(report.tunnelled_ids),
                           max_penetration=report.max_penetration,
                           tray=tray_to_msg(report.tray), thrown_ids=list(report.thrown_ids),
                           max_speed=report.max_speed, landed_ids=list(report.landed_ids),
                           landed_at=[Point(x=float(x), y=float(y), z=float(z))
                                      for x, y, z in report.landed_at],
                           landed_speeds=[float(v) for v in report.landed_speeds])


def progress_to_msg(progress: Progress) -> PhysicsProgress:
    return PhysicsProgress(phase=PHASES[progress.phase], sim_time=progress.sim_time,
                           parts_moving=progress.parts_moving,
                           max_displacement=progress.max_displacement,
                           tray=tray_to_msg(progress.tray))


# ----------------------------------------------------------------------------- vibrations
_DIRECTION_NAMES = {VibrationMsg.DIRECTION_FIXED: FIXED, VibrationMsg.DIRECTION_RANDOM: RANDOM,
                    VibrationMsg.DIRECTION_CENTRE: CENTRE}
_DIRECTION_VALUES = {name: value for value, name in _DIRECTION_NAMES.items()}


def vibration_from_msg(msg: VibrationMsg, default: Vibration) -> Vibration:
    """A Vibration from a message; each field left 0 (all of the amplitude, or
    DIRECTION_DEFAULT) takes `default`'s. Checked later by the core; a direction that is no
    DIRECTION_* constant raises InvalidArgument here."""
    a = msg.amplitude
    amplitude = (a.x, a.y, a.z) if (a.x, a.y, a.z) != (0.0, 0.0, 0.0) else default.amplitude
    direction = default.direction
    if msg.direction != VibrationMsg.DIRECTION_DEFAULT:
        if msg.direction not in _DIRECTION_NAMES:
            raise InvalidArgument('vibration.direction', msg.direction,
                                  'must be 0 (default), 1 (fixed), 2 (random) or 3 (centre)')
        direction = _DIRECTION_NAMES[msg.direction]
    return Vibration(
        amplitude=amplitude,
        frequency=or_default('vibration.frequency', msg.frequency, default.frequency),
        duration=or_default('vibration.duration', msg.duration, default.duration),
        direction=direction)


def vibration_to_msg(vibration: Vibration) -> VibrationMsg:
    """A message carrying every field of `vibration` (none left to the world's defaults)."""
    x, y, z = vibration.amplitude
    return VibrationMsg(amplitude=Vector3(x=float(x), y=float(y), z=float(z)),
                        frequency=float(vibration.frequency),
                        duration=float(vibration.duration),
                        direction=_DIRECTION_VALUES[vibration.direction])
