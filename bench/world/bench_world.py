"""World benchmarks: print figures, with ratios against baselines measured in the same run.

    make bench            (or: tools/ws python -m bench.world.bench_world [--seeds 3])

1. 480 radial capacitors (body 5 x 11 mm) dropped into a 300 x 300 x 26 mm bin: wall time to
   settle, simulated time, parts escaped; against pybullet's defaults (50 solver iterations,
   warm start 0.1, 20 mm contact-breaking threshold) on the same drop, capped at the same
   simulated time.
2. 50 capacitors on the 195 x 150 x 27 mm tray: the same figures, and one vibration.
3. The world node (a process, driven over DDS) against the pure core for the same drop.
4. The 480-capacitor drop simulated in centimetres (today's world) against the same drop in
   metres (the world before: length_unit 1 and its contact-breaking factor 0.001), the same
   seeds: wall time, and what the physics did (the deepest overlap, the lowest part).

The process is pinned to one core: PyBullet steps on one thread. Timings on a shared machine
vary by 10-20 %: compare ratios, not single figures.
"""

import argparse
import os
import resource
import statistics
import sys
import time

import numpy as np
from pick_common.containers import ContainerSpec
from pick_common.rclpy_adapter import LockedActionClient
from pick_common.specs import MOVES, SceneSpec
from pick_msgs.action import DropParts
from pick_msgs.srv import ResetScene
from pick_sim_world.config import PhysicsConfig
from pick_sim_world.world import World

BIN = ContainerSpec(inner_size=(0.3, 0.3, 0.026))
TRAY = ContainerSpec.tray()
PYBULLET_DEFAULTS = dict(solver_iterations=50, warm_starting_factor=0.1,
                         contact_breaking_threshold=0.02)
METRES = dict(length_unit=1.0, contact_breaking_threshold=0.001)   # the world before


def drop(container: ContainerSpec, count: int, seed: int, physics: PhysicsConfig,
         vibrate: bool = False) -> dict:
    with World(SceneSpec(container, seed=seed), physics) as world:
        start = time.perf_counter()
        _, report = world.drop(count)
        out = dict(wall=time.perf_counter() - start, sim=report.sim_time, steps=report.steps,
                   settled=report.settled, escaped=len(report.escaped_ids),
                   overlap=report.max_penetration,
                   lowest=float(world.snapshot().poses[:, 2].min()))
        if vibrate:
            start = time.perf_counter()
            vib = world.vibrate(MOVES['spread'])
            out.update(vib_wall=time.perf_counter() - start, vib_sim=vib.sim_time,
                       vib_escaped=len(vib.escaped_ids), vib_settled=vib.settled)
    return out


def row(label: str, runs: list[dict]) -> None:
    wall = [r['wall'] for r in runs]
    sim = [r['sim'] for r in runs]
    ms = [1000 * r['wall'] / r['steps'] for r in runs]
    print(f'{label:<44} wall {statistics.median(wall):6.2f} s (max {max(wall):5.2f})  '
          f'sim {statistics.median(sim):5.2f} s  {statistics.median(ms):5.2f} ms/step  '
          f'settled {sum(r["settled"] for r in runs)}/{len(runs)}  '
          f'escaped {sum(r["escaped"] for r in runs)}')


def bench_bin(seeds: list[int], iterations: int) -> None:
    print('\n== 480 radial capacitors into a 300 x 300 x 26 mm bin')
    ours = [drop(BIN, 480, s, PhysicsConfig(solver_iterations=iterations)) for s in seeds]
    row(f'ours ({iterations} iterations, warm start 0.85, threshold 0.02)', ours)
    cap = max(r['sim'] for r in ours)
    base = [drop(BIN, 480, s, PhysicsConfig(max_settle_time=cap, **PYBULLET_DEFAULTS))
            for s in seeds]
    row(f'pybullet defaults, capped at {cap:.2f} s sim', base)
    per_step = statistics.median(1000 * r['wall'] / r['steps'] for r in ours)
    per_step_base = statistics.median(1000 * r['wall'] / r['steps'] for r in base)
    print(f'speed-up per step vs pybullet defaults: {per_step_base / per_step:.2f}x; '
          f'target: the bin settled in <= 5 s wall -> '
          f'{"met" if max(r["wall"] for r in ours) <= 5.0 else "NOT met"} '
          f'(worst {max(r["wall"] for r in ours):.2f} s)')


def bench_scale(seeds: list[int]) -> None:
    print('\n== 480 radial capacitors into the 300 x 300 x 26 mm bin: centimetres against '
          'metres')
    runs = {'centimetres (today)': [drop(BIN, 480, s, PhysicsConfig()) for s in seeds],
            'metres (before)': [drop(BIN, 480, s, PhysicsConfig(**METRES)) for s in seeds]}
    for label, got in runs.items():
        row(label, got)
        print(f'{"":<44} deepest overlap {1000 * max(r["overlap"] for r in got):.3f} mm, '
              f'lowest part centre {1000 * min(r["lowest"] for r in got):.2f} mm')
    now, before = (statistics.median(r['wall'] for r in g) for g in runs.values())
    print(f'wall time, centimetres / metres: {now / before:.2f}')


def bench_tray(seeds: list[int]) -> None:
    print('\n== 50 radial capacitors onto the 195 x 150 x 27 mm tray, then one vibration')
    runs = [drop(TRAY, 50, s, PhysicsConfig(), vibrate=True) for s in seeds]
    row('drop and settle', runs)
    print(f'{"one default vibration, then settle":<44} '
          f'wall {statistics.median(r["vib_wall"] for r in runs):6.2f} s  '
          f'sim {statistics.median(r["vib_sim"] for r in runs):5.2f} s  '
          f'settled {sum(r["vib_settled"] for r in runs)}/{len(runs)}  '
          f'escaped {sum(r["vib_escaped"] for r in runs)}')


def bench_node(count: int, seed: int) -> None:
    """Same drop through the node (goal to result, over DDS) and in the core."""
    # The node-process and client helpers of the graph tests.
    sys.path.insert(0, os.path.join(os.path.dirname(__file__), '..', '..', 'tests'))
    from graph import Client, NodeProcess, unique_namespace

    print(f'\n== the world node against the pure core: {count} capacitors into the bin, '
          f'seed {seed}')
    os.environ.setdefault('ROS_DOMAIN_ID', str(150 + os.getpid() % 50))
    os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
    core = drop(BIN, count, seed, PhysicsConfig())
    ns = unique_namespace('bench')
    proc = NodeProcess('pick_sim_world', 'world', ['-p', f'seed:={seed}',
                                                   '-r', f'__ns:={ns}'])
    client = Client()
    try:
        action = LockedActionClient(client.node, DropParts, f'{ns}/drop_parts')
        reset = client.node.create_client(ResetScene, f'{ns}/reset_scene')
        assert client.wait(lambda: action.server_is_ready() and reset.service_is_ready(), 60)
        walls = {}
        for markers in (True, False):
            client.result(reset.call_async(ResetScene.Request(keep_scene=True, seed=seed)))
            if not markers:
                # the same drop without the marker message, to show what it costs
                proc.stop()
                proc = NodeProcess('pick_sim_world', 'world', [
                    '-p', f'seed:={seed}', '-p', 'publish_markers:=false', '-r', f'__ns:={ns}'])
                action = LockedActionClient(client.node, DropParts, f'{ns}/drop_parts')
                assert client.wait(action.server_is_ready, 60)
            start = time.perf_counter()
            handle = client.result(action.send_goal_async(DropParts.Goal(count=count)))
            result = client.result(handle.get_result_async(), 300).result
            walls[markers] = time.perf_counter() - start
            assert result.error_code == 0, result.error_msg
            assert result.settle.sim_time == core['sim'], 'the node must run the same drop'
        print(f'core    wall {core["wall"]:6.2f} s  sim {core["sim"]:.2f} s')
        for markers, wall in walls.items():
            label = 'node, markers on ' if markers else 'node, markers off'
            print(f'{label} wall {wall:6.2f} s  ratio node/core {wall / core["wall"]:.3f}')
    finally:
        client.close()
        proc.stop()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--seeds', type=int, default=3, help='drops per figure')
    parser.add_argument('--iterations', type=int, default=PhysicsConfig().solver_iterations,
                        help='solver iterations of the tuned bin drop')
    parser.add_argument('--skip-node', action='store_true')
    parser.add_argument('--only-scale', action='store_true',
                        help='only the centimetres-against-metres drop (4)')
    args = parser.parse_args()
    os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})
    seeds = list(range(args.seeds))
    print(f'pinned to core {sorted(os.sched_getaffinity(0))}; numpy {np.__version__}')
    if args.only_scale:
        bench_scale(seeds)
        return
    bench_bin(seeds, args.iterations)
    bench_scale(seeds)
    bench_tray(seeds)
    if not args.skip_node:
        bench_node(480, 0)
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f'\npeak resident memory of this process: {rss:.0f} MiB')


if __name__ == '__main__':
    main()
