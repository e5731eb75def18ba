"""Every service and action of every node, fuzzed over DDS with property-based requests.

One worker (`world`, `validity`, `feeder_controller`) and an `experiment_manager` run as real
processes. Each endpoint gets requests drawn by hypothesis from its interface definition (fuzz.py:
NaN, inf, huge and empty values, wrong sizes, unknown ids, degenerate geometry, paths that leave
the node's directories); the experiment manager also gets experiment files with mutated content.
Every request must be answered, with an error code and a message when refused, never INTERNAL
(the code of an unforeseen exception), and no node may die; a good request afterwards still
works. Long runs: PICK_FUZZ_EXAMPLES=1000 make test PYTEST_ARGS='tests/test_fuzz_graph.py'.
"""

from collections import Counter
import os

from fuzz import documents, requests, TRIED
from geometry_msgs.msg import Vector3
from graph import Client, NodeProcess, stop_all, unique_namespace
from hypothesis import given, HealthCheck, settings
from pick_common.rclpy_adapter import LockedActionClient
from pick_msgs.action import DropParts, FeedCycle, RemoveParts, RunExperiment, Vibrate
from pick_msgs.msg import ContainerGeometry, PartModel, Vibration
from pick_msgs.srv import CheckParts, GetParts, ResetScene
import pytest
import trimesh
import yaml

pytestmark = pytest.mark.graph
NS = unique_namespace('fuzz')
EXAMPLES = int(os.environ.get('PICK_FUZZ_EXAMPLES', 25))
LONG = 'PICK_FUZZ_EXAMPLES' in os.environ
FUZZ = settings(max_examples=EXAMPLES, deadline=None, derandomize=not LONG,
                suppress_health_check=list(HealthCheck), database=None)
INTERNAL = GetParts.Response.INTERNAL
CODES = {GetParts.Response.NONE: 'NONE', GetParts.Response.INVALID_ARGUMENT: 'INVALID_ARGUMENT',
         GetParts.Response.UNKNOWN_INSTANCE: 'UNKNOWN_INSTANCE',
         GetParts.Response.UNKNOWN_PART: 'UNKNOWN_PART', GetParts.Response.BUSY: 'BUSY',
         GetParts.Response.PHYSICS_FAULT: 'PHYSICS_FAULT',
         GetParts.Response.CANCELED: 'CANCELED', INTERNAL: 'INTERNAL'}
GIVE_UP = 10.0       # s an accepted goal may run before it is canceled (a valid, long one)
ANSWER_WAIT = 60.0   # s for a service's answer (a service cannot be canceled)
TINY = {'id': 'tiny', 'seed': 3, 'part': {'model': 'radial_capacitor'},
        'experiments': [{'id': 'bins', 'type': 'bin_static', 'iterations': 1, 'parts': 4,
                         'bins_mm': [[60, 60, 20]]}]}


def tray() -> ContainerGeometry:
    c = ContainerGeometry(type=ContainerGeometry.TYPE_TRAY, wall_thickness=0.003,
                          floor_thickness=0.01)
    c.inner_size = Vector3(x=0.195, y=0.150, z=0.027)
    c.feeder_zone_center.x = -0.073125
    c.feeder_zone_size = Vector3(x=0.04875, y=0.12)
    return c


@pytest.fixture(scope='module')
def places(tmp_path_factory):
    """The node's directories: meshes (one valid STL), experiments (the tiny file), output."""
    root = tmp_path_factory.mktemp('fuzz')
    for name in ('meshes', 'experiments', 'out'):
        (root / name).mkdir()
    trimesh.creation.box((0.01, 0.005, 0.003)).export(str(root / 'meshes' / 'block.stl'))
    # Degenerate geometry that must never reach PyBullet or FCL (an empty BVH crashes it).
    trimesh.Trimesh([[0, 0, 0], [0.01, 0, 0], [0, 0.01, 0]], [[0, 1, 2]]).export(
        str(root / 'meshes' / 'flat.stl'))
    (root / 'meshes' / 'empty.stl').write_text('solid empty\nendsolid empty\n')
    (root / 'meshes' / 'garbage.stl').write_bytes(bytes(range(256)) * 4)
    (root / 'experiments' / 'tiny.yaml').write_text(yaml.safe_dump(TINY))
    (root / 'secret.yaml').write_text(yaml.safe_dump(TINY))     # outside every directory
    return root


@pytest.fixture(scope='module')
def nodes(places, private_ros_domain):
    meshes = ['-p', f'mesh_dirs:=["{places / "meshes"}"]']
    procs = [NodeProcess('pick_sim_world', 'world', ['-r', f'__ns:={NS}/w', '-p',
                                                     'container.kind:=tray', *meshes]),
             NodeProcess('pick_validity', 'validity', ['-r', f'__ns:={NS}/w', *meshes]),
             NodeProcess('feeder_controller', 'feeder_controller', ['-r', f'__ns:={NS}/w']),
             NodeProcess('experiment_manager', 'experiment_manager', [
                 '-r', f'__ns:={NS}', '-p', 'workers:=[w]', '-p', 'call_timeout:=60.0',
                 '-p', f'experiment_dirs:=["{places / "experiments"}"]',
                 '-p', f'output_dirs:=["{places / "out"}"]'])]
    yield procs
    stop_all(procs)


class Endpoints:
    """Typed calls to every endpoint, each answer checked: answered, a known error code, a
    message with every error, never INTERNAL, no node process gone."""

    def __init__(self, client, nodes) -> None:
        self.c, self.nodes = client, tuple(nodes)
        node = client.node
        self.services = {'get_parts': node.create_client(GetParts, f'{NS}/w/get_parts'),
                         'reset_scene': node.create_client(ResetScene, f'{NS}/w/reset_scene'),
                         'check_parts': node.create_client(CheckParts, f'{NS}/w/check_parts')}
        self.actions = {name: LockedActionClient(node, t, f'{NS}/{name}') for name, t in (
            ('w/drop_parts', DropParts), ('w/vibrate', Vibrate), ('w/remove_parts', RemoveParts),
            ('w/feed_cycle', FeedCycle), ('run_experiment', RunExperiment))}
        assert client.wait_for_servers(*self.services.values(), *self.actions.values(),
                                       nodes=self.nodes), 'the nodes did not come up'

    def _checked(self, endpoint: str, answer, request, fuzzed: bool) -> object:
        if fuzzed:
            TRIED.setdefault(endpoint, Counter())[CODES.get(answer.error_code,
                                                            answer.error_code)] += 1
        assert answer.error_code in CODES, (endpoint, answer.error_code, request)
        assert answer.error_code != INTERNAL, (endpoint, answer.error_msg, request)
        assert answer.error_code == 0 or answer.error_msg, (endpoint, request)
        for proc in self.nodes:
            assert proc.running(), f'{proc.name} died on {request}:\n{proc.output()}'
        return answer

    def call(self, name: str, request, fuzzed: bool = False) -> object:
        future = self.services[name].call_async(request)
        assert self.c.wait(future.done, ANSWER_WAIT, self.nodes), (name, 'no answer', request)
        return self._checked(name, future.result(), request, fuzzed)

    def run(self, name: str, goal, fuzzed: bool = False) -> object:
        """Send a goal and wait for its result; a goal still running after GIVE_UP s (a
        valid, long one) is canceled and must then end."""
        handle = self.c.result(self.actions[name].send_goal_async(goal), GIVE_UP)
        assert handle.accepted
        future = handle.get_result_async()
        if not self.c.wait(future.done, GIVE_UP, self.nodes):
            self.c.result(handle.cancel_goal_async())
            assert self.c.wait(future.done, GIVE_UP, self.nodes), (name, 'cancel ignored')
        return self._checked(name, future.result().result, goal, fuzzed)

    def tray_scene(self) -> ResetScene.Request:
        return ResetScene.Request(container=tray(), part_model=PartModel(
            name='radial_capacitor'), instance_count=1, seed=1)

    def fresh(self, parts: int = 6) -> list:
        """The tray with `parts` settled capacitors; returns their Part messages."""
        assert self.call('reset_scene', self.tray_scene()).error_code == 0
        assert self.run('w/drop_parts', DropParts.Goal(count=parts)).error_code == 0
        return list(self.call('get_parts', GetParts.Request()).parts.parts)


@pytest.fixture(scope='module')
def cell(nodes, places):
    client = Client()
    yield Endpoints(client, nodes)
    client.close()


def test_get_parts(cell):
    cell.fresh()

    @FUZZ
    @given(requests(GetParts.Request(instances=[0])))
    def fuzz(request):
        cell.call('get_parts', request, fuzzed=True)

    fuzz()
    assert len(cell.call('get_parts', GetParts.Request()).parts.parts) == 6


def test_reset_scene(cell, places):
    mesh = ResetScene.Request(container=tray(), part_model=PartModel(
        name='mesh', mesh_path=str(places / 'meshes' / 'block.stl'), mass=0.001),
        instance_count=2, seed=4)

    @FUZZ
    @given(requests(cell.tray_scene()) | requests(mesh))
    def fuzz(request):
        cell.call('reset_scene', request, fuzzed=True)

    fuzz()
    for name in ('flat.stl', 'empty.stl', 'garbage.stl'):
        mesh.part_model.mesh_path = str(places / 'meshes' / name)
        assert cell.call('reset_scene', mesh).error_code == ResetScene.Response.INVALID_ARGUMENT
        answer = cell.call('check_parts', CheckParts.Request(
            container=tray(), part_model=mesh.part_model, parts=cell.fresh(1)))
        assert answer.error_code == CheckParts.Response.INVALID_ARGUMENT, answer.error_msg
        assert f"part.mesh_path: '{mesh.part_model.mesh_path}'" in answer.error_msg
    mesh.part_model.mesh_path = str(places / 'meshes' / 'block.stl')
    assert cell.call('reset_scene', mesh).error_code == 0     # a mesh inside mesh_dirs
    outside = cell.call('reset_scene', ResetScene.Request(
        container=tray(), part_model=PartModel(name='mesh', mass=0.001, mesh_path=str(
            places / 'meshes' / '..' / 'secret.yaml')), instance_count=1))
    assert outside.error_code == ResetScene.Response.INVALID_ARGUMENT
    assert 'is outside the directories this node may use (mesh_dirs:' in outside.error_msg
    cell.fresh()


@pytest.mark.parametrize(('name', 'template'), [
    ('w/drop_parts', DropParts.Goal(count=3, zone=DropParts.Goal.ZONE_FEEDER)),
    ('w/vibrate', Vibrate.Goal(vibration=Vibration(duration=0.2))),
    ('w/remove_parts', RemoveParts.Goal(part_ids=[0, 1], skip_settle=True)),
])
def test_world_actions(cell, name, template):
    cell.fresh()

    @FUZZ
    @given(requests(template))
    def fuzz(goal):
        cell.run(name, goal, fuzzed=True)
        if len(cell.call('get_parts', GetParts.Request()).parts.parts) > 60:
            cell.fresh()      # keep the scene small: a fuzzed count may be large and valid

    fuzz()
    parts = cell.fresh()
    assert cell.run('w/remove_parts', RemoveParts.Goal(part_ids=[parts[0].id])).error_code == 0


def test_check_parts(cell, places):
    parts = cell.fresh(8)
    template = CheckParts.Request(container=tray(), part_model=PartModel(
        name='radial_capacitor'), parts=parts, target_ids=[parts[0].id], check_neighbours=True)

    @FUZZ
    @given(requests(template))
    def fuzz(request):
        cell.call('check_parts', request, fuzzed=True)

    fuzz()
    report = cell.call('check_parts', template).report
    assert report.checked == 1 and [r.part_id for r in report.results] == [parts[0].id]
    mesh = PartModel(name='mesh', mass=0.001, mesh_path='/etc/passwd')
    answer = cell.call('check_parts', CheckParts.Request(container=tray(), part_model=mesh,
                                                         parts=parts))
    assert answer.error_code == CheckParts.Response.INVALID_ARGUMENT
    assert "part_model.mesh_path: '/etc/passwd' is outside" in answer.error_msg


def test_feed_cycle(cell):
    cell.fresh(1)
    template = FeedCycle.Goal(instance=0, restart=True, feeder_parts=10, min_count=2,
                              max_count=4, max_vibrations=5,
                              moves=[Vibration(duration=0.2)])

    @FUZZ
    @given(requests(template))
    def fuzz(goal):
        cell.run('w/feed_cycle', goal, fuzzed=True)
        if len(cell.call('get_parts', GetParts.Request()).parts.parts) > 60:
            cell.fresh(1)

    fuzz()
    cell.fresh(1)
    assert cell.run('w/feed_cycle', template).error_code == 0


def test_run_experiment(cell, places):
    good = RunExperiment.Goal(experiment_file=str(places / 'experiments' / 'tiny.yaml'),
                              output_dir=str(places / 'out'))
    count = iter(range(10 ** 6))

    @FUZZ
    @given(requests(good))
    def fuzz_goal(goal):
        cell.run('run_experiment', goal, fuzzed=True)

    @settings(FUZZ, max_examples=max(5, EXAMPLES // 2))
    @given(documents(TINY))
    def fuzz_file(doc):
        path = places / 'experiments' / f'fuzzed_{next(count)}.yaml'
        path.write_text(yaml.safe_dump(doc))
        cell.run('run_experiment', RunExperiment.Goal(experiment_file=str(path),
                                                      output_dir=str(places / 'out')),
                 fuzzed=True)

    fuzz_goal()
    fuzz_file()
    refused = cell.run('run_experiment', RunExperiment.Goal(
        experiment_file=str(places / 'secret.yaml'), output_dir=str(places / 'out')))
    assert refused.error_code == RunExperiment.Result.INVALID_ARGUMENT
    assert 'is outside the directories this node may use (experiment_dirs:' in refused.error_msg
    refused = cell.run('run_experiment', RunExperiment.Goal(
        experiment_file=good.experiment_file, output_dir=str(places / 'out' / '..' / '..')))
    assert 'output_dir:' in refused.error_msg and '(output_dirs:' in refused.error_msg
    answer = cell.run('run_experiment', good)
    assert answer.error_code == 0, answer.error_msg
    assert os.path.isfile(os.path.join(answer.results_path, 'iterations.csv'))
