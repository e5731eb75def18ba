"""A feeder run again on the cores, to the feed or move that spilled: `spill.png` for the report.

The first feeder_emptying iteration whose row in iterations.csv spilled a part is run again
from its seed (procedures.run_unit on the cores: the same physics as the nodes), the tray drawn
before each feed and each move of the feeder's cycle, and stopped at the first that sends a
part over a wall: nothing after it is simulated. A drawer for analysis.pictures.write (this
room may run iterations; analysis may not).
"""

import csv
import os

import numpy as np

from ..analysis.pictures import camera, save, SIZE
from ..analysis.summary import Summary
from ..experiment_file import ExperimentFile, FEEDER_EMPTYING
from ..experiment_file.plan import plan
from .local_backend import LocalBackend
from .procedures import run_unit


class _Seen(Exception):
    """The move that spilled was found: the rest of the run is not simulated again."""


class _Watching(LocalBackend):
    """The cores, drawing the tray before each feed and each move of the feeder's cycle and
    stopping at the first that sends a part over a wall: `spill` = (picture before, picture
    after, what it was, e.g. 'move 12', its report)."""

    def __init__(self, camera: dict) -> None:
        super().__init__()
        self.camera, self.done, self.spill = camera, {'feed': 0, 'move': 0}, None

    def feed(self, valid: int, on_table: int, restart):
        world = self._world
        if not getattr(world.vibrate, 'watched', False):
            world.vibrate = self._watched(world.vibrate, 'move')
            world.drop = self._watched(world.drop, 'feed')
        return super().feed(valid, on_table, restart)

    def _watched(self, operation, name: str):
        world = self._world

        def watched(*args, **kwargs):
            before = world.render(*SIZE, **self.camera)
            out = operation(*args, **kwargs)
            report = out[1] if isinstance(out, tuple) else out
            self.done[name] += 1
            if _spilled(report):
                self.spill = (before, world.render(*SIZE, **self.camera),
                              f'{name} {self.done[name]}', report)
                raise _Seen
            return out
        watched.watched = True
        return watched


def _spilled(report) -> set[int]:
    """The parts a world operation's report has over a wall (not through one, not thrown)."""
    return set(report.spilled_ids) - set(report.tunnelled_ids) - set(report.thrown_ids)


def spill_picture(file: ExperimentFile, summary: Summary, run_dir: str,
                  captions: dict[str, str]) -> str | None:     # an analysis.pictures.Drawer
    """spill.png: the first feeder run that spilled, re-simulated to the feed or move that
    spilled: the tray before it and after it; returns its caption (None: no run spilled)."""
    exp = file.first_of(FEEDER_EMPTYING)
    if exp is None or exp.id not in summary.experiments:
        return None
    with open(os.path.join(run_dir, 'iterations.csv'), newline='') as f:
        row = next((r for r in csv.DictReader(f) if r['experiment'] == exp.id
                    and int(r['spilled'] or 0) > 0), None)
    if row is None:
        return None
    unit = next(u for u in plan(file, exp, summary.experiments)
                if u.iteration == int(row['iteration']))
    with _Watching(camera(unit)) as backend:
        backend.start(file)
        try:
            run_unit(file, unit, backend)
        except _Seen:
            pass
    if backend.spill is None:
        return None
    before, after, what, report = backend.spill
    save(os.path.join(run_dir, 'spill.png'), np.hstack([before, after]))
    where = '; '.join(f'part {i} at x {p[0] * 1000:.0f}, y {p[1] * 1000:.0f} mm, {v:.2f} m/s'
                      for i, p, v in zip(report.landed_ids, report.landed_at,
                                         report.landed_speeds, strict=True))
    return (f'Run {unit.iteration + 1} of `{exp.id}` (seed {unit.seed}; it spilled '
            f'{row["spilled"]} parts), re-simulated to {what} of the run, the first to send '
            f'a part over a wall: the tray before it (left) and after it (right). '
            f'{len(_spilled(report))} part(s) went over' + (f', landing beside the tray: '
                                                             f'{where}.' if where else '.'))
