"""The one place that maps check_parts requests and ValidityReport messages to and from the
validity core. Container, part-model and part conversions are pick_common's, reused."""

from collections.abc import Sequence

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

from .config import (
    CheckConfig,
    GraspPose,
    Gripper,
    is_suction,
    PlaceSpec,
    Setup,
    SUCTION_FIELDS,
    SuctionCup,
    SuctionGrasp,
)
from .results import PartResult, Report
from .validity import Validator


def request_to_core(request: CheckParts.Request
                    ) -> tuple[ContainerSpec, list[int], object, list[int] | None]:
    """Container, ids, poses (N, 7) and targets (None for all) of a request (its setup:
    `setup_from_request`)."""
    ids, _, poses = common.parts_to_arrays(request.parts)
    targets = [int(t) for t in request.target_ids] or None
    return common.container_from_msg(request.container), ids.tolist(), poses, targets


def _xyz(v) -> tuple[float, float, float]:
    return float(v.x), float(v.y), float(v.z)


def setup_from_request(request: CheckParts.Request, defaults: Setup,
                       mesh_dirs: Sequence[str]) -> Setup:
    """The request's part model, gripper, grasps, placement and settings; each but the part
    left empty (all 0 or an empty list) takes the node's default. A mesh file must lie in one
    of `mesh_dirs`. Checked by the core."""
    part = common.part_spec_from_msg(request.part_model, mesh_dirs)
    g = request.gripper
    gripper = defaults.gripper
    if g.type == GripperMsg.SUCTION:
        gripper = SuctionCup(**{name: getattr(g, name) for name in SUCTION_FIELDS})
    elif g.type != GripperMsg.JAWS:
        raise InvalidArgument('gripper.type', g.type, f'must be {GripperMsg.JAWS} (jaws) or '
                              f'{GripperMsg.SUCTION} (suction)')
    elif any((g.body_diameter, g.body_length, g.jaw_height, g.jaw_depth)):
        gripper = Gripper(g.body_diameter, g.body_length, g.jaw_height, g.jaw_depth,
                          g.finger_clearance)
    if is_suction(gripper):
        grasps = tuple(SuctionGrasp(m.name, _xyz(m.up_axis), _xyz(m.grasp_point))
                       for m in request.grasps) or defaults.grasps
    else:
        grasps = tuple(GraspPose(m.name, _xyz(m.up_axis), _xyz(m.closing_axis), m.jaw_opening,
                                 _xyz(m.grasp_point)) for m in request.grasps) or defaults.grasps
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
    if is_suction(g):
        request.gripper = GripperMsg(type=GripperMsg.SUCTION,
                                     **{name: getattr(g, name) for name in SUCTION_FIELDS})
        request.grasps = [_grasp_msg(x.name, x.up_axis, (0.0, 0.0, 0.0), 0.0, x.grasp_point)
                          for x in setup.grasps]
    else:
        request.gripper = GripperMsg(type=GripperMsg.JAWS, body_diameter=g.body_diameter,
                                     body_length=g.body_length, jaw_height=g.jaw_height,
                                     jaw_depth=g.jaw_depth,
                                     finger_clearance=g.finger_clearance)
        request.grasps = [_grasp_msg(x.name, x.up_axis, x.closing_axis, x.jaw_opening,
                                     x.grasp_point) for x in setup.grasps]
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
            g = validator.grasps[r.grasp_index]
            item.grasp = _grasp_msg(g.name, g.up, g.closing, g.jaw_opening, g.point)
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
