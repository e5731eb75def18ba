"""The `validity` node: a thin ROS 2 wrapper around `pick_validity.validity.Validator`.

Service `check_parts` (poses come in the request, so a real cell can call it with poses from its
own vision system); topic `results` (the last report, latched, for review). The gripper, the
grasp poses, the placement and the check settings are parameters.
"""

import math
import traceback

from pick_msgs.msg import PartModel, ValidityReport
from pick_msgs.srv import CheckParts
from pick_sim_world import conversions as world_conversions
from pick_sim_world.errors import WorldError
from pick_sim_world.node_runner import declare_mesh_dirs, LATCHED, run
from pick_sim_world.parts import build_part
from rcl_interfaces.msg import FloatingPointRange, ParameterDescriptor
from rclpy.node import Node

from . import conversions as conv
from .config import CAPACITOR_GRASPS, CheckConfig, GraspPose, Gripper, PlaceSpec
from .validity import Validator

CACHE_SIZE = 8   # part models whose geometry and placeability are kept

def _describe(text: str, low: float | None = None, high: float | None = None):
    descriptor = ParameterDescriptor(description=text, read_only=True)
    if low is not None:
        descriptor.floating_point_range = [FloatingPointRange(from_value=low, to_value=high)]
    return descriptor


class ValidityNode(Node):
    """Translates check_parts requests to core calls; publishes the last report."""

    def __init__(self) -> None:
        super().__init__('validity')
        self._defaults = conv.Setup(*self._declare_parameters())
        self._cache: dict[tuple, Validator] = {}
        # Fail at start, not at the first request, on a bad gripper, grasp or setting.
        self._validator_for(world_conversions.part_spec_from_msg(
            PartModel(name='radial_capacitor')), self._defaults)
        self._results = self.create_publisher(ValidityReport, 'results', LATCHED)
        self.create_service(CheckParts, 'check_parts', self._check_parts)
        grasps = self._defaults.grasps
        self.get_logger().info(f'{len(grasps)} grasp pose(s): '
                               f'{", ".join(g.name for g in grasps)}')

    def _declare_parameters(self):
        def get(name, default, text, low=None, high=None):
            return self.declare_parameter(name, default, _describe(text, low, high)).value

        d = Gripper()
        gripper = Gripper(
            body_diameter=get('gripper.body_diameter', d.body_diameter, 'D, m', 1e-4, 1.0),
            body_length=get('gripper.body_length', d.body_length, 'm', 1e-4, 2.0),
            jaw_height=get('gripper.jaw_height', d.jaw_height, 'V, m', 1e-4, 1.0),
            jaw_depth=get('gripper.jaw_depth', d.jaw_depth, 'W, m', 1e-4, 1.0))
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
                get(prefix + 'jaw_opening', d.jaw_opening, 'U, m', 1e-4, 1.0),
                tuple(get(prefix + 'grasp_point', list(d.grasp_point),
                          "jaw tips' centre in the part frame, m"))))
        p = PlaceSpec()
        place = PlaceSpec(
            place_axis=tuple(get('place.axis', list(p.place_axis),
                                 'part axis pointing down into the placing surface')),
            seat_offset=get('place.seat_offset', p.seat_offset,
                            'distance from the part origin to its seating plane along '
                            'place.axis, m', -1.0, 1.0))
        c = CheckConfig()
        config = CheckConfig(
            tolerance=get('check.tolerance', c.tolerance, "largest angle of a grasp's up axis "
                          'from +Z, rad', 1e-6, math.pi / 2),
            tilt_min=get('check.tilt_min', c.tilt_min, 'rad', -math.pi / 2, math.pi / 2),
            tilt_max=get('check.tilt_max', c.tilt_max, 'rad', -math.pi / 2, math.pi / 2),
            tilt_step=get('check.tilt_step', c.tilt_step, 'rad', 1e-3, math.pi))
        self._mesh_dirs = declare_mesh_dirs(self)
        return gripper, tuple(grasps), place, config

    def _validator_for(self, spec, setup: conv.Setup) -> Validator:
        """The validator of a part model and setup, built once (placeability tables are the
        costly part) and kept for the next CACHE_SIZE different ones."""
        key = (conv.geometry_key(spec), setup)
        validator = self._cache.get(key)
        if validator is None:
            validator = Validator(build_part(spec), setup.gripper, setup.grasps, setup.place,
                                  setup.config)
            if len(self._cache) >= CACHE_SIZE:
                self._cache.pop(next(iter(self._cache)))
            self._cache[key] = validator
        return validator

    def _check_parts(self, request: CheckParts.Request,
                     response: CheckParts.Response) -> CheckParts.Response:
        try:
            container, spec, ids, poses, targets = conv.request_to_core(request,
                                                                        self._mesh_dirs)
            validator = self._validator_for(
                spec, conv.setup_from_request(request, self._defaults))
            report = validator.check(container, ids, poses, targets, request.check_neighbours)
        except WorldError as exc:
            response.error_code = world_conversions.error_code(exc)
            response.error_msg = str(exc)
            self.get_logger().warning(f'check_parts refused: {exc}')
            return response
        except Exception as exc:  # a bug: answer, log, keep serving
            response.error_code = world_conversions.ERROR_INTERNAL
            response.error_msg = f'internal error: {type(exc).__name__}: {exc}'
            self.get_logger().error(f'{response.error_msg}\n{traceback.format_exc()}')
            return response
        frame = request.parts[0].pose.header.frame_id
        response.report = conv.report_to_msg(report, validator, self.get_clock().now().to_msg(),
                                             frame, request.instance)
        self._results.publish(response.report)
        return response


def main(args=None) -> None:
    run('validity', ValidityNode, args=args)
