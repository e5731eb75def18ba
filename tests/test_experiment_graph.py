"""End to end: the `run` command brings up two workers (world, validity, feeder_controller) and
experiment_manager as processes, runs a small file of every experiment type over DDS with a
drop test beside it, and leaves each its results and recording. Each recording is decoded by
an independent reader (mcap-ros2-support, from the schema text in the file) and matched against
its results; the results are matched against the same file run on the cores in one process.
Then: replay, a bad file, a worker killed mid-run (the other finishes the run with the same
results), a second goal beside the first (canceled while it waits) and a third refused, and
the last worker killed (the runs fail, keeping what finished)."""

from collections.abc import Callable
import glob
import json
import os
import re
import signal
import subprocess
import time

from ament_index_python.packages import get_package_share_directory
from experiment_manager import experiment_file
from experiment_manager.analysis import summary as summary_model
from experiment_manager.analysis.results import FILES, read_text_rows, ResultsWriter
from experiment_manager.analysis.verdicts import verdicts
from experiment_manager.analysis.wording import verdict_table
from experiment_manager.commands import interrupt, supervisor
from experiment_manager.commands.launcher import executable, WORKER_NODES
from experiment_manager.running.local_backend import LocalBackend
from experiment_manager.running.scheduler import Runner
from graph import SMALL, unique_namespace
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from pick_common.rclpy_adapter import LockedActionClient
from pick_msgs.action import RunExperiment
from pick_msgs.msg import ValidityReport, Verdict
from pick_sim_world.bodies import instance_seed
import pytest
import rclpy
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions
from rosgraph_msgs.msg import Clock
import yaml

pytestmark = pytest.mark.graph
NS = unique_namespace('exp')
WORKERS = 2
STAGE_COUNTS = ('checked', 'candidates', 'placeable', 'container_free', 'valid')


def rows(directory: str, name: str) -> list[dict]:
    return read_text_rows(os.path.join(directory, f'{name}.csv'), drop=('wall_time',))


def run_command(*args: str, timeout: float = 600.0) -> subprocess.CompletedProcess:
    return subprocess.run([executable('experiment_manager', 'run'), *args],
                          capture_output=True, text=True, timeout=timeout)


def graph_and_cores(path: str, tmp_path, label: str, workers: int
                    ) -> tuple[subprocess.CompletedProcess, str, str, dict]:
    """The file at `path` run through the graph (`run`, `workers` workers, a namespace of its
    own) and on the cores in this process: run's output, the graph's run directory, the cores'
    directory and the cores' summary as its JSON."""
    done = run_command(path, '--output', str(tmp_path / 'out'), '--namespace',
                       unique_namespace(label), '--workers', str(workers))
    assert done.returncode == 0, done.stderr
    run_dir = re.search(r'^results:\s+(\S+)', done.stdout, re.M).group(1)
    file = experiment_file.load(path)
    cores = str(tmp_path / 'cores')
    with LocalBackend() as backend, ResultsWriter(cores, file.text) as writer:
        expected = json.loads(Runner(file, [backend], writer).run().json_text())
    return done, run_dir, cores, expected


@pytest.fixture(scope='module')
def graph_runs(tmp_path_factory, private_ros_domain
               ) -> dict[str, tuple[str, str, subprocess.CompletedProcess]]:
    """The small file and a drop test (DROPS) in one `run`, the drop test beside the small
    file on its workers (filling what the small file leaves idle): per file id, its run
    directory, its recording and `run`'s output with that file's lines only."""
    out, logs = tmp_path_factory.mktemp('out'), tmp_path_factory.mktemp('logs')
    drops = out / 'drops.yaml'
    drops.write_text(DROPS)
    done = run_command(SMALL, str(drops), '--output', str(out), '--namespace', NS, '--logs',
                       str(logs), '--workers', str(WORKERS))
    node_logs = '\n'.join(f'== {p}\n{open(p).read()[-3000:]}' for p in glob.glob(f'{logs}/*'))
    assert done.returncode == 0, done.stderr + node_logs
    runs = {}
    for block in re.split(r'^(?=results:)', done.stdout, flags=re.M)[1:]:
        run_dir = re.search(r'^results:\s+(\S+)', block, re.M).group(1)
        recording = re.search(r'^recording:\s+(\S+)', block, re.M).group(1)
        runs[os.path.basename(run_dir).split('_')[0]] = (run_dir, recording, subprocess.
                                                         CompletedProcess(done.args, 0, block,
                                                                          done.stderr))
    assert set(runs) == {'small', 'drops'}, done.stdout
    return runs


@pytest.fixture(scope='module')
def graph_run(graph_runs):
    return graph_runs['small']


@pytest.fixture(scope='module')
def core_run(tmp_path_factory) -> str:
    """The small file run on the cores in this process: the results the graph must give."""
    directory = str(tmp_path_factory.mktemp('cores'))
    file = experiment_file.load(SMALL)
    with LocalBackend() as backend, ResultsWriter(directory, file.text) as writer:
        Runner(file, [backend], writer).run()
    return directory


def test_the_graph_gives_the_results_of_the_cores(graph_run, core_run):
    run_dir, _, done = graph_run
    assert 'best bin' in done.stdout and 'optimum' in done.stdout
    # the decisions end the output: one table, a row per option (option, verdict, the stage
    # that stops most parts) with its deciding reason below it, as the report's verdict table
    verdict_lines = done.stdout.split('verdicts:\n')[1].splitlines()
    assert verdict_lines[0].split() == ['option', 'verdict', 'stops', 'most', 'parts']
    table_rows, reasons = verdict_lines[1::2], verdict_lines[2::2]
    assert [line.split()[0] for line in table_rows] == ['static', 'vibrating', 'gripper']
    assert all(re.search(r'  (NOT FEASIBLE|FEASIBLE|UNDECIDED)  ', line) for line in table_rows)
    assert all(re.fullmatch(r'      \(.+\)', line) for line in reasons)
    # the cores decide the same
    expected = verdict_table([(v.option, v.verdict, v.stops, v.reasons[0]) for v in verdicts(
        summary_model.read(os.path.join(core_run, 'summary.json')))])
    assert table_rows == expected[1::2], (table_rows, expected)
    report = re.search(r'^report:\s+(\S+)', done.stdout, re.M).group(1)
    assert report == os.path.join(run_dir, 'report.html')
    for name in ('report.md', 'fig14_bins.png', 'fig15_table.png', 'bin.png', 'tray.png'):
        assert os.path.exists(os.path.join(run_dir, name)), name
    for name in FILES:
        assert rows(run_dir, name) == rows(core_run, name), name
    # what the run ran with, every default applied, written once at its start: the report's
    with open(os.path.join(run_dir, 'resolved.json'), encoding='utf-8') as f:
        ran = json.load(f)
    file = experiment_file.load(SMALL)
    assert ran['gripper'] == {'type': 'jaws', **{
        k.file_key: round(getattr(file.gripper, k.field) / k.factor, 6)
        for k in file.gripper.KEYS}}
    assert [a['name'] for a in ran['part']['aspects']] == [a.name for a in file.aspects]
    assert ran['tray']['hopper_lip_mm'] == file.tray.drop_height * 1000


def test_every_recorded_message_decodes_and_matches_the_results(graph_run):
    run_dir, recording, _ = graph_run
    with open(recording, 'rb') as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        messages = [(channel.topic, message.log_time, msg) for _, channel, message, msg
                    in reader.iter_decoded_messages(log_time_order=True)]
        attachments = {a.name: a.data for a in reader.iter_attachments()}
        channels = list(reader.get_summary().channels.values())
    # Every channel carries what its publishers offered, in rosbag2's format (read with a plain
    # YAML reader): the nodes' latched topics transient local, the streams volatile.
    latched = ('scene', 'markers', 'results', 'state', 'tf_static', 'verdicts')
    for c in channels:
        offers = yaml.safe_load(c.metadata['offered_qos_profiles'])
        want = 'transient_local' if c.topic.rsplit('/', 1)[-1] in latched else 'volatile'
        assert offers and {(o['reliability'], o['durability']) for o in offers} == {
            ('reliable', want)}, (c.topic, offers)
    tf_static = [msg for topic, _, msg in messages if topic == '/tf_static']
    tf = [msg for topic, _, msg in messages if topic == '/tf']
    by_topic: dict[str, list] = {}
    for topic, _, msg in messages:
        if topic not in ('/tf_static', '/tf'):
            by_topic.setdefault(topic[len(NS):], []).append(msg)
    workers = [f'/worker_{k}' for k in range(WORKERS)]
    assert set(by_topic) <= {'/progress', '/verdicts'} | {f'{w}/{t}' for w in workers for t in (
        'parts', 'scene', 'markers', 'settle_reports', 'results', 'feeder/state')}
    assert all(f'{w}/results' in by_topic for w in workers), 'a worker ran no iteration'
    iterations = rows(run_dir, 'iterations')
    assert sum(len(by_topic[f'{w}/scene']) for w in workers) == len(iterations)  # a reset each
    # /tf_static puts every instance frame of every scene in the world frame (RViz, Foxglove):
    # each scene's transforms as the scene gives them, in a message of its own.
    static = {(t.header.frame_id, t.child_frame_id, t.transform.translation.x,
               t.transform.translation.y, t.transform.translation.z)
              for m in tf_static for t in m.transforms}
    for w in workers:
        for scene in by_topic[f'{w}/scene']:
            for inst in scene.instances:
                assert inst.frame_id.startswith(f'{NS[1:]}{w}/instance_')
                assert (scene.header.frame_id, inst.frame_id, inst.transform.translation.x,
                        inst.transform.translation.y, inst.transform.translation.z) in static
    assert len(tf_static) == len(iterations)
    # /tf moves each part's frame, in which its markers are drawn (frame-locked), to its pose
    # in every parts message.
    poses = {(p.pose.header.frame_id, p.pose.header.frame_id.replace(
        f'instance_{p.instance}', f'part_{p.id}'), round(p.pose.pose.position.x, 9))
        for w in workers for m in by_topic[f'{w}/parts'] for p in m.parts}
    assert poses == {(t.header.frame_id, t.child_frame_id, round(t.transform.translation.x, 9))
                     for m in tf for t in m.transforms if t.child_frame_id.startswith(NS[1:])}
    for w in workers:
        drawn = [m for msg in by_topic[f'{w}/markers'] for m in msg.markers
                 if m.ns.startswith('part_')]
        assert drawn and all(m.frame_locked and m.header.frame_id == f'{NS[1:]}{w}/{m.ns}'
                             for m in drawn)
        # no more markers than parts messages, each drawing the parts of one of them
        shown = {frozenset(p.id for p in m.parts) for m in by_topic[f'{w}/parts']}
        assert len(by_topic[f'{w}/markers']) <= len(by_topic[f'{w}/parts'])
        assert all(frozenset(int(m.ns[5:]) for m in msg.markers if m.ns.startswith('part_'))
                   in shown for msg in by_topic[f'{w}/markers'])
    progress = by_topic['/progress'][-1]
    assert progress.iterations_done == progress.iterations_total == len(iterations)

    # Each worker's ValidityReports belong to the iteration of the scene it published last
    # (its instance seed names the iteration); per iteration, one report per check that had
    # parts to check, in order, with the same counts and, part by part, the same stage as
    # parts.csv.
    key_of_seed = {instance_seed(int(i['seed']), 0): (i['experiment'], i['group'],
                                                      i['iteration']) for i in iterations}
    reports: dict[tuple, list] = {}
    settles: dict[tuple, list] = {}
    for w in workers:
        key = None
        for topic, _, msg in messages:
            if topic == f'{NS}{w}/scene':
                key = key_of_seed[msg.instances[0].seed]
            elif topic == f'{NS}{w}/results':
                reports.setdefault(key, []).append(msg)
            elif topic == f'{NS}{w}/settle_reports':
                settles.setdefault(key, []).append(msg)
    # The physics health of each iteration is in the recording: its world reports give the
    # iteration's deepest penetration and its parts spilled and tunnelled.
    for i in iterations:
        got = settles[(i['experiment'], i['group'], i['iteration'])]
        assert max(r.max_penetration for r in got) == float(i['max_penetration'])
        assert max(r.max_speed for r in got) == float(i['max_speed'])
        assert len({t for r in got for t in r.tunnelled_ids}) == int(i['tunnelled'])
        assert len({t for r in got for t in r.thrown_ids}) == int(i['thrown'])
    checks: dict[tuple, list] = {}
    for c in rows(run_dir, 'checks'):
        if int(c['parts_on_table']):
            checks.setdefault((c['experiment'], c['group'], c['iteration']), []).append(c)
    assert set(reports) == set(checks)
    stages: dict[tuple, dict[int, int]] = {}
    for p in rows(run_dir, 'parts'):
        if p['inside'] == 'True':
            key = (p['experiment'], p['group'], p['iteration'], p['check'])
            stages.setdefault(key, {})[int(p['part_id'])] = int(p['stage'])
    for key, got in reports.items():
        assert [tuple(getattr(r, k) for k in STAGE_COUNTS) for r in got] == [
            tuple(int(c[k]) for k in STAGE_COUNTS) for c in checks[key]]
        for c, r in zip(checks[key], got, strict=True):
            assert {x.part_id: x.stage_reached for x in r.results} == stages[(*key, c['check'])]
    feeder = next(i for i in iterations if i['type'] == 'feeder_emptying')
    assert int(feeder['vibrations']) in [by_topic[f'{w}/feeder/state'][-1].vibrations
                                         for w in workers if f'{w}/feeder/state' in by_topic]

    with open(SMALL, 'rb') as f:
        assert attachments['experiment.yaml'] == f.read()
    for name in ('iterations.csv', 'checks.csv', 'parts.csv', 'picks.csv', 'summary.json'):
        with open(os.path.join(run_dir, name), 'rb') as f:
            assert attachments[name] == f.read(), name


def test_the_foxglove_layout_shows_recorded_topics_and_fields(graph_run):
    """The installed layout (for a run in the root namespace) names, in its 3D, plot and raw
    message panels, only topics the recording has, and fields their messages have."""
    _, recording, _ = graph_run
    share = get_package_share_directory('experiment_manager')
    with open(os.path.join(share, 'foxglove', 'pick_sim_layout.json'), encoding='utf-8') as f:
        layout = json.load(f)
    def any_worker(topic: str) -> str:      # which worker ran what varies from run to run
        return re.sub(r'/worker_\d+/', '/worker_k/', topic)

    with open(recording, 'rb') as f:
        last = {any_worker(channel.topic): msg for _, channel, _, msg in
                make_reader(f, decoder_factories=[DecoderFactory()]).iter_decoded_messages()}
    named = []                     # (topic, field or None)
    for panel in layout['configById'].values():
        named += [(t, None) for t in panel.get('topics', {})]
        named += [tuple(p['value'].split('.', 1)) for p in panel.get('paths', [])]
        if 'topicPath' in panel:
            named.append((panel['topicPath'], None))
    assert len(named) >= 6
    for topic, field in named:
        recorded = any_worker(f'{NS}{topic}')
        assert recorded in last, (topic, sorted(last))
        assert field is None or hasattr(last[recorded], field), (topic, field)
    assert layout['configById']['3D!scene']['followTf'] == 'world'
    assert '/tf_static' in last


def test_the_run_s_verdicts_are_published_recorded_and_printed(graph_run):
    """The decisions of the run: on the latched `verdicts` topic (recorded, once), as the
    report computes them from summary.json, and in run's last lines."""
    run_dir, recording, done = graph_run
    with open(recording, 'rb') as f:
        got = [msg for _, channel, _, msg in make_reader(
            f, decoder_factories=[DecoderFactory()]).iter_decoded_messages()
            if channel.topic == f'{NS}/verdicts']
    expected = verdicts(summary_model.read(os.path.join(run_dir, 'summary.json')))
    assert len(got) == 1 and got[0].run_directory == run_dir
    assert [(v.option, v.verdict, list(v.reasons), v.stops_most) for v in got[0].verdicts] == [
        (v.option, v.verdict, v.reasons, v.stops) for v in expected]
    assert {v.verdict for v in got[0].verdicts} <= {
        Verdict.FEASIBLE, Verdict.NOT_FEASIBLE, Verdict.UNDECIDED, Verdict.NOT_ANALYSED}
    printed = done.stdout[done.stdout.index('verdicts:\n'):].splitlines()[1:]
    assert printed == verdict_table([(v.option, v.verdict, v.stops, v.reasons[0])
                                     for v in expected])


SENSITIVITY = os.path.join(os.path.dirname(SMALL), 'sensitivity_experiment.yaml')


def test_a_sensitivity_run_through_the_graph_gives_the_cores_answers_and_records_them(
        tmp_path, private_ros_domain):
    """A feeder run repeated in 8 scenarios (the part's friction, the gripper, the table's
    moves) on two workers, each switched between scenarios as iterations reach it: the rows
    are the cores', and the sensitivity's summary is in summary.json, the report, the
    recording (an independent reader) and run's output."""
    done, run_dir, cores, expected = graph_and_cores(SENSITIVITY, tmp_path, 'sens', 2)
    for name in FILES:
        assert rows(run_dir, name) == rows(cores, name), name
    with open(os.path.join(run_dir, 'summary.json')) as f:
        summary = json.load(f)
    robust = summary['experiments']['robust']
    assert robust == expected['experiments']['robust'] and len(robust['scenarios']) == 8
    for r in robust['robustness']:
        assert f'    {r["line"]}' in done.stdout.splitlines()
    report = open(os.path.join(run_dir, 'report.md')).read()
    assert '## How far the answers move (`robust`)' in report
    assert os.path.exists(os.path.join(run_dir, 'sensitivity_robust.png'))
    recording = re.search(r'^recording:\s+(\S+)', done.stdout, re.M).group(1)
    with open(recording, 'rb') as f:
        attached = {a.name: a.data for a in make_reader(f).iter_attachments()}
    assert json.loads(attached['summary.json'])['experiments']['robust'] == robust


DROPS = """id: drops
seed: 3
part: {model: to220}
hopper_lip_mm: 30
experiments:
  - {id: drop, type: drop_test, iterations: 12, height_mm: 80,
     measured: {'+y': 5, '-y': 5, '+x': 1, '-x': 1}}
"""


def test_a_drop_test_beside_another_run_gives_the_cores_aspects(graph_runs, tmp_path):
    """A drop test on two workers, run beside the small file: the world drops each part from
    the plate's height (which reaches it in ContainerGeometry) and the rows, aspects and G-test
    are the cores'; its recording has its own iterations' scenes and frames only."""
    run_dir, recording, _ = graph_runs['drops']
    file = experiment_file.parse(DROPS)
    cores = str(tmp_path / 'cores')
    with LocalBackend() as backend, ResultsWriter(cores, file.text) as writer:
        expected = json.loads(Runner(file, [backend], writer).run().json_text())
    assert rows(run_dir, 'iterations') == rows(cores, 'iterations')
    with open(recording, 'rb') as f:
        messages = [(channel.topic, msg) for _, channel, _, msg in make_reader(
            f, decoder_factories=[DecoderFactory()]).iter_decoded_messages()]
    seeds = {instance_seed(int(i['seed']), 0) for i in rows(run_dir, 'iterations')}
    scenes = [m for topic, m in messages if topic.endswith('/scene')]
    assert len(scenes) == 12 and {m.instances[0].seed for m in scenes} == seeds
    assert len([m for topic, m in messages if topic == '/tf_static']) == 12
    assert {m.experiment_id for topic, m in messages if topic == f'{NS}/progress'} == {'drop'}
    with open(os.path.join(run_dir, 'summary.json')) as f:
        got = json.load(f)['experiments']['drop']
    assert got == expected['experiments']['drop'] and got['drops'] + got['other'] == 12
    assert '## Drop test (`drop`)' in open(os.path.join(run_dir, 'report.md')).read()


DOSED = """id: dosed
seed: 4
feeder_zone_mm: {center: [-60, 10], size: [40, 80]}
experiments:
  - {id: feeder, type: feeder_emptying, iterations: 1, parts: 30, optimal_range: [10, 20],
     max_feed: 5, max_vibrations: 60}
"""


def test_a_dosed_feed_onto_a_moved_zone_through_the_graph_gives_the_cores_rows(
        tmp_path, private_ros_domain):
    """The feeder zone (in the tray's ContainerGeometry) and the dose (in the feed_cycle
    goal) reach the nodes: the graph's rows are the cores', every feed at most 5 parts."""
    path = tmp_path / 'dosed.yaml'
    path.write_text(DOSED)
    _, run_dir, cores, _ = graph_and_cores(str(path), tmp_path, 'dosed', 1)
    assert rows(run_dir, 'iterations') == rows(cores, 'iterations')
    (row,) = rows(run_dir, 'iterations')
    assert int(row['feeds']) >= 30 // 5 and int(row['picks']) > 0


def start_replay(client, recording: str, name: str, rate: str) -> tuple[subprocess.Popen, list]:
    """`replay` of worker_0's results at `rate` under the prefix `name` (one per test: no test
    hears another's replay), and the list that receives what it publishes. The replay waits
    for this subscription to match (up to 60 s: discovery is slow on a loaded machine; with
    the 2 s default every message was lost there)."""
    prefix = unique_namespace(name)
    received: list = []
    client.node.create_subscription(ValidityReport, f'{prefix}{NS}/worker_0/results',
                                    received.append, 100)
    replay = subprocess.Popen([executable('experiment_manager', 'replay'), recording,
                               '--rate', rate, '--prefix', prefix, '--match-wait', '60',
                               '--topics', f'{NS}/worker_0/results'],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    return replay, received


def test_replay_republishes_a_topic_of_the_recording(graph_run, client):
    _, recording, _ = graph_run
    expected = sum(1 for _ in make_reader(open(recording, 'rb')).iter_messages(
        topics=[f'{NS}/worker_0/results']))
    replay, received = start_replay(client, recording, 'replay', '100')
    assert client.wait(lambda: len(received) == expected, 60.0), (
        f'{len(received)} of {expected}: {replay.communicate()[0]}')
    assert replay.wait(30) == 0
    info = subprocess.run([executable('experiment_manager', 'replay'), recording, '--info'],
                          capture_output=True, text=True, timeout=60)
    assert f'{NS}/worker_0/results' in info.stdout and 'attachment iterations.csv' in info.stdout


def test_replay_loops_and_publishes_the_recordings_clock(graph_run, client):
    _, recording, _ = graph_run
    topic = f'{NS}/worker_0/results'
    with open(recording, 'rb') as f:
        times = [m.log_time for _, _, m in make_reader(f).iter_messages(topics=[topic])]
    prefix = unique_namespace('replay_loop')
    received, clocks = [], []
    client.node.create_subscription(ValidityReport, f'{prefix}{topic}', received.append, 100)
    client.node.create_subscription(Clock, f'{prefix}/clock', clocks.append, QoSProfile(
        depth=100, reliability=ReliabilityPolicy.BEST_EFFORT))
    replay = subprocess.Popen([executable('experiment_manager', 'replay'), recording, '--rate',
                               '10', '--prefix', prefix, '--match-wait', '60', '--topics', topic,
                               '--loop', '--clock', '100'],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    def stamps() -> list[int]:
        return [c.clock.sec * 10**9 + c.clock.nanosec for c in clocks]

    def clock_went_back() -> bool:      # a pass after the first began
        return any(b < a for a, b in zip(stamps(), stamps()[1:], strict=False))
    try:
        assert client.wait(lambda: len(received) > len(times) and clock_went_back(), 120.0), (
            f'{len(received)} of more than {len(times)} messages; clock: {stamps()}')
        replay.send_signal(signal.SIGINT)
        output = replay.communicate(timeout=30)[0]
    finally:
        replay.kill()
    assert replay.returncode == 130, output
    # The clock tells the recording's time: never before its first message or after its last.
    assert times[0] <= min(stamps()) and max(stamps()) <= times[-1]


def test_replay_stopped_with_sigint_says_how_far_it_got(graph_run, client):
    _, recording, _ = graph_run
    replay, received = start_replay(client, recording, 'replay_stop', '0.1')
    try:
        assert client.wait(lambda: len(received) >= 1, 60.0), replay.communicate(timeout=30)[0]
        replay.send_signal(signal.SIGINT)
        output = replay.communicate(timeout=30)[0]
    finally:
        replay.kill()
    assert replay.returncode == 130, output
    assert 1 <= int(re.search(r'stopped after (\d+) messages', output).group(1)) < 10, output


def test_replay_says_when_no_subscriber_matched(graph_run):
    _, recording, _ = graph_run
    prefix = unique_namespace('replay_alone')      # nobody subscribes under this prefix
    done = subprocess.run([executable('experiment_manager', 'replay'), recording, '--rate',
                           '1000', '--prefix', prefix, '--match-wait', '0.2', '--topics',
                           f'{NS}/worker_0/results'], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert (f'replay: {prefix}{NS}/worker_0/results: no subscriber matched within 0.2 s '
            '(--match-wait); publishing anyway') in done.stderr


def test_a_bad_file_fails_before_any_node_starts(tmp_path):
    bad = tmp_path / 'bad.yaml'
    bad.write_text(open(SMALL).read().replace('max_vibrations: 15', 'max_vibrations: -3'))
    start = time.monotonic()
    done = run_command(str(bad), '--output', str(tmp_path), timeout=120)
    assert done.returncode == 2
    assert re.search(r'experiments\[3\]\.max_vibrations: -3 must be within \[1, ',
                     done.stderr), done.stderr
    assert time.monotonic() - start < 30 and 'node logs' not in done.stderr



def test_every_error_of_a_file_and_a_bad_option_are_named_as_given(tmp_path):
    bad = tmp_path / 'bad.yaml'
    bad.write_text(open(SMALL).read().replace('max_vibrations: 15', 'max_vibrations: -3')
                   .replace('seed:', 'sed:'))
    done = run_command(str(bad), '--output', str(tmp_path), timeout=120)
    assert done.returncode == 2
    assert 'run: 2 errors:' in done.stderr, done.stderr
    assert f'{bad}: sed: ' in done.stderr and 'did you mean seed?' in done.stderr
    assert re.search(r'experiments\[3\]\.max_vibrations: -3 must be within', done.stderr)
    done = run_command(SMALL, '--iterations', '-1', timeout=120)
    assert done.returncode == 2 and '--iterations -1 must be within [1, ' in done.stderr
    done = run_command(SMALL, '--at-once', '3', timeout=120)
    assert done.returncode == 2 and '--at-once 3 must be within [1, 2]' in done.stderr


def test_the_reduced_copies_of_iterations_are_removed(tmp_path):
    # --iterations writes a reduced copy of each file; a run that stops (here: on the second,
    # bad, file) leaves none behind.
    scratch = tmp_path / 'tmp'
    scratch.mkdir()
    bad = tmp_path / 'bad.yaml'
    bad.write_text(open(SMALL).read().replace('max_vibrations: 15', 'max_vibrations: -3'))
    done = subprocess.run([executable('experiment_manager', 'run'), SMALL, str(bad),
                           '--iterations', '1'], capture_output=True, text=True, timeout=120,
                          env={**os.environ, 'TMPDIR': str(scratch)})
    assert done.returncode == 2 and 'max_vibrations' in done.stderr, done.stderr
    assert list(scratch.iterdir()) == []

LONG = """id: long
seed: 3
experiments:
  - {id: sweep, type: table_sweep, iterations: 1, counts: {first: 5, last: 5}}
  - {id: feeder, type: feeder_emptying, iterations: 3, parts: 150, optimal_range: [20, 30],
     max_vibrations: 100000}
"""


def start_run(file, tmp_path, namespace: str, workers: int, *args: str,
              **popen) -> subprocess.Popen:
    """The `run` command in the background, into tmp_path/out, logs in tmp_path/logs."""
    return subprocess.Popen([executable('experiment_manager', 'run'), str(file), '--output',
                             str(tmp_path / 'out'), '--namespace', namespace, '--workers',
                             str(workers), '--logs', str(tmp_path / 'logs'), *args], **popen)


def first_iteration_done(out) -> Callable[[], bool]:
    def done() -> bool:
        found = glob.glob(f'{out}/*/iterations.csv')
        return bool(found) and len(open(found[0]).read().splitlines()) >= 2
    return done


@pytest.mark.parametrize('workers', [2, 1])
def test_a_killed_world_is_started_again_and_the_run_gives_the_same_results(
        tmp_path, client, core_run, private_ros_domain, workers):
    """The world of worker 0 is killed with SIGKILL mid-run; `run` starts it again. Its
    iteration runs again (on the other worker, or on it); with one worker the run can finish
    only if the manager takes the restarted world back."""
    ns = unique_namespace('exp_lose')
    run = start_run(SMALL, tmp_path, ns, workers, stdout=subprocess.PIPE,
                    stderr=subprocess.PIPE, text=True)
    try:
        assert client.wait(first_iteration_done(tmp_path / 'out'), 120.0), 'no iteration finished'
        os.kill(_world_pid(ns), signal.SIGKILL)
        stdout, stderr = run.communicate(timeout=600)
    finally:
        if run.poll() is None:
            run.kill()
    assert run.returncode == 0, stderr
    assert re.search(r'worker_0/world \(pid \d+\) was killed by signal 9', stderr), stderr
    assert 'worker_0/world started again (1 of 3)' in stderr
    if workers == 1:
        assert 'worker worker_0 was lost and came back' in open(
            tmp_path / 'logs' / 'experiment_manager.log').read()
    run_dir = re.search(r'^results:\s+(\S+)', stdout, re.M).group(1)
    for name in FILES:
        assert rows(run_dir, name) == rows(core_run, name), name


def _world_pid(namespace: str) -> int:
    return _pid(f'{namespace}/worker_0', 'lib/pick_sim_world/world')


def test_a_third_goal_or_second_run_is_refused_and_a_killed_last_worker_ends_the_runs(
        tmp_path, client, private_ros_domain):
    ns = unique_namespace('exp_kill')
    path = tmp_path / 'long.yaml'
    path.write_text(LONG)
    out = tmp_path / 'out'
    run = start_run(path, tmp_path, ns, 1, '--respawns', '0', stdout=subprocess.PIPE,
                    stderr=subprocess.PIPE, text=True)
    try:
        assert client.wait(first_iteration_done(out), 120.0), 'no iteration finished'

        manager = LockedActionClient(client.node, RunExperiment, f'{ns}/run_experiment')
        assert client.wait_for_servers(manager)
        # a second goal runs beside the first (RUNS_AT_ONCE), on what the first leaves idle
        # (into the run's output: the only directory `run` lets its manager write)
        beside = client.result(manager.send_goal_async(RunExperiment.Goal(
            experiment_file=str(path), output_dir=str(out))))
        assert beside.accepted
        assert client.wait(lambda: len(glob.glob(f'{out}/long_*/recording.mcap')) == 2,
                           60.0), 'the second goal did not begin its run'
        handle = client.result(manager.send_goal_async(RunExperiment.Goal(
            experiment_file=str(path), output_dir=str(tmp_path / 'other'))))
        busy = client.result(handle.get_result_async()).result
        assert busy.error_code == RunExperiment.Result.BUSY and 'not queued' in busy.error_msg
        # the second run waits for the one worker, which the first keeps while it has an
        # iteration ready: canceled, it ends now, not when the first has finished
        client.result(beside.cancel_goal_async())
        canceled = client.result(beside.get_result_async()).result
        assert canceled.error_code == RunExperiment.Result.CANCELED, canceled.error_msg
        first_dir = sorted(glob.glob(f'{out}/long_*'))[0]     # named by when they began
        assert not os.path.exists(os.path.join(first_dir, 'report.html')), \
            'the first run had finished: the cancel waited for it'
        # a second `run` in the namespace starts no node beside the running ones
        second = run_command(str(path), '--output', str(tmp_path / 'second'), '--namespace', ns,
                             '--workers', '1', timeout=120)
        assert second.returncode == 2, second.stderr
        assert re.search(rf"namespace '{ns}' of ROS domain \d+ is taken by `run` \(pid "
                         rf'{run.pid}\) on this host', second.stderr), second.stderr

        os.kill(_world_pid(ns), signal.SIGKILL)
        stdout, stderr = run.communicate(timeout=120)
    finally:
        if run.poll() is None:
            run.kill()
    assert run.returncode == 1, stderr
    assert re.search(r'world \(pid \d+\) was killed by signal 9', stderr), stderr
    assert 'finished iterations are kept in' in stderr
    run_dir, beside_dir = sorted(glob.glob(f'{out}/long_*'))    # named by when they began
    assert [r['experiment'] for r in rows(run_dir, 'iterations')][:1] == ['sweep']
    with open(os.path.join(run_dir, 'recording.mcap'), 'rb') as f:
        summary = make_reader(f).get_summary()     # closed properly: it has a summary
    assert summary is not None and summary.statistics.message_count > 0
    assert {a.name for a in summary.attachment_indexes} >= {'experiment.yaml', 'iterations.csv'}
    # the run beside it ended with the graph and closed its recording too
    with open(os.path.join(beside_dir, 'recording.mcap'), 'rb') as f:
        assert make_reader(f).get_summary() is not None
    assert not os.path.exists(tmp_path / 'other'), 'the busy goal wrote nothing'
    assert not os.path.exists(tmp_path / 'second'), 'the refused run wrote nothing'


def _pid(namespace: str, executable_path: str) -> int:
    found = subprocess.run(['pgrep', '-f', f'{executable_path} --ros-args -r __ns:={namespace}'],
                           capture_output=True, text=True)
    return int(found.stdout.split()[0])


def _interrupted(tmp_path, client, stop: Callable[[subprocess.Popen, str], None]
                 ) -> tuple[str, subprocess.CompletedProcess]:
    """Start `run` on the small file with one worker, let one iteration finish, call
    stop(run, namespace), then resume the run directory in a new graph. Returns the run
    directory and the resumed run's output."""
    ns = unique_namespace('exp_stop')
    run = start_run(SMALL, tmp_path, ns, 1, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                    text=True)
    try:
        assert client.wait(first_iteration_done(tmp_path / 'out'), 120.0), 'no iteration finished'
        stop(run, ns)
        run.communicate(timeout=120)
    finally:
        if run.poll() is None:
            run.kill()
    run_dir = glob.glob(f'{tmp_path}/out/small_*')[0]
    assert 1 <= len(rows(run_dir, 'iterations')) < 14
    resumed = run_command('--resume', run_dir, '--namespace', unique_namespace('exp_resume'),
                          '--logs', str(tmp_path / 'logs_resume'), '--workers', '2')
    assert resumed.returncode == 0, resumed.stderr
    return run_dir, resumed


@pytest.mark.parametrize('signum', [signal.SIGINT, signal.SIGTERM], ids=['SIGINT', 'SIGTERM'])
def test_a_stopped_run_closes_its_files_and_resumes_to_the_same_results(
        tmp_path, client, core_run, private_ros_domain, signum):
    def stop(run: subprocess.Popen, ns: str) -> None:
        run.send_signal(signum)
        assert run.wait(120) == 130, run.stderr.read()
    run_dir, _ = _interrupted(tmp_path, client, stop)
    with open(os.path.join(run_dir, 'recording.mcap'), 'rb') as f:
        summary = make_reader(f).get_summary()      # closed: it has a summary
    assert summary.statistics.message_count > 0
    assert {a.name for a in summary.attachment_indexes} >= {'experiment.yaml', 'iterations.csv'}
    assert os.path.exists(os.path.join(run_dir, 'recording_2.mcap'))   # the resumed part
    for name in FILES:
        assert rows(run_dir, name) == rows(core_run, name), name


@pytest.mark.parametrize('signum', [signal.SIGINT, signal.SIGTERM], ids=['SIGINT', 'SIGTERM'])
def test_a_signal_stops_run_between_two_callbacks_never_inside_one(private_ros_domain, signum):
    """`run`'s handler (`interrupt`) only sets a flag; its spin loop raises KeyboardInterrupt
    after the callback in progress returns. Raised inside rclpy's executor (the progress
    feedback runs as each iteration ends, which is when a user or a test stops a run), it left
    the callback half run and `run` once exited with 1 instead of 130."""
    saved = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)     # as cli.main does
    node = rclpy.create_node('signal_test', namespace=unique_namespace('exp_signal'))
    events = []

    def tick():
        events.append('start')
        if len(events) == 1:
            os.kill(os.getpid(), signum)    # delivered before the next bytecode here
        events.append('end')
    try:
        interrupt.install()                 # as cli.main does
        node.create_timer(0.01, tick)
        with pytest.raises(KeyboardInterrupt):
            supervisor.spin_until(node, lambda: False, [], 10.0)
        assert events == ['start', 'end']
        assert supervisor.spin_until(node, lambda: len(events) == 4, [], 10.0) is None
        assert events == ['start', 'end'] * 2, 'a second spin loop runs on (the flag is reset)'
    finally:
        for s, handler in saved.items():
            signal.signal(s, handler)
        node.destroy_node()
        rclpy.try_shutdown()


def test_a_killed_manager_s_recording_is_recovered_and_its_run_resumed(
        tmp_path, client, core_run, private_ros_domain):
    def kill_manager(run: subprocess.Popen, ns: str) -> None:
        os.kill(_pid(ns, 'lib/experiment_manager/experiment_manager'), signal.SIGKILL)
        assert run.wait(120) == 1
    run_dir, _ = _interrupted(tmp_path, client, kill_manager)
    cut = os.path.join(run_dir, 'recording.mcap')
    info = subprocess.run([executable('experiment_manager', 'replay'), cut, '--info'],
                          capture_output=True, text=True, timeout=60)
    assert info.returncode == 2 and f'replay {cut} --recover OUT.mcap' in info.stderr
    out = str(tmp_path / 'recovered.mcap')
    done = subprocess.run([executable('experiment_manager', 'replay'), cut, '--recover', out],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    messages = int(re.search(r'(\d+) messages', done.stderr).group(1))
    with open(out, 'rb') as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        assert reader.get_summary().statistics.message_count == messages > 0
        assert sum(1 for _ in reader.iter_decoded_messages()) == messages
        assert 'experiment.yaml' in {a.name for a in reader.iter_attachments()}
    for name in FILES:
        assert rows(run_dir, name) == rows(core_run, name), name


def test_a_run_killed_with_sigkill_leaves_no_node_behind(tmp_path, client, private_ros_domain):
    ns = unique_namespace('exp_orphans')

    def nodes() -> list[str]:
        return subprocess.run(['pgrep', '-f', f'__ns:={ns}'], capture_output=True,
                              text=True).stdout.split()
    run = start_run(SMALL, tmp_path, ns, 1, stdout=subprocess.DEVNULL,
                    stderr=subprocess.DEVNULL)
    try:
        assert client.wait(first_iteration_done(tmp_path / 'out'), 120.0), 'no iteration finished'
        assert len(nodes()) == 4        # world, validity, feeder_controller, the manager
    finally:
        run.kill()
        run.wait()
    assert client.wait(lambda: not nodes(), 30.0), f'left running: {nodes()}'


TINY = """id: tiny
seed: 5
experiments:
  - {id: bins, type: bin_static, iterations: 2, parts: 20, bins_mm: [[100, 100, 30]]}
"""


def test_the_manager_finds_the_workers_under_its_namespace(tmp_path, client, start_node):
    """`ros2 run` style: two workers in sub-namespaces and a manager with its defaults; a
    namespace with a validity node alone is not a worker. The manager is named as launch
    names a node (`-r __node:=`), which must not rename its recorder node too."""
    ns = unique_namespace('exp_find')
    nodes = [start_node(pkg, exe, '-r', f'__ns:={ns}/{w}') for w in ('cell_a', 'cell_b')
             for pkg, exe in WORKER_NODES]
    nodes.append(start_node('pick_validity', 'validity', '-r', f'__ns:={ns}/lone'))
    manager = start_node('experiment_manager', 'experiment_manager', '-r', f'__ns:={ns}', '-r',
                         '__node:=experiment_manager', '-p', f'experiment_dirs:=["{tmp_path}"]',
                         '-p', f'output_dirs:=["{tmp_path}"]')
    path = tmp_path / 'tiny.yaml'
    path.write_text(TINY)
    action = LockedActionClient(client.node, RunExperiment, f'{ns}/run_experiment')
    assert client.wait_for_servers(action, nodes=(manager,))
    def manager_nodes() -> list[str]:
        return sorted(n for n, s in client.node.get_node_names_and_namespaces() if s == ns)
    assert client.wait(lambda: len(manager_nodes()) == 2, 60.0, nodes=(manager,))
    assert manager_nodes() == ['experiment_manager', 'experiment_manager_recorder']
    # Discovery takes the workers there at the start of the run: wait until both are up.
    def workers_up() -> bool:
        names = {n for n, _ in client.node.get_service_names_and_types()}
        return all({f'{ns}/{w}/reset_scene', f'{ns}/{w}/check_parts',
                    f'{ns}/{w}/feed_cycle/_action/send_goal'} <= names
                   for w in ('cell_a', 'cell_b'))
    assert client.wait(workers_up, 60.0, nodes=tuple(nodes))
    handle = client.result(action.send_goal_async(RunExperiment.Goal(
        experiment_file=str(path), output_dir=str(tmp_path / 'out'))))
    result = client.result(handle.get_result_async(), 300.0).result
    assert result.error_code == 0, result.error_msg
    assert len(rows(result.results_path, 'iterations')) == 2
    assert 'on 2 worker(s): cell_a, cell_b' in manager.output()
