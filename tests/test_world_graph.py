"""The real `world` executable, driven over DDS from a client node."""

import math
import os
import signal

from ament_index_python.packages import get_package_share_directory
from geometry_msgs.msg import Vector3
from graph import NodeProcess, stop_all, unique_namespace
import numpy as np
from pick_common.node_runner import LATCHED
from pick_common.rclpy_adapter import LockedActionClient
from pick_msgs.action import DropParts, RemoveParts, Vibrate
from pick_msgs.msg import ContainerGeometry, PartArray, Scene, Vibration
from pick_msgs.srv import GetParts, ResetScene
import pytest
from visualization_msgs.msg import Marker, MarkerArray

pytestmark = pytest.mark.graph
NS = unique_namespace('cell_a')
FRAME = f'{NS[1:]}/instance_'   # instance k's frame is FRAME + str(k)
OK = GetParts.Response.NONE


@pytest.fixture(scope='module')
def world(private_ros_domain):
    proc = NodeProcess('pick_sim_world', 'world', [
        '-r', f'__ns:={NS}', '-p', 'container.kind:=tray', '-p', 'seed:=5',
        '-p', 'publish_markers:=true'])
    yield proc
    stop_all((proc,))


class Cell:
    """Typed access to the world's endpoints under NS."""

    def __init__(self, client, world: NodeProcess) -> None:
        self.c = client
        node = client.node
        self.get_parts_srv = node.create_client(GetParts, f'{NS}/get_parts')
        self.reset_srv = node.create_client(ResetScene, f'{NS}/reset_scene')
        self.actions = {t: LockedActionClient(node, t, f'{NS}/{name}') for t, name in (
            (DropParts, 'drop_parts'), (Vibrate, 'vibrate'), (RemoveParts, 'remove_parts'))}
        assert client.wait_for_servers(self.get_parts_srv, self.reset_srv,
                                       *self.actions.values(), nodes=(world,)), \
            'the world node did not come up'

    def call(self, client, request):
        return self.c.result(client.call_async(request))

    def get_parts(self, instances=()):
        return self.call(self.get_parts_srv, GetParts.Request(instances=list(instances)))

    def reset(self, **fields):
        return self.call(self.reset_srv, ResetScene.Request(**fields))

    def send(self, action_type, goal, feedback=None):
        handle = self.c.result(self.actions[action_type].send_goal_async(
            goal, feedback_callback=feedback))
        assert handle.accepted
        return handle

    def run(self, action_type, goal, feedback=None):
        handle = self.send(action_type, goal, feedback)
        return self.c.result(handle.get_result_async(), 120.0).result


@pytest.fixture
def cell(world, client):
    cell = Cell(client, world)
    assert cell.reset(keep_scene=True, seed=5).error_code == OK
    return cell


def _poses(parts: PartArray) -> np.ndarray:
    return np.array([[p.pose.pose.position.x, p.pose.pose.position.y, p.pose.pose.position.z]
                     for p in parts.parts])


def test_scene_is_latched_and_describes_the_tray(cell, client):
    scenes = []
    client.node.create_subscription(Scene, f'{NS}/scene', scenes.append, LATCHED)
    assert client.wait(lambda: scenes, 30.0), 'no latched scene'
    scene = scenes[-1]
    assert scene.header.frame_id == 'world'
    assert [i.frame_id for i in scene.instances] == [FRAME + '0']
    container = scene.instances[0].container
    assert container.type == ContainerGeometry.TYPE_TRAY
    assert math.isclose(container.inner_size.x, 0.195) and math.isclose(
        container.inner_size.y, 0.150)
    assert scene.part_model.name == 'radial_capacitor' and len(scene.part_model.primitives) == 2


def test_drop_50_parts_then_read_them_vibrate_and_remove(cell, client):
    published = []
    client.node.create_subscription(PartArray, f'{NS}/parts', published.append, 10)
    feedback = []
    drop = cell.run(DropParts, DropParts.Goal(count=50), feedback.append)
    assert drop.error_code == OK, drop.error_msg
    assert len(drop.part_ids) == 50 and drop.settle.settled and not drop.settle.escaped_ids
    assert feedback, 'feedback at the first settle check at least'
    assert client.wait(lambda: any(len(m.parts) == 50 for m in published), 30.0)
    parts = cell.get_parts()
    assert parts.error_code == OK and len(parts.parts.parts) == 50
    assert all(p.inside and p.pose.header.frame_id == FRAME + '0'
               for p in parts.parts.parts)
    assert np.allclose(_poses(parts.parts), _poses(drop.parts))
    markers = []
    client.node.create_subscription(MarkerArray, f'{NS}/markers', markers.append, LATCHED)
    assert client.wait(lambda: markers, 30.0), 'no latched markers'
    kinds = [m.ns.split('_')[0] for m in markers[-1].markers[1:]]
    assert markers[-1].markers[0].action == Marker.DELETEALL
    assert kinds.count('container') == 5 and kinds.count('part') == 50 * 2  # body + leads
    # each part's markers in its own frame, which /tf moves (frame-locked)
    assert all(m.frame_locked and m.header.frame_id == FRAME.replace('instance_', m.ns)
               for m in markers[-1].markers[1:] if m.ns != 'container')

    vibrate = cell.run(Vibrate, Vibrate.Goal())   # zeros: the node's default vibration
    assert vibrate.error_code == OK, vibrate.error_msg
    moved = np.linalg.norm(_poses(vibrate.parts) - _poses(drop.parts), axis=1)
    assert np.median(moved) > 0.002   # the default vertical shake: about 4 mm (measured)

    remove = cell.run(RemoveParts, RemoveParts.Goal(part_ids=list(drop.part_ids[:5])))
    assert remove.error_code == OK and list(remove.removed_ids) == list(drop.part_ids[:5])
    left = cell.get_parts().parts.parts
    assert len(left) == 45 and not {p.id for p in left} & set(drop.part_ids[:5])


def test_feed_drops_into_the_feeder_zone(cell):
    result = cell.run(DropParts, DropParts.Goal(count=12, zone=DropParts.Goal.ZONE_FEEDER))
    assert result.error_code == OK and len(result.parts.parts) == 12


@pytest.mark.parametrize(('action_type', 'goal', 'code', 'text'), [
    (DropParts, DropParts.Goal(count=0), DropParts.Result.INVALID_ARGUMENT, 'count: 0'),
    (DropParts, DropParts.Goal(count=10**6), DropParts.Result.INVALID_ARGUMENT, 'count'),
    (DropParts, DropParts.Goal(count=3, max_settle_time=math.nan),
     DropParts.Result.INVALID_ARGUMENT, 'max_settle_time: nan must be finite'),
    (DropParts, DropParts.Goal(count=3, instances=[7]), DropParts.Result.UNKNOWN_INSTANCE,
     'instances: 7 does not exist'),
    (DropParts, DropParts.Goal(count=3, zone=9), DropParts.Result.INVALID_ARGUMENT, 'zone: 9'),
    (Vibrate, Vibrate.Goal(vibration=Vibration(amplitude=Vector3(x=math.inf))),
     Vibrate.Result.INVALID_ARGUMENT,
     r'vibration.amplitude[0]: inf must be finite'),
    (Vibrate, Vibrate.Goal(vibration=Vibration(frequency=-1.0)), Vibrate.Result.INVALID_ARGUMENT,
     'vibration.frequency: -1.0'),
    (Vibrate, Vibrate.Goal(vibration=Vibration(direction=4)), Vibrate.Result.INVALID_ARGUMENT,
     'vibration.direction: 4 must be'),
    (RemoveParts, RemoveParts.Goal(part_ids=[123456]), RemoveParts.Result.UNKNOWN_PART,
     'part_ids: 123456 is not a part'),
    (RemoveParts, RemoveParts.Goal(), RemoveParts.Result.INVALID_ARGUMENT, 'part_ids: [] is'),
])
def test_bad_goals_get_an_error_and_the_node_keeps_serving(cell, action_type, goal, code, text):
    result = cell.run(action_type, goal)
    assert result.error_code == code and text in result.error_msg, result.error_msg
    again = cell.run(DropParts, DropParts.Goal(count=2))
    assert again.error_code == OK


def test_bad_service_requests_get_an_error(cell):
    missing = cell.get_parts([4])
    assert missing.error_code == GetParts.Response.UNKNOWN_INSTANCE
    bad = ResetScene.Request(instance_count=1)
    bad.container.inner_size = Vector3(x=0.1, y=math.nan, z=0.02)
    bad.container.wall_thickness, bad.container.floor_thickness = 0.003, 0.01
    bad.part_model.name = 'radial_capacitor'
    answer = cell.reset(container=bad.container, part_model=bad.part_model, instance_count=1)
    assert answer.error_code == ResetScene.Response.INVALID_ARGUMENT
    assert 'container.inner_size[1]: nan must be finite' in answer.error_msg
    bad.part_model.name = 'resistor'
    bad.container.inner_size.y = 0.1
    answer = cell.reset(container=bad.container, part_model=bad.part_model, instance_count=1)
    assert answer.error_code == ResetScene.Response.UNKNOWN_PART and 'resistor' in answer.error_msg
    assert cell.get_parts().error_code == OK


def test_reset_builds_a_new_scene_with_instances(cell, client):
    request = ResetScene.Request(instance_count=2, seed=9)
    request.container.type = ContainerGeometry.TYPE_BIN
    request.container.inner_size = Vector3(x=0.1, y=0.08, z=0.02)
    request.container.wall_thickness, request.container.floor_thickness = 0.002, 0.005
    request.part_model.name = 'dip'
    answer = cell.reset(**{k: getattr(request, k) for k in (
        'container', 'part_model', 'instance_count', 'seed')})
    assert answer.error_code == OK, answer.error_msg
    assert [i.frame_id for i in answer.scene.instances] == [FRAME + '0',
                                                            FRAME + '1']
    result = cell.run(DropParts, DropParts.Goal(count=10))
    assert result.error_code == OK and len(result.parts.parts) == 20
    assert len(cell.get_parts([1]).parts.parts) == 10
    # Back to the module's tray for the other tests.
    request.container = ContainerGeometry(type=ContainerGeometry.TYPE_TRAY)
    request.container.inner_size = Vector3(x=0.195, y=0.150, z=0.027)
    request.container.wall_thickness, request.container.floor_thickness = 0.003, 0.01
    request.container.feeder_zone_center.x = -0.073125
    request.container.feeder_zone_size = Vector3(x=0.04875, y=0.12)
    request.part_model.name = 'radial_capacitor'
    assert cell.reset(container=request.container, part_model=request.part_model,
                      instance_count=1, seed=5).error_code == OK


def test_a_second_goal_while_one_runs_is_busy_and_cancel_stops_the_first(cell, client):
    feedback = []
    first = cell.send(DropParts, DropParts.Goal(count=300, max_settle_time=60.0),
                      feedback.append)
    assert client.wait(lambda: feedback, 60.0), 'no feedback from the running drop'
    second = cell.run(DropParts, DropParts.Goal(count=1))
    assert second.error_code == DropParts.Result.BUSY and 'not queued' in second.error_msg
    assert cell.get_parts().error_code == OK, 'get_parts answers while physics runs'
    client.result(first.cancel_goal_async())
    result = client.result(first.get_result_async(), 60.0).result
    assert result.error_code == DropParts.Result.CANCELED
    # The parts stream in by layers: those spawned before the cancel stay, where they stopped.
    assert 0 < len(result.part_ids) <= 300
    assert sorted(p.id for p in result.parts.parts) == sorted(result.part_ids)


@pytest.mark.parametrize(('args', 'text'), [
    (['-p', 'instances:=0'], 'instances out of range. Min: 1, Max: 64'),
    (['-p', 'part.model:=resistor'], "part.model: 'resistor' is not a part model"),
    (['-p', 'container.inner_size:=[0.1, 0.0, 0.02]'], 'container.inner_size[1]: 0.0 must be'),
    (['-p', 'part.model:=mesh', '-p', 'part.mesh_path:=/no/such.stl', '-p', 'part.mass:=0.001'],
     "part.mesh_path: '/no/such.stl' does not exist"),
    (['--params-file', '/no/such.yaml'], "Couldn't parse params file"),
    (['-p', 'vibration.direction:=sideways'],
     "vibration.direction: 'sideways' must be one of fixed, random"),
    (['-p', 'vibration.amplitude:=[0.0, 0.0, 0.0]'], 'vibration.amplitude'),
])
def test_bad_parameters_stop_the_node_with_a_clear_message(private_ros_domain, args, text):
    proc = NodeProcess('pick_sim_world', 'world', args)
    proc.process.wait(60)
    output = proc.output()
    assert proc.process.returncode == 2, output
    assert text in output and 'Traceback' not in output, output


def test_parameter_file_configures_the_scene(private_ros_domain, client, start_node):
    params = os.path.join(get_package_share_directory('pick_sim_world'), 'config', 'tray.yaml')
    namespace = unique_namespace('cell_b')
    start_node('pick_sim_world', 'world', '-r', f'__ns:={namespace}', '--params-file', params)
    scenes = []
    client.node.create_subscription(Scene, f'{namespace}/scene', scenes.append, LATCHED)
    assert client.wait(lambda: scenes, 60.0), 'no latched scene from the parameter file node'
    assert scenes[-1].part_model.name == 'to220'
    assert scenes[-1].instances[0].container.type == ContainerGeometry.TYPE_TRAY


def test_a_node_that_crashes_natively_leaves_its_python_stacks_in_its_log(client):
    """Shutdown crashes seen in CI left nothing to go on; the launcher turns on faulthandler."""
    proc = NodeProcess('pick_sim_world', 'world', ['-r', f'__ns:={NS}/crash'])
    try:
        probe = client.node.create_client(GetParts, f'{NS}/crash/get_parts')
        assert client.wait_for_servers(probe, nodes=(proc,))
        os.kill(proc.process.pid, signal.SIGSEGV)
        assert proc.process.wait(30) == -signal.SIGSEGV
    finally:
        proc.stop()
    output = proc.output()
    assert 'Fatal Python error: Segmentation fault' in output, output
    assert 'Current thread' in output and 'Thread 0x' in output, output
