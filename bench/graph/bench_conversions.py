"""What the world node's messages cost to build and serialise after each operation.

The world publishes `parts` and `markers` after every drop, vibration and removal (a feeder run
of the paper's test case makes about 600 of them). For capacitors settled on the tray (30) and
in a 300 x 300 x 26 mm bin (480), prints the median time to build each message from a snapshot
and to serialise it, and the markers' total as a multiple of the parts message's (same run).

    tools/ws python -m bench.graph.bench_conversions [--repeat 30]
"""

import argparse
from functools import partial
import statistics
import time

from builtin_interfaces.msg import Time
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
    args = parser.parse_args()
    stamp = Time(sec=1)
    for name, (container, count) in SCENES.items():
        with World(SceneSpec(container, seed=1)) as world:
            world.drop(count)
            states = world.snapshot()
            totals = {}
            for kind, build in (
                    ('parts', partial(common.states_to_msg, states, stamp, 'world', 'w/')),
                    ('markers', partial(conv.markers_msg, world, states, stamp, 'w/'))):
                build_ms, msg = median_ms(build, args.repeat)
                serialize_ms, data = median_ms(partial(serialize_message, msg), args.repeat)
                totals[kind] = build_ms + serialize_ms
                print(f'{name}: {kind:<8} build {build_ms:7.2f} ms, serialise '
                      f'{serialize_ms:6.2f} ms, {len(data):8d} bytes')
            print(f'{name}: markers cost {totals["markers"] / totals["parts"]:.2f} x the parts '
                  'message')


if __name__ == '__main__':
    main()
