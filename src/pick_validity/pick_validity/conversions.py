"""The one place that maps check_parts requests and ValidityReport messages to and from the
validity core. Container, part-model and part conversions are pick_common's, reused."""

from collections.abc import Sequence
from dataclasses import fields

from builtin_interfaces.msg import Time
from geometry_msgs.msg import Point, Vector3
import numpy as np
from pick_common import conversions as common
from pick_common.containers import ContainerSpec
from pick_common.errors import InvalidArgument
from pick_msgs.msg import CheckSettings, PartValidity, ValidityReport
from pick_msgs.msg import GraspPose as GraspPoseMsg
from pick_msgs.msg import Gripper as GripperMsg
from pick_msgs.msg import PlaceSpec as PlaceSpecMsg
from pick_msgs.srv import CheckParts
from std_msgs.msg import Header

from .config import CheckConfig, PlaceSpec, Setup
from .grippers import GripperKind, KINDS
from .results import PartResult, Report
from .validity import Validator


def request_to_core(request: CheckParts.Request
                    ) -> tuple[ContainerSpec, list[int], object, list[int] | None]:
    """Container, ids, poses (N, 7) and targets (None for all) of a request (its setup:
    `setup_from_request`)."""
    ids, _, poses = common.parts_to_arrays(request.parts)
    targets = [int(t) for t in request.target_ids] or None
    return common.container_from_msg(request.container), ids.tolist(), poses, targets


# The message's type of each gripper kind (pick_msgs/msg/Gripper.msg).
MSG_TYPES = {'jaws': GripperMsg.JAWS, 'suction': GripperMsg.SUCTION}
KIND_OF_MSG = {value: KINDS[kind] for kind, value in MSG_TYPES.items()}


def _xyz(v) -> tuple[float, float, float]:
    return float(v.x), float(v.y), float(v.z)


def gripper_from_msg(g: GripperMsg, default: GripperKind) -> GripperKind:
    """The message's gripper, of the kind its type names; one whose kind's fields are all 0
    is `default` (a request that leaves the gripper empty)."""
    kind = KIND_OF_MSG.get(g.type)
    if kind is None:
        kinds = ' or '.join(f'{value} ({name})' for name, value in MSG_TYPES.items())
        raise InvalidArgument('gripper.type', g.type, f'must be {kinds}')
    values = {key.field: getattr(g, key.field) for key in kind.KEYS}
    return kind(**values) if any(values.values()) else default


def gripper_to_msg(gripper: GripperKind) -> GripperMsg:
    return GripperMsg(type=MSG_TYPES[gripper.kind], **gripper.values())


def _written_grasp(gripper: GripperKind, m: GraspPoseMsg):
    """A request's grasp as the gripper's kind writes it (the message's fields it has)."""
    values = {'name': m.name, 'up_axis': _xyz(m.up_axis), 'closing_axis': _xyz(m.closing_axis),
              'jaw_opening': m.jaw_opening, 'grasp_point': _xyz(m.grasp_point)}
    return gripper.written(**{f.name: values[f.name] for f in fields(gripper.written)})


def setup_from_request(request: CheckParts.Request, defaults: Setup,
                       mesh_dirs: Sequence[str]) -> Setup:
    """The request's part model, gripper, grasps, placement and settings; each but the part
    left empty (all 0 or an empty list) takes the node's default. A mesh file must lie in one
    of `mesh_dirs`. Checked by the core."""
    part = common.part_spec_from_msg(request.part_model, mesh_dirs)
    gripper = gripper_from_msg(request.gripper, defaults.gripper)
    grasps = tuple(_written_grasp(gripper, m) for m in request.grasps) or defaults.grasps
    place = defaults.place
    if any(_xyz(request.place.place_axis)):
        place = PlaceSpec(_xyz(request.place.place_axis), request.place.seat_offset)
    s = request.settings
    config = defaults.config
    if s.tilt_step != 0.0:
        config = CheckConfig(s.tolerance, s.tilt_min, s.tilt_max, s.tilt_step,
                             s.approach_cone, s.rim_tolerance, s.regrasp_station,
                             s.station_margin or CheckConfig.station_margin)
    return Setup(part, gripper, grasps, place, config)


def setup_to_request(setup: Setup, request: CheckParts.Request) -> CheckParts.Request:
    """Fill a request's part model, gripper, grasps, placement and settings from a Setup."""
    g, p, c = setup.gripper, setup.place, setup.config
    request.part_model = common.part_spec_to_msg(setup.part)
    request.gripper = gripper_to_msg(g)
    request.grasps = [_written_grasp_msg(x) for x in setup.grasps]
    request.place = PlaceSpecMsg(place_axis=Vector3(x=p.place_axis[0], y=p.place_axis[1],
                                                    z=p.place_axis[2]),
                                 seat_offset=p.seat_offset)
    request.settings = CheckSettings(tolerance=c.tolerance, tilt_min=c.tilt_min,
                                     tilt_max=c.tilt_max, tilt_step=c.tilt_step,
                                     approach_cone=c.approach_cone,
                                     rim_tolerance=c.rim_tolerance,
                                     regrasp_station=c.regrasp_station,
                                     station_margin=c.station_margin)
    return request


def _grasp_msg(name, up, closing, opening, point) -> GraspPoseMsg:
    return GraspPoseMsg(name=name, up_axis=Vector3(x=float(up[0]), y=float(up[1]),
                                                   z=float(up[2])),
                        closing_axis=Vector3(x=float(closing[0]), y=float(closing[1]),
                                             z=float(closing[2])),
                        jaw_opening=float(opening),
                        grasp_point=Point(x=float(point[0]), y=float(point[1]),
                                          z=float(point[2])))


def _written_grasp_msg(grasp) -> GraspPoseMsg:
    """A written grasp of any kind as a message; the fields its kind does not have, 0."""
    v = {'closing_axis': (0.0, 0.0, 0.0), 'jaw_opening': 0.0,
         **{f.name: getattr(grasp, f.name) for f in fields(grasp)}}
    return _grasp_msg(v['name'], v['up_axis'], v['closing_axis'], v['jaw_opening'],
                      v['grasp_point'])


def report_to_msg(report: Report, validator: Validator, stamp: Time, frame_id: str,
                  instance: int) -> ValidityReport:
    msg = ValidityReport(header=Header(stamp=stamp, frame_id=frame_id), instance=instance,
                         neighbour_check=report.neighbour_check, wall_time=report.wall_time,
                         checked=report.counts['checked'], outside=report.counts['outside'],
                         candidates=report.counts['candidates'],
                         placeable=report.counts['placeable'],
                         container_free=report.counts['container_free'],
                         valid=report.counts['valid'])
    for r in report.results:
        item = PartValidity(part_id=r.part_id, stage_reached=r.stage, valid=r.valid,
                            reason=r.reason, grasp_index=r.grasp_index,
                            candidacy_angle=float(r.candidacy_angle),
                            jaw_opening=float(r.jaw_opening), valid_tilts=list(r.valid_tilts),
                            regrasp=r.regrasp)
        if r.grasp_index >= 0:
            geo = validator.geometry
            g = geo.grasps[r.grasp_index]
            item.grasp = _grasp_msg(g.name, g.up, g.closing, geo.gripper.width(g), g.point)
        if r.gripper_pose is not None:
            item.gripper_pose = common.pose_msg(r.gripper_pose[:3], r.gripper_pose[3:])
        msg.results.append(item)
    return msg


def report_from_msg(msg: ValidityReport) -> Report:
    """A core Report from a ValidityReport (counts recomputed from the stages)."""
    results = []
    for r in msg.results:
        pose = None
        if r.valid:
            p, q = r.gripper_pose.position, r.gripper_pose.orientation
            pose = np.array([p.x, p.y, p.z, q.x, q.y, q.z, q.w])
        results.append(PartResult(r.part_id, r.stage_reached, r.reason, r.grasp_index,
                                  r.candidacy_angle, pose, r.jaw_opening,
                                  tuple(r.valid_tilts), r.regrasp))
    return Report(results, msg.neighbour_check, wall_time=msg.wall_time)
