"""The one place that maps check_parts requests and ValidityReport messages to and from the
validity core. Container, part-model and part conversions are pick_sim_world's, reused."""

from builtin_interfaces.msg import Time
from geometry_msgs.msg import Point, Pose, Quaternion, Vector3
from pick_msgs.msg import GraspPose as GraspPoseMsg
from pick_msgs.msg import PartValidity, ValidityReport
from pick_msgs.srv import CheckParts
from pick_sim_world import conversions as world_conversions
from pick_sim_world.containers import ContainerSpec
from pick_sim_world.parts import PartSpec
from std_msgs.msg import Header

from .validity import Report, Validator


def request_to_core(request: CheckParts.Request) -> tuple[ContainerSpec, PartSpec, list[int],
                                                         object, list[int] | None]:
    """Container, part spec, ids, poses (N, 7) and targets (None for all) of a request."""
    ids, _, poses = world_conversions.parts_to_arrays(request.parts)
    targets = [int(t) for t in request.target_ids] or None
    return (world_conversions.container_from_msg(request.container),
            world_conversions.part_spec_from_msg(request.part_model), ids.tolist(), poses,
            targets)


def geometry_key(spec: PartSpec) -> tuple:
    """What a part's collision geometry depends on (not its mass or friction)."""
    return spec.model, tuple(sorted(spec.dimensions.items())), spec.mesh_path, spec.scale


def _pose(values) -> Pose:
    x, y, z, qx, qy, qz, qw = (float(v) for v in values)
    return Pose(position=Point(x=x, y=y, z=z),
                orientation=Quaternion(x=qx, y=qy, z=qz, w=qw))


def report_to_msg(report: Report, validator: Validator, stamp: Time, frame_id: str,
                  instance: int) -> ValidityReport:
    msg = ValidityReport(header=Header(stamp=stamp, frame_id=frame_id), instance=instance,
                         neighbour_check=report.neighbour_check, wall_time=report.wall_time,
                         checked=report.counts['checked'],
                         candidates=report.counts['candidates'],
                         placeable=report.counts['placeable'],
                         container_free=report.counts['container_free'],
                         valid=report.counts['valid'])
    for r in report.results:
        item = PartValidity(part_id=r.part_id, stage_reached=r.stage, valid=r.valid,
                            reason=r.reason, grasp_index=r.grasp_index,
                            candidacy_angle=float(r.candidacy_angle),
                            jaw_opening=float(r.jaw_opening), valid_tilts=list(r.valid_tilts))
        if r.grasp_index >= 0:
            g = validator.grasps[r.grasp_index]
            item.grasp = GraspPoseMsg(
                name=g.name, up_axis=Vector3(x=g.up[0], y=g.up[1], z=g.up[2]),
                closing_axis=Vector3(x=g.closing[0], y=g.closing[1], z=g.closing[2]),
                jaw_opening=g.jaw_opening, grasp_point=Point(x=g.point[0], y=g.point[1],
                                                             z=g.point[2]))
        if r.gripper_pose is not None:
            item.gripper_pose = _pose(r.gripper_pose)
        msg.results.append(item)
    return msg
