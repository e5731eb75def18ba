"""Where fed parts land on the tray: per feed, how many the hopper let out of the dose, how
high the pile stands and how many parts reach over a wall's top, with the spills of each feeder
run, for a hopper (its lip, rate and exit speed) and a feeder zone (the test case's, or one set
back from the -X wall).

    tools/ws python -m studies.feeder_landing [--part pth1.yaml] [--runs 4] [--parts 480]
        [--range 45,55] [--lip-mm 30] [--rate 10] [--speed-mm-s 100] [--set-back-mm 0]
        [--max-feed N] [--moves spread,forward] [--wall-mm 27] [--output DIR]

Runs `--runs` seeded feeder_emptying runs of the test case's part file on the cores at the
optimal range given, the tray's feeder zone moved `--set-back-mm` away from the -X wall (its far
edge kept: the file key feeder_zone_mm), and with `--max-feed` a hopper that doses at most N
parts a feed (the feeder_emptying key max_feed), with `--moves` another vibration cycle (named
moves), with `--wall-mm` other walls, and the hopper's `--lip-mm`, `--rate` (parts/s) and
`--speed-mm-s` (file keys hopper_lip_mm, hopper_rate, hopper_speed_mm_s). The tray is measured
after every feed, before the vibration that follows it; printed, over all feeds: the parts
let out against the doses asked, the pile's top (the highest point of any
part on the tray: median, 90th percentile, highest), the feeds after which a part stood higher
than the walls, the parts that then reached over a wall's inner face higher than its top
(resting on or against its top), and per run the parts spilled (outside the tray, not through
it), and the feeder's verdict as the run's summary decides it (kept in `--output`, a run
directory `decide` reads). Parts' points are the part's visual mesh, posed as the world
reports it.
"""

import argparse
import os
import tempfile

from experiment_manager.analysis.results import read_csv, ResultsWriter
from experiment_manager.running.local_backend import LocalBackend
from experiment_manager.running.scheduler import Runner
import numpy as np
from pick_common.states import PartStates
import trimesh

from studies.cases import variant

OVER_WALL = 0.004   # m: a part this close to a wall's inner face, or past it, leans on it


class Landing(LocalBackend):
    """The cores, measuring the tray after every feed (self.feeds: one row per feed)."""

    def __init__(self) -> None:
        super().__init__()
        self.feeds: list[tuple[int, float, int, int, int]] = []

    def start(self, file) -> None:
        super().start(file)
        if getattr(self._world, 'landing', None) is self:
            return
        drop = self._world.drop

        def measured_drop(count, zone='container', **kw):
            out = drop(count, zone=zone, **kw)
            if zone == 'feeder':
                self.measure(count, len(out[0]), self._world.snapshot(), file.tray)
            return out
        self._world.drop, self._world.landing = measured_drop, self

    def measure(self, count: int, fed: int, states: PartStates, tray) -> None:
        x, y, wall = tray.inner_size
        points = np.asarray(self._world.part.visual.vertices)
        tops, reach = [], []
        for pose in states.poses:
            rotation = trimesh.transformations.quaternion_matrix(np.roll(pose[3:], 1))[:3, :3]
            p = points @ rotation.T + pose[:3]
            tops.append(p[:, 2].max())
            reach.append(min(x / 2 - np.abs(p[:, 0]).max(), y / 2 - np.abs(p[:, 1]).max()))
        tops, reach = np.array(tops), np.array(reach)
        self.feeds.append((count, float(tops.max()), int((tops > wall).sum()),
                           int(((reach < OVER_WALL) & (tops > wall)).sum()), fed))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--part', default='pth1.yaml')
    parser.add_argument('--runs', type=int, default=4)
    parser.add_argument('--parts', type=int, default=480)
    parser.add_argument('--range', default='45,55')
    parser.add_argument('--lip-mm', type=float, default=30.0)
    parser.add_argument('--rate', type=float, default=None, help='the hopper, parts/s '
                        "(default: the file's hopper_rate)")
    parser.add_argument('--speed-mm-s', type=float, default=None, help="the parts' speed "
                        "leaving the hopper (default: the file's hopper_speed_mm_s)")
    parser.add_argument('--set-back-mm', type=float, default=0.0)
    parser.add_argument('--max-feed', type=int, default=None)
    parser.add_argument('--wall-mm', type=float, default=None, help="the tray's wall height "
                        "(default: the file's tray_mm)")
    parser.add_argument('--output', default=None, help='keep the run directory here')
    parser.add_argument('--moves', default=None, help="the vibration cycle's named moves "
                        "(default: the part file's)")
    args = parser.parse_args()
    span = [int(v) for v in args.range.split(',')]
    sections = {'hopper_lip_mm': args.lip_mm,
                **({'hopper_rate': args.rate} if args.rate else {}),
                **({'hopper_speed_mm_s': args.speed_mm_s} if args.speed_mm_s else {}),
                **({'moves': args.moves.split(',')} if args.moves else {})}
    experiments = [{'id': 'feeder', 'type': 'feeder_emptying', 'iterations': args.runs,
                    'parts': args.parts, 'optimal_range': span, 'max_vibrations': 500,
                    **({'max_feed': args.max_feed} if args.max_feed else {})}]
    tray = variant(args.part, experiments).tray
    if args.wall_mm:
        sections['tray_mm'] = [1000 * tray.inner_size[0], 1000 * tray.inner_size[1],
                               args.wall_mm]
    if args.set_back_mm:
        (cx, cy), (sx, sy) = tray.feeder_zone_center, tray.feeder_zone_size
        b = args.set_back_mm / 1000.0
        sections['feeder_zone_mm'] = {'center': [1000 * (cx + b / 2), 1000 * cy],
                                      'size': [1000 * (sx - b), 1000 * sy]}
    file = variant(args.part, experiments, **sections)
    with tempfile.TemporaryDirectory() as scratch:
        out = args.output or scratch
        os.makedirs(out, exist_ok=True)
        with Landing() as backend, ResultsWriter(out, file.text) as writer:
            summary = Runner(file, [backend], writer).run()
        rows = read_csv(os.path.join(out, 'iterations.csv'))
    feeds = np.array(backend.feeds)
    (cx, cy), (sx, sy) = file.tray.feeder_zone_center, file.tray.feeder_zone_size
    dose = f'at most {args.max_feed} parts a feed' if args.max_feed else 'no dose'
    cycle = ', '.join(args.moves.split(',')) if args.moves else "the file's cycle"
    tray = file.tray
    print(f'{args.part}: {dose}, {cycle}, hopper lip {args.lip_mm:g} mm, '
          f'{tray.hopper_rate:g} parts/s at {1000 * tray.hopper_speed:g} mm/s, feeder zone at '
          f'{1000 * cx:.2f}, {1000 * cy:.2f} mm, {1000 * sx:.2f} x {1000 * sy:.2f} mm, walls '
          f'{1000 * file.tray.inner_size[2]:g} mm')
    top = np.percentile(1000 * feeds[:, 1], [50, 90, 100])
    print(f'  {len(feeds)} feeds let out {int(feeds[:, 4].sum())} of the {int(feeds[:, 0].sum())} '
          f'parts asked ({int((feeds[:, 4] < feeds[:, 0]).sum())} feeds held back at the outlet)')
    print(f'  {len(feeds)} feeds: pile top median {top[0]:.1f} mm, 90th {top[1]:.1f}, '
          f'highest {top[2]:.1f}; {int((feeds[:, 2] > 0).sum())} feeds left a part higher '
          f"than the walls; {int(feeds[:, 3].sum())} parts over a wall's top after a feed")
    print('  spilled per run: ' + ', '.join(str(r['spilled']) for r in rows)
          + '; vibrations: ' + ', '.join(str(r['vibrations']) for r in rows))
    grounds = summary.experiments['feeder'].decision
    for ground, d in (('time', grounds.time), ('spills', grounds.spills)):
        print(f'  {ground}: {d.verdict}: {d.reason}')


if __name__ == '__main__':
    main()
