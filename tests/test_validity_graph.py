"""The real `validity` executable, fed a bin settled by the real `world` executable over DDS,
agrees part by part with the pure core; bad requests get an error and it keeps serving."""

import copy
import math

from graph import NodeProcess, stop_all, unique_namespace
from pick_common.conversions import container_from_msg, part_spec_from_msg, parts_to_arrays
from pick_common.node_runner import LATCHED
from pick_common.rclpy_adapter import LockedActionClient
from pick_msgs.action import DropParts
from pick_msgs.msg import Scene, ValidityReport
from pick_msgs.srv import CheckParts, GetParts
from pick_validity.config import Setup
from pick_validity.validity import Validator
import pytest

pytestmark = pytest.mark.graph
NS = unique_namespace('cell_v')
OK = CheckParts.Response.NONE


@pytest.fixture(scope='module')
def nodes(private_ros_domain):
    world = NodeProcess('pick_sim_world', 'world', [
        '-r', f'__ns:={NS}', '-p', 'container.inner_size:=[0.15, 0.15, 0.026]', '-p', 'seed:=3',
        '-p', 'publish_markers:=false'])
    validity = NodeProcess('pick_validity', 'validity', ['-r', f'__ns:={NS}'])
    yield world, validity
    stop_all((world, validity))


@pytest.fixture(scope='module')
def settled(nodes):
    """A scene and its 120 settled parts, read from the world node over DDS."""
    from graph import Client
    client = Client()
    try:
        drop = LockedActionClient(client.node, DropParts, f'{NS}/drop_parts')
        assert client.wait_for_servers(drop, nodes=nodes)
        handle = client.result(drop.send_goal_async(DropParts.Goal(count=120)))
        result = client.result(handle.get_result_async(), 120.0).result
        assert result.error_code == 0, result.error_msg
        scenes = []
        client.node.create_subscription(Scene, f'{NS}/scene', scenes.append, LATCHED)
        get_parts = client.node.create_client(GetParts, f'{NS}/get_parts')
        assert client.wait_for_servers(get_parts) and client.wait(lambda: scenes, 30.0)
        parts = client.result(get_parts.call_async(GetParts.Request())).parts.parts
        yield scenes[-1], parts
    finally:
        client.close()


def _request(scene, parts, **fields) -> CheckParts.Request:
    return CheckParts.Request(container=scene.instances[0].container,
                              part_model=copy.deepcopy(scene.part_model),
                              parts=copy.deepcopy(list(parts)), **fields)


@pytest.fixture
def check(client, nodes):
    """Call check_parts: request -> response."""
    service = client.node.create_client(CheckParts, f'{NS}/check_parts')
    assert client.wait_for_servers(service, nodes=nodes), 'validity did not come up'
    return lambda request: client.result(service.call_async(request))


@pytest.mark.parametrize('neighbours', [False, True])
def test_service_agrees_with_the_core_on_a_settled_bin(client, check, settled, neighbours):
    scene, parts = settled
    reports = []
    client.node.create_subscription(ValidityReport, f'{NS}/results', reports.append, LATCHED)
    response = check(_request(scene, parts, check_neighbours=neighbours))
    assert response.error_code == OK, response.error_msg
    ids, _, poses = parts_to_arrays(parts)
    core = Validator(Setup(part_spec_from_msg(scene.part_model))).check(
        container_from_msg(scene.instances[0].container), ids, poses,
        neighbour_check=neighbours)
    got = [(r.part_id, r.stage_reached, r.grasp_index, tuple(r.valid_tilts), r.regrasp)
           for r in response.report.results]
    assert got == [r.key() for r in core.results]
    report = response.report
    assert report.checked == 120 and report.valid == core.counts['valid']
    assert report.candidates >= report.placeable >= report.container_free >= report.valid
    assert report.header.frame_id == f'{NS[1:]}/instance_0'
    assert client.wait(lambda: reports and reports[-1].checked == 120, 30.0), 'no results'
    valid = [r for r in report.results if r.valid]
    assert valid, 'a settled bin has valid parts'
    assert all(r.grasp.name and r.valid_tilts and r.gripper_pose.orientation.w != 0
               for r in valid)


def test_a_suction_request_is_checked_with_the_cup_as_the_core_checks_it(check, settled):
    # the world's capacitors, checked with a 3 mm cup on their flat ends and, lying, at four
    # rolls: the request carries the cup and its grasps; the node answers as the core does
    from pick_validity import conversions as validity_conv
    from pick_validity.grasps import SuctionGrasp
    from pick_validity.grippers import SuctionCup
    scene, parts = settled
    cup = SuctionCup(cup_diameter=0.003)
    grasps = (SuctionGrasp('end', (0, 0, 1), (0, 0, 0.0055)),
              *(SuctionGrasp(f'side{k}', (math.cos(k * math.pi / 2), math.sin(k * math.pi / 2),
                                          0.0), (0.0025 * math.cos(k * math.pi / 2),
                                                 0.0025 * math.sin(k * math.pi / 2), 0.0))
                for k in range(4)))
    setup = Setup(part_spec_from_msg(scene.part_model), gripper=cup, grasps=grasps)
    request = validity_conv.setup_to_request(setup, _request(scene, parts, check_neighbours=True))
    assert request.gripper.type == request.gripper.SUCTION
    response = check(request)
    assert response.error_code == OK, response.error_msg
    ids, _, poses = parts_to_arrays(parts)
    core = Validator(setup).check(container_from_msg(scene.instances[0].container), ids, poses)
    assert [(r.part_id, r.stage_reached, r.grasp_index, tuple(r.valid_tilts), r.regrasp)
            for r in response.report.results] == [r.key() for r in core.results]
    assert response.report.valid == core.counts['valid'] > 0
    # an unknown gripper type is refused by name, and the node keeps serving
    bad = validity_conv.setup_to_request(setup, _request(scene, parts))
    bad.gripper.type = 7
    answer = check(bad)
    assert answer.error_code == CheckParts.Response.INVALID_ARGUMENT
    assert 'gripper.type: 7 must be 0 (jaws) or 1 (suction)' in answer.error_msg
    assert check(_request(scene, parts)).error_code == OK


def test_targets_only_are_checked(check, settled):
    scene, parts = settled
    response = check(_request(scene, parts, target_ids=[parts[3].id, parts[7].id]))
    assert response.error_code == OK
    assert [r.part_id for r in response.report.results] == [parts[3].id, parts[7].id]


def test_bad_requests_get_an_error_and_it_keeps_serving(check, settled):
    scene, parts = settled
    bad = _request(scene, parts)
    bad.parts[5].pose.pose.position.x = math.nan
    answer = check(bad)
    assert answer.error_code == CheckParts.Response.INVALID_ARGUMENT
    assert f'parts[5] (id {parts[5].id}).pose' in answer.error_msg and 'finite' in answer.error_msg

    bad = _request(scene, parts)
    bad.parts[2].pose.pose.orientation.w += 0.5
    answer = check(bad)
    assert answer.error_code == CheckParts.Response.INVALID_ARGUMENT
    assert 'must be a unit quaternion' in answer.error_msg

    answer = check(_request(scene, []))
    assert answer.error_code == CheckParts.Response.INVALID_ARGUMENT and 'empty' in answer.error_msg

    answer = check(_request(scene, parts, target_ids=[99999]))
    assert answer.error_code == CheckParts.Response.UNKNOWN_PART

    unknown = _request(scene, parts)
    unknown.part_model.name = 'resistor'
    answer = check(unknown)
    assert answer.error_code == CheckParts.Response.UNKNOWN_PART and 'resistor' in answer.error_msg

    answer = check(_request(scene, parts))
    assert answer.error_code == OK and answer.report.checked == 120


def test_bad_parameters_stop_the_node_with_a_clear_message(private_ros_domain):
    proc = NodeProcess('pick_validity', 'validity', [
        '-p', 'grasps.side_px.closing_axis:=[1.0, 0.0, 0.0]'])
    proc.process.wait(60)
    output = proc.output()
    assert proc.process.returncode == 2, output
    assert 'grasps.side_px.closing_axis: (1.0, 0.0, 0.0) is parallel to up_axis' in output
    assert 'Traceback' not in output
