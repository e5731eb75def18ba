"""What fitting the tray's delivered motion at every settle check of a vibration costs.

`TrayDrive.motion` fits a sinusoid to every step of the vibration so far. The world fitted it at
each settle check for the progress it hands its caller; the world node sends one check's
progress in many (at most one every FEEDBACK_PERIOD of wall time), and now the fit is made only
when a reader reads `Progress.tray`. In one run, `--vibrations` vibrations of `--count` parts on
the tray, each with a reader that reads the tray's motion at every check (what the world paid
before) and one that reads it at most every FEEDBACK_PERIOD (what the world node reads): CPU
time, fits made and their CPU time, and whether the parts' poses and the reports' motion agree.

    tools/ws python -m bench.world.bench_tray_fit [--part-file FILE] [--count 8] [--vibrations 200]
"""

import argparse
import hashlib
import time

from experiment_manager.experiment_file.loading import part_of
from pick_common.containers import ContainerSpec
from pick_common.parts.spec import PartSpec
from pick_common.specs import SceneSpec, Vibration
from pick_sim_world import tray
from pick_sim_world.world import World
from pick_sim_world.world_node import FEEDBACK_PERIOD


def run(part: PartSpec, count: int, vibrations: int, period: float) -> tuple:
    """CPU s, fits, their CPU s, a digest of the final poses and the reports' motions."""
    fits = [0, 0.0]
    fit = tray.TrayDrive.motion

    def counted(drive):
        start = time.process_time()
        try:
            return fit(drive)
        finally:
            fits[0] += 1
            fits[1] += time.process_time() - start

    tray.TrayDrive.motion = counted
    last, read = [None], []

    def progress(p) -> bool:
        now = time.monotonic()
        if last[0] is None or now - last[0] >= period:
            last[0] = now
            read.append(p.tray)
        return True

    try:
        with World(SceneSpec(ContainerSpec.tray(), part, seed=3)) as world:
            world.drop(count)
            fits[:] = [0, 0.0]
            start = time.process_time()
            motions = [world.vibrate(Vibration(), progress=progress).tray
                       for _ in range(vibrations)]
            cpu = time.process_time() - start
            poses = hashlib.sha256(world.snapshot().poses.tobytes()).hexdigest()[:12]
    finally:
        tray.TrayDrive.motion = fit
    return cpu, fits[0], fits[1], poses, motions


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--part-file', metavar='FILE')
    parser.add_argument('--count', type=int, default=8)
    parser.add_argument('--vibrations', type=int, default=200)
    args = parser.parse_args()
    part = part_of(args.part_file) if args.part_file else PartSpec()
    results = {}
    for label, period in (('read at every check', 0.0),
                          (f'read at most every {FEEDBACK_PERIOD:g} s', FEEDBACK_PERIOD)):
        cpu, fits, fit_cpu, poses, motions = results[label] = run(part, args.count,
                                                                  args.vibrations, period)
        print(f'{label:<28}: {cpu:6.2f} s of CPU, {fits:5d} fits in {fit_cpu:5.2f} s, '
              f'poses {poses}', flush=True)
    every, throttled = results.values()
    print(f'CPU ratio {every[0] / throttled[0]:.3f}; the same poses and motions: '
          f'{every[3] == throttled[3] and every[4] == throttled[4]}')


if __name__ == '__main__':
    main()
