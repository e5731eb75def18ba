"""Which stage turns down a capacitor lying alone on the tray floor, by its roll about its own
body axis: the test case's side grasps are four poses 90 degrees apart about that axis, and a
part that rests at a roll between them is approached tilted by the difference.

    tools/ws python -m studies.roll [--files pth0 pth2] [--step 3]

For each test-case file: the part lies on its side (body axis along +X of the tray, its body on
the floor) in the middle of the empty tray, rolled by 0..45 degrees about its body axis, and is
checked with the file's gripper, grasps and settings (all four stages; no neighbours). Prints
the stage each roll ends at (5 valid, 3 container: the gripper meets the tray) and the share of
rolls that are valid, which is the share of lone lying parts a check finds valid when rolls
are uniform. Found in the test case's sweeps (docs/paper-test-case.md): with the
grasp fixed to the part, 15 % (valid within 6 deg of a side grasp; the jaws met the floor
beyond); with jaws that grip a round body at any roll (pick_validity README, Candidacy), 100 %.
"""

import argparse
import os

from experiment_manager import experiment_file
import numpy as np
from pick_common.containers import ContainerSpec
from pick_common.parts.geometry import build_part
from pick_validity.results import STAGE_VALID
from pick_validity.validity import Validator
from scipy.spatial.transform import Rotation

from studies.cases import parse_args, TEST_CASE


def stages_by_roll(name: str, rolls: np.ndarray) -> list[int]:
    f = experiment_file.load(os.path.join(TEST_CASE, f'{name}.yaml'))
    part = build_part(f.part)
    validator = Validator(f.setup, part)
    tray = ContainerSpec.tray(f.tray.inner_size)
    radius = f.part.dimensions['body_diameter'] / 2
    out = []
    for roll in rolls:
        q = (Rotation.from_euler('y', 90, degrees=True)
             * Rotation.from_euler('z', roll, degrees=True)).as_quat()
        pose = np.array([[0.0, 0.0, radius, *q]])
        out.append(validator.check(tray, [0], pose, [0], True).results[0].stage)
    return out


# the size of its smoke test (tests/test_studies.py): `--small`
SMALL = ['--files', 'pth0', '--step', '15']


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--files', nargs='+', default=['pth0', 'pth2'])
    parser.add_argument('--step', type=float, default=3.0, help='degrees between rolls')
    args = parse_args(parser, SMALL)
    rolls = np.arange(0.0, 45.0 + 1e-9, args.step)
    for name in args.files:
        stages = stages_by_roll(name, rolls)
        valid = np.mean([s == STAGE_VALID for s in stages])
        print(f'{name}: ' + ' '.join(f'{r:g}:{s}' for r, s in zip(rolls, stages, strict=True))
              + f'  -> valid at {100 * valid:.0f} % of rolls')


if __name__ == '__main__':
    main()
