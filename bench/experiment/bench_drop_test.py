"""How long a drop test takes: 400 drops of a 480-triangle mesh part (a 120-sided cylinder,
10 mm across and long) from 100 mm, run on the cores the way `run` runs it, on one worker and
on two; beside it, as the baseline in the same run, the same 400 parts poured at once into one
bin (a bin_static iteration: one pile instead of 400 single drops). Target: at most 2 minutes
on 2 cores.

    tools/ws python -m bench.experiment.bench_drop_test [--drops 400]

Prints each run's wall time, drops per second and the ratio to the baseline and the target.
"""

import argparse
import os
import tempfile
import time

from experiment_manager import experiment_file
from experiment_manager.analysis.results import ResultsWriter
from experiment_manager.running.local_backend import LocalBackend
from experiment_manager.running.scheduler import Runner
import trimesh

TARGET_S = 120.0


def _file(directory: str, experiment: str) -> experiment_file.ExperimentFile:
    mesh = trimesh.creation.cylinder(radius=0.005, height=0.01, sections=120)
    path = os.path.join(directory, 'part.stl')
    mesh.export(path)
    text = f"""id: bench_drops
seed: 1
part:
  model: mesh
  mesh: {path}
  units: m
  mass_g: 2
  place: {{axis: [0, 0, -1], seat_offset_mm: 5}}
  grasps: [{{name: across, up_axis: [1, 0, 0], closing_axis: [0, 1, 0], jaw_opening_mm: 14}}]
experiments:
  - {experiment}
"""
    return experiment_file.parse(text, os.path.join(directory, 'bench.yaml'))


def timed(file: experiment_file.ExperimentFile, workers: int) -> float:
    with tempfile.TemporaryDirectory() as out:
        backends = [LocalBackend() for _ in range(workers)]
        start = time.perf_counter()
        try:
            with ResultsWriter(out, file.text) as writer:
                Runner(file, backends, writer).run()
        finally:
            for b in backends:
                b.close()
        return time.perf_counter() - start


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--drops', type=int, default=400)
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        drops = _file(tmp, f'{{id: drops, type: drop_test, iterations: {args.drops}, '
                           'height_mm: 100}')
        pile = _file(tmp, f'{{id: pile, type: bin_static, iterations: 1, parts: {args.drops}, '
                          'bins_mm: [[250, 250, 60]]}')
        triangles = len(trimesh.load(os.path.join(tmp, 'part.stl')).faces)
        base = timed(pile, 1)
        print(f'part: {triangles} triangles; baseline, {args.drops} parts poured into one bin: '
              f'{base:.1f} s')
        for workers in (1, 2):
            wall = timed(drops, workers)
            print(f'{args.drops} drops on {workers} worker(s): {wall:.1f} s, '
                  f'{args.drops / wall:.1f} drops/s, {wall / base:.2f} x the pile, '
                  f'{wall / TARGET_S:.2f} x the 2-minute target')


if __name__ == '__main__':
    main()
