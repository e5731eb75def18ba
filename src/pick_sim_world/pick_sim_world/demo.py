"""`pick_world_demo`: drop parts into a bin and onto the vibrating tray and print a summary.

The README's run command runs this until the experiment manager exists. It uses the pure core
(no ROS graph): a 480-capacitor bin fill, then 50 capacitors on the tray, one vibration, one
feed and one removal, with the figures a user checks first (settle times, parts escaped).
"""

import argparse
import sys
import time

import numpy as np

from .config import SceneSpec, Vibration
from .containers import ContainerSpec
from .errors import WorldError
from .parts import BUILTIN_MODELS, PartSpec
from .world import quaternion_angles, SettleReport, World


def _line(label: str, report: SettleReport, parts: int) -> str:
    state = 'settled' if report.settled else f'NOT settled ({len(report.unsettled_ids)} moving)'
    return (f'{label:<34} {parts:>4} parts  {state:<8}  sim {report.sim_time:5.2f} s  '
            f'wall {report.wall_time:5.2f} s  escaped {len(report.escaped_ids)}')


def run(model: str, bin_parts: int, tray_parts: int, seed: int) -> int:
    part = PartSpec(model=model)
    print(f'part model {model}: {BUILTIN_MODELS[model][2]}')
    bin_spec = ContainerSpec(inner_size=(0.3, 0.3, 0.026))
    with World(SceneSpec(bin_spec, part, 1, seed)) as world:
        start = time.perf_counter()
        _, report = world.drop(bin_parts)
        print(_line('bin 300 x 300 x 26 mm: drop', report, bin_parts))
        print(f'{"":<34} total wall time with spawning {time.perf_counter() - start:.2f} s')
        escaped = len(report.escaped_ids)
    with World(SceneSpec(ContainerSpec.tray(), part, 1, seed)) as world:
        ids, report = world.drop(tray_parts)
        print(_line('tray 195 x 150 x 27 mm: drop', report, tray_parts))
        before = world.snapshot()
        report = world.vibrate(Vibration())
        after = world.snapshot()
        moved = np.linalg.norm(after.poses[:, :3] - before.poses[:, :3], axis=1)
        flipped = quaternion_angles(after.poses[:, 3:], before.poses[:, 3:]) > np.pi / 2
        print(_line('tray: vibrate 1 s at 30 Hz', report, tray_parts))
        print(f'{"":<34} median move {np.median(moved) * 1000:.1f} mm, '
              f'{int(flipped.sum())} parts turned over 90 deg')
        _, report = world.drop(10, zone='feeder')
        print(_line('tray: feed 10 parts', report, len(world.snapshot().ids)))
        _, report = world.remove(ids[:5])
        print(_line('tray: remove 5 parts', report, len(world.snapshot().ids)))
        escaped += len(report.escaped_ids)
    return 0 if escaped == 0 else 1


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--model', default='radial_capacitor', choices=sorted(BUILTIN_MODELS))
    parser.add_argument('--bin-parts', type=int, default=480)
    parser.add_argument('--tray-parts', type=int, default=50)
    parser.add_argument('--seed', type=int, default=0)
    args = parser.parse_args(argv)
    try:
        sys.exit(run(args.model, args.bin_parts, args.tray_parts, args.seed))
    except WorldError as exc:
        print(f'pick_world_demo: {exc}', file=sys.stderr)
        sys.exit(2)


if __name__ == '__main__':
    main()
