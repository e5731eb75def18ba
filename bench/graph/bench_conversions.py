"""What the world node's messages cost to build and serialise after each operation.

The world publishes `parts` and the parts' frames on `/tf` after every drop, vibration and
removal (a feeder run of the paper's test case makes about 600 of them), `markers` when the
parts change (they were published after each operation too). For capacitors settled on the tray
(30) and in a 300 x 300 x 26 mm bin (480), prints the median time to build each message from a
snapshot and to serialise it, and the markers' and the frames' totals as multiples of the parts
message's (same run).

    tools/ws python -m bench.graph.bench_conversions [--repeat 30] [--part-file FILE [--count 8]]

--part-file FILE: instead, `--count` parts of the experiment file's part (a board's part file,
a CAD model whose collision pieces are hulls of thousands of points) settled on the tray; the
markers are built with the part's shapes kept (as the world node builds them after its first
operation) and built anew each call (as it did before), and the parts' frames, in one run.
"""

import argparse
from functools import partial
import statistics
import time

from builtin_interfaces.msg import Time
from experiment_manager.experiment_file.loading import part_of
from pick_common import conversions as common
from pick_common.containers import ContainerSpec
from pick_common.specs import SceneSpec
from pick_sim_world import conversions as conv
from pick_sim_world.world import World
from rclpy.serialization import serialize_message

SCENES = {'30 capacitors on the tray': (ContainerSpec.tray(), 30),
          '480 capacitors in a 300 x 300 x 26 mm bin':
              (ContainerSpec(inner_size=(0.3, 0.3, 0.026)), 480)}


def median_ms(function, repeat: int) -> tuple[float, object]:
    times, result = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - start)
    return statistics.median(times) * 1000.0, result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--repeat', type=int, default=30)
    parser.add_argument('--part-file', metavar='FILE')
    parser.add_argument('--count', type=int, default=8)
    args = parser.parse_args()
    stamp = Time(sec=1)
    if args.part_file:
        part_markers(args, stamp)
        return
    for name, (container, count) in SCENES.items():
        with World(SceneSpec(container, seed=1)) as world:
            world.drop(count)
            states = world.snapshot()
            totals = {}
            for kind, build in (
                    ('parts', partial(common.states_to_msg, states, stamp, 'world', 'w/')),
                    ('markers', partial(conv.markers_msg, world, states, stamp, 'w/')),
                    ('tf', partial(conv.parts_tf_msg, states, stamp, 'w/'))):
                build_ms, msg = median_ms(build, args.repeat)
                serialize_ms, data = median_ms(partial(serialize_message, msg), args.repeat)
                totals[kind] = build_ms + serialize_ms
                print(f'{name}: {kind:<8} build {build_ms:7.2f} ms, serialise '
                      f'{serialize_ms:6.2f} ms, {len(data):8d} bytes')
            print(f'{name}: markers cost {totals["markers"] / totals["parts"]:.2f} x the parts '
                  f'message, the frames {totals["tf"] / totals["parts"]:.2f} x')


def part_markers(args: argparse.Namespace, stamp: Time) -> None:
    """The markers of `--count` parts of the file's part on the tray, shapes kept and anew."""
    with World(SceneSpec(ContainerSpec.tray(), part_of(args.part_file), seed=1)) as world:
        world.drop(args.count)
        states = world.snapshot()
        points = None

        def anew():
            conv._shapes_of = ((), [])
            return conv.markers_msg(world, states, stamp, 'w/')

        for label, build in (('shapes kept', partial(conv.markers_msg, world, states, stamp,
                                                      'w/')), ('built anew', anew)):
            build_ms, msg = median_ms(build, args.repeat)
            serialize_ms, data = median_ms(partial(serialize_message, msg), args.repeat)
            points = sum(len(m.points) for m in msg.markers)
            print(f'{args.count} parts, markers {label:<11}: build {build_ms:7.2f} ms, '
                  f'serialise {serialize_ms:6.2f} ms, {len(data):8d} bytes')
        print(f'{points} points in all')
        build_ms, msg = median_ms(partial(conv.parts_tf_msg, states, stamp, 'w/'), args.repeat)
        serialize_ms, data = median_ms(partial(serialize_message, msg), args.repeat)
        print(f'{args.count} parts, frames on /tf     : build {build_ms:7.2f} ms, '
              f'serialise {serialize_ms:6.2f} ms, {len(data):8d} bytes')


if __name__ == '__main__':
    main()
