"""How the gripper decides the validity stages: a test-case file's part dropped on the tray
(seeded scenes), checked with the file's grasps and placement and with grippers that differ
from the file's in body diameter, jaw depth and finger clearance. Prints the valid parts per
scene and the parts stopped at each stage (1 candidacy, 2 placeability, 3 container,
4 neighbours, 5 valid).

    tools/ws python -m studies.gripper_stages [--file pth0.yaml] [--parts 50] [--seeds 3]
"""

import argparse
import collections
from dataclasses import replace
import itertools
import os

from experiment_manager.experiment_file import load
from pick_common.specs import SceneSpec
from pick_sim_world.world import World
from pick_validity.validity import Validator

from studies.cases import parse_args, TEST_CASE

# the size of its smoke test (tests/test_studies.py): `--small`
SMALL = ['--parts', '10', '--seeds', '1']


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--file', default='pth0.yaml')
    parser.add_argument('--parts', type=int, default=50)
    parser.add_argument('--seeds', type=int, default=3)
    args = parse_args(parser, SMALL)
    f = load(os.path.join(TEST_CASE, args.file))
    scenes = []
    for seed in range(args.seeds):
        with World(SceneSpec(f.tray, f.part, seed=seed)) as world:
            world.drop(args.parts)
            scenes.append((world.snapshot(), world.part))
    print(f'{args.file}: {args.parts} parts on the tray, seeds 0-{args.seeds - 1}; the '
          f"file's gripper: D {f.gripper.body_diameter * 1e3:g} mm, W "
          f'{f.gripper.jaw_depth * 1e3:g} mm, finger clearance '
          f'{f.gripper.finger_clearance * 1e3:g} mm')
    for d, w, clear in itertools.product((8, 12, 20), (3, 6), (1, 2)):
        gripper = replace(f.gripper, body_diameter=d / 1000, jaw_depth=w / 1000,
                          finger_clearance=clear / 1000)
        stages, valid = collections.Counter(), []
        for state, part in scenes:
            report = Validator(replace(f.setup, gripper=gripper), part).check(
                f.tray, state.ids, state.poses)
            stages.update(r.stage for r in report.results)
            valid.append(report.counts['valid'])
        print(f'D {d:2d} mm, W {w} mm, clearance {clear} mm: valid per scene {valid}; '
              f'stopped at each stage {dict(sorted(stages.items()))}')


if __name__ == '__main__':
    main()
