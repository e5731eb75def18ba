"""The `validity` node: a thin ROS 2 wrapper around `pick_validity.validity.Validator`.

Service `check_parts` (poses come in the request, so a real cell can call it with poses from its
own vision system); topic `results` (the last report, latched, for review). The gripper, the
grasp poses, the placement and the check settings are parameters.
"""

from pick_common.node_runner import answer_error, declare, declare_mesh_dirs, LATCHED, run
from pick_common.parts.spec import PartSpec
from pick_msgs.msg import ValidityReport
from pick_msgs.srv import CheckParts
from rclpy.node import Node

from . import conversions as conv
from .config import CAPACITOR_GRASPS, CheckConfig, LIMITS, PlaceSpec, Setup
from .grasps import GraspPose
from .grippers import Jaws
from .validity import Validator

# Validators (part model x gripper, grasps, placing, settings) kept: a gripper_sweep cycles
# through up to 64 setups per scene. 64 PTH0 validators took 0.8 MB of RSS and 17 ms each to
# build, so keeping 64 costs little and spares a rebuild per check.
CACHE_SIZE = 64


class ValidityNode(Node):
    """Translates check_parts requests to core calls; publishes the last report."""

    def __init__(self) -> None:
        super().__init__('validity')
        self._defaults = Setup(PartSpec(), *self._declare_parameters())
        self._cache: dict[tuple, Validator] = {}
        # Fail at start, not at the first request, on a bad gripper, grasp or setting.
        self._validator_for(self._defaults)
        self._results = self.create_publisher(ValidityReport, 'results', LATCHED)
        self.create_service(CheckParts, 'check_parts', self._check_parts)
        grasps = self._defaults.grasps
        self.get_logger().info(f'{len(grasps)} grasp pose(s): '
                               f'{", ".join(g.name for g in grasps)}')

    def _declare_parameters(self):
        def get(name, default, text, limit=None):
            return declare(self, name, default, text, limit)

        # the default gripper's kind, parallel jaws, with its keys as parameters (the kind's
        # table: grippers.Jaws.KEYS); a request may send any kind
        d = Jaws()
        gripper = Jaws(**{key.field: get(f'gripper.{key.field}', getattr(d, key.field),
                                         key.text, key.limit) for key in Jaws.KEYS})
        defaults = {g.name: g for g in CAPACITOR_GRASPS}
        names = get('grasp_names', list(defaults),
                    'names of the grasp poses; each has grasps.<name>.* parameters')
        grasps = []
        for name in names:
            d = defaults.get(name, GraspPose(name, (0.0, 0.0, 1.0), (1.0, 0.0, 0.0), 0.01))
            prefix = f'grasps.{name}.'
            grasps.append(GraspPose(
                name,
                tuple(get(prefix + 'up_axis', list(d.up_axis), 'part axis that must point up')),
                tuple(get(prefix + 'closing_axis', list(d.closing_axis),
                          "part axis along the jaws' closing direction")),
                get(prefix + 'jaw_opening', d.jaw_opening, 'U, m', LIMITS['jaw_opening']),
                tuple(get(prefix + 'grasp_point', list(d.grasp_point),
                          'point the jaws close on, in the part frame, m'))))
        p = PlaceSpec()
        place = PlaceSpec(
            place_axis=tuple(get('place.axis', list(p.place_axis),
                                 'part axis pointing down into the placing surface')),
            seat_offset=get('place.seat_offset', p.seat_offset,
                            'distance from the part origin to its seating plane along '
                            'place.axis, m', LIMITS['place.seat_offset']))
        c = CheckConfig()
        config = CheckConfig(
            tolerance=get('check.tolerance', c.tolerance, "largest angle of a grasp's up axis "
                          'from +Z, rad', LIMITS['check.tolerance']),
            tilt_min=get('check.tilt_min', c.tilt_min, 'rad', LIMITS['check.tilt_min']),
            tilt_max=get('check.tilt_max', c.tilt_max, 'rad', LIMITS['check.tilt_max']),
            tilt_step=get('check.tilt_step', c.tilt_step, 'rad', LIMITS['check.tilt_step']),
            approach_cone=get('check.approach_cone', c.approach_cone,
                              "largest angle of the gripper's axis from +Z, rad",
                              LIMITS['check.approach_cone']),
            rim_tolerance=get('check.rim_tolerance', c.rim_tolerance,
                              "how far above the container's rim a part's centre may lie, m",
                              LIMITS['check.rim_tolerance']))
        self._mesh_dirs = declare_mesh_dirs(self)
        return gripper, tuple(grasps), place, config

    def _validator_for(self, setup: Setup) -> Validator:
        """The validator of a setup, built once (placeability tables are the costly part) and
        kept for the next CACHE_SIZE different ones."""
        key = setup.key()
        validator = self._cache.get(key)
        if validator is None:
            validator = Validator(setup)
            if len(self._cache) >= CACHE_SIZE:
                self._cache.pop(next(iter(self._cache)))
            self._cache[key] = validator
        return validator

    def _check_parts(self, request: CheckParts.Request,
                     response: CheckParts.Response) -> CheckParts.Response:
        try:
            container, ids, poses, targets = conv.request_to_core(request)
            validator = self._validator_for(
                conv.setup_from_request(request, self._defaults, self._mesh_dirs))
            report = validator.check(container, ids, poses, targets, request.check_neighbours)
        except Exception as exc:  # core errors get their code, bugs INTERNAL (answer_error)
            answer_error(response, exc, self.get_logger(), 'check_parts')
            return response
        frame = request.parts[0].pose.header.frame_id
        response.report = conv.report_to_msg(report, validator, self.get_clock().now().to_msg(),
                                             frame, request.instance)
        self._results.publish(response.report)
        return response


def main(args=None) -> None:
    run('validity', ValidityNode, args=args)
