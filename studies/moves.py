"""Where each named feeder move carries parts: three capacitors (PTH0's part) laid 50 mm toward
the tray's +x wall, 30 mm apart, lying on their sides, then one move (pick_common.specs.MOVES)
and a settle; the scene of test_world.py's
test_centring_carries_parts_off_centre_toward_the_middle_where_a_flip_does_not.

    tools/ws python -m studies.moves [--moves centre,flip,backward,spread]
        [--offset-mm 50]

Prints per move: the parts' centroid (x, y, mm) before and after, how far it moved toward the
tray's centre along x (mm; negative: away), the simulated time of the vibration and settle,
and the tray's tracking error (delivered against commanded amplitude).
"""

import argparse

import numpy as np
from pick_common.containers import ContainerSpec
from pick_common.parts.spec import PartSpec
from pick_common.specs import MOVES, SceneSpec
from pick_sim_world.config import PhysicsConfig
from pick_sim_world.world import World

from studies.cases import parse_args

LYING = (0.0, 0.7071068, 0.0, 0.7071068)     # the capacitor's axis along x


def carry(move: str, offset: float) -> tuple[np.ndarray, np.ndarray, float, float]:
    """(centroid before, after, simulated s of the move and its settle, the tray's tracking
    error), x y in m."""
    scene = SceneSpec(ContainerSpec.tray(), PartSpec(model='radial_capacitor'), 1, 3)
    with World(scene, PhysicsConfig()) as world:
        ids, _ = world.drop(3, zone='feeder')
        for pid, y in zip(ids, (-0.03, 0.0, 0.03), strict=True):
            world.engine.set_pose(world.body(pid), [offset, y, 0.004], LYING)
        world.settle()
        before = world.snapshot().poses[:, :2].mean(axis=0)
        report = world.vibrate(MOVES[move])
        error = report.tray.error if report.tray else float('nan')
        return before, world.snapshot().poses[:, :2].mean(axis=0), report.sim_time, error


# the size of its smoke test (tests/test_studies.py): `--small`
SMALL = ['--moves', 'centre']


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('--moves', default='centre,flip,backward,spread')
    ap.add_argument('--offset-mm', type=float, default=50.0)
    args = parse_args(ap, SMALL)
    print(f'{"move":<10} {"before x, y mm":>16} {"after x, y mm":>16} {"toward centre mm":>17} '
          f'{"sim s":>6} {"tray error":>10}')
    for move in args.moves.split(','):
        before, after, sim, error = carry(move, args.offset_mm / 1000.0)
        print(f'{move:<10} {before[0] * 1e3:8.1f} {before[1] * 1e3:7.1f} '
              f'{after[0] * 1e3:8.1f} {after[1] * 1e3:7.1f} '
              f'{(abs(before[0]) - abs(after[0])) * 1e3:17.1f} {sim:6.2f} {100 * error:9.1f}%')


if __name__ == '__main__':
    main()
