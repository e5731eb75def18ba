"""The cup's grasp search (grasp_proposals.propose_suction) on parts' models, with the
caster's grid and without it, in one run: per part the seconds of each, their ratio, and
whether the proposals (or the refusal's message) are the same to the character (they must be:
the grid only spares a line the triangles whose shadows cannot hold it).

    tools/ws python -m bench.validity.bench_cup_search PART_FILE [PART_FILE ...]

Each PART_FILE is an experiment file (a board's part files, in <output>/<board id>_parts/);
its part is built as a run builds it (its pieces from the cache, or cut first), the built-in
cup (config/board_cell.yaml's: 4 mm) searched on it. Without the grid, every line is tested
against every triangle's shadow (the caster before its grid: `FlatCaster`). One core.
"""

import argparse
import os
import time

from experiment_manager.experiment_file.loading import part_of
from experiment_manager.experiment_file.part import geometry
import numpy as np
from pick_common.errors import InvalidArgument
from pick_validity import grasp_fit, grasp_proposals, suction
from pick_validity.grippers import SuctionCup


class FlatCaster(grasp_fit.Caster):
    """The caster without its grid: each line against every triangle's shadow."""

    def _file(self) -> None:
        pass

    def crossings_of(self, origins: np.ndarray) -> list[np.ndarray]:
        origins = np.asarray(origins, dtype=np.float64)
        feet = origins @ self._axes.T
        held = ((self._low[None] <= feet[:, None]) & (feet[:, None] <= self._high[None])
                ).all(axis=2)
        line, near = np.nonzero(held)
        t, hit = grasp_fit._crossed(self.triangles[near], origins[line], self.direction)
        return np.split(t[hit], np.cumsum(np.bincount(line[hit], minlength=len(origins)))[:-1])


def search(part, caster: type) -> tuple[str, float]:
    """The cup's proposals (or its refusal) as text, and the seconds the search took, with
    `caster` in the two modules that cast."""
    grasp_proposals.Caster = suction.Caster = caster
    start = time.perf_counter()
    try:
        said = repr([(p.grasp, p.width) for p in grasp_proposals.propose_suction(
            part, SuctionCup())])
    except InvalidArgument as exc:
        said = f'refused: {exc}'
    return said, time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('files', nargs='+', metavar='PART_FILE')
    args = parser.parse_args()
    os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})
    print(f'{"part":60} {"triangles":>9} {"grid s":>8} {"flat s":>8} {"ratio":>6}  same')
    totals = [0.0, 0.0]
    for path in args.files:
        part = geometry(part_of(path))
        grid, grid_s = search(part, grasp_fit.Caster)
        flat, flat_s = search(part, FlatCaster)
        totals[0] += grid_s
        totals[1] += flat_s
        name = os.path.splitext(os.path.basename(path))[0][-60:]
        print(f'{name:60} {len(grasp_fit.surface(part)):9d} {grid_s:8.2f} {flat_s:8.2f} '
              f'{flat_s / grid_s:6.1f}  {"yes" if grid == flat else "NO"}', flush=True)
    print(f'{"all":60} {"":9} {totals[0]:8.2f} {totals[1]:8.2f} {totals[1] / totals[0]:6.1f}')


if __name__ == '__main__':
    main()
