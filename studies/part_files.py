"""One part from any file gives one answer: KiCad's 5 mm capacitor from its STEP file, from
STL exports of it at a finer and a coarser tessellation, from the finer one with its origin
moved to its mass centre, and turned and moved.

    tools/ws python -m studies.part_files [--drops 300] [--parts 60] [--seeds 4]
        [--length-unit 0.01]

For each file: the part's aspects (names, quasi-static shares); `--drops` drops from 100 mm
onto a plate (a drop_test's), the share resting on each aspect with its 95 % interval
(Clopper-Pearson) and on none; `--parts` capacitors on the tray per seed, checked with the
test case's gripper and the grasps of config/parts/cp_radial_kicad.yaml written in the file's
frame: valid parts per check (mean and 95 % interval over the seeds), where they stopped,
and the share resting upside down (the part's z axis within 60 degrees of down), with its
interval. --length-unit 1 runs the world in metres with its former contact-breaking factor,
for the comparison docs/physics.md gives.
"""

import argparse
from collections import Counter
import os
import tempfile
import time

from experiment_manager.experiment_file.drop_test import plate
import numpy as np
from pick_common.containers import ContainerSpec
from pick_common.parts.aspects import classify, OTHER, part_aspects
from pick_common.parts.geometry import build_part
from pick_common.parts.spec import PartSpec
from pick_common.specs import SceneSpec
from pick_common.states import rotate
from pick_common.stats import interval, rate_interval
from pick_sim_world.config import PhysicsConfig
from pick_sim_world.world import World
from pick_validity.config import PlaceSpec, Setup
from pick_validity.grasps import GraspPose
from pick_validity.grippers import Jaws
from pick_validity.results import (
    STAGE_CANDIDACY,
    STAGE_CONTAINER,
    STAGE_NEIGHBOUR,
    STAGE_OUTSIDE,
    STAGE_PLACEABILITY,
    STAGE_VALID,
)
from pick_validity.validity import Validator
import trimesh

from studies.cases import parse_args

STEP = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'src',
                    'experiment_manager', 'config', 'parts', 'CP_Radial_D5.0mm_P2.00mm.step')
MASS = 0.0004                   # kg: cp_radial_kicad.yaml's
POINT = np.array([0.001, 0.0, 0.0025])      # m, KiCad's frame: the body's middle
GRASPS = [((1, 0, 0), (0, 1, 0)), ((-1, 0, 0), (0, 1, 0)), ((0, 1, 0), (1, 0, 0)),
          ((0, -1, 0), (1, 0, 0)), ((0, 0, 1), (1, 0, 0))]
GRIPPER = Jaws(body_diameter=0.02, body_length=0.06, jaw_height=0.015, jaw_depth=0.003)
TURN = trimesh.transformations.euler_matrix(0.7, 0.3, -1.2)[:3, :3]
STAGES = {STAGE_CANDIDACY: 'candidacy', STAGE_PLACEABILITY: 'placeability',
          STAGE_CONTAINER: 'container', STAGE_NEIGHBOUR: 'neighbours', STAGE_VALID: 'valid',
          STAGE_OUTSIDE: 'outside'}


def files(directory: str) -> dict[str, tuple[PartSpec, np.ndarray, np.ndarray]]:
    """name -> (spec, turn, shift of its frame from KiCad's)."""
    out = {'step': (PartSpec(model='mesh', mesh_path=STEP, mass=MASS), np.eye(3), np.zeros(3))}
    fine = trimesh.load(STEP, force='mesh', tol_linear=0.005, tol_angular=0.2)
    coarse = trimesh.load(STEP, force='mesh', tol_linear=0.05, tol_angular=0.8)
    for name, mesh, turn, shift in (
            ('stl_fine', fine, np.eye(3), np.zeros(3)),
            ('stl_coarse', coarse, np.eye(3), np.zeros(3)),
            ('stl_centred', fine, np.eye(3), -np.asarray(fine.center_mass)),
            ('stl_turned', fine, TURN, np.array([0.0, 0.02, -0.01]))):
        moved = mesh.copy()
        moved.apply_transform(np.vstack([np.column_stack([turn, shift]), [0, 0, 0, 1]]))
        moved.apply_scale(1000.0)
        path = os.path.join(directory, f'{name}.stl')
        moved.export(path)
        out[name] = (PartSpec(model='mesh', mesh_path=path, scale=0.001, mass=MASS), turn, shift)
    return out


def share(k: int, n: int) -> str:
    low, high = rate_interval(k, n)
    return f'{100 * k / n:5.1f} % [{100 * low:4.1f}, {100 * high:4.1f}]'


def kicad_z(poses: np.ndarray, turn: np.ndarray) -> np.ndarray:
    """The world z of KiCad's z axis for poses of a file's frame turned by `turn`."""
    return rotate(poses[:, 3:], turn @ np.array([0.0, 0.0, 1.0]))[:, 2]


# the size of its smoke test (tests/test_studies.py): `--small`
SMALL = ['--drops', '4', '--parts', '6', '--seeds', '2']


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('--drops', type=int, default=300)
    ap.add_argument('--parts', type=int, default=60)
    ap.add_argument('--seeds', type=int, default=4)
    ap.add_argument('--length-unit', type=float, default=PhysicsConfig().length_unit)
    args = parse_args(ap, SMALL)
    physics = PhysicsConfig(length_unit=args.length_unit) if args.length_unit != 1.0 else \
        PhysicsConfig(length_unit=1.0, contact_breaking_threshold=0.001)
    with tempfile.TemporaryDirectory() as tmp:
        for name, (spec, turn, shift) in files(tmp).items():
            start = time.perf_counter()
            part = build_part(spec)
            found = part_aspects(part)
            print(f'{name}: {len(part.visual.faces)} triangles, {len(part.primitives)} pieces; '
                  'aspects ' + ', '.join(f'{a.name} {100 * a.quasi_static:.1f} %'
                                         for a in found if a.quasi_static >= 0.005))
            seen: Counter = Counter()
            for first in range(0, args.drops, 64):
                n = min(64, args.drops - first)
                with World(SceneSpec(plate(part, 0.1, 0.003), spec, n, first),
                           PhysicsConfig(**{**vars(physics), 'settle_moving_fraction': 0.0})
                           ) as world:
                    world.drop(1)
                    seen.update(classify(found, world.snapshot().poses[:, 3:]))
            print(f'  {args.drops} drops: ' + '; '.join(
                f'{a} {share(k, args.drops)}' for a, k in seen.most_common()
                if k >= 0.01 * args.drops or a == OTHER))
            grasps = tuple(GraspPose(f'g{i}', tuple(turn @ up), tuple(turn @ closing), 0.011,
                                     tuple(turn @ POINT + shift))
                           for i, (up, closing) in enumerate(GRASPS))
            down = turn @ np.array([0.0, 0.0, -1.0])
            setup = Setup(spec, gripper=GRIPPER, grasps=grasps,
                          place=PlaceSpec(tuple(down), float(down @ shift)))
            valid, stops, upside, total = [], Counter(), 0, 0
            for seed in range(args.seeds):
                with World(SceneSpec(ContainerSpec.tray(), spec, 1, seed), physics) as world:
                    world.drop(args.parts)
                    state = world.snapshot()
                    inside = state.inside
                    report = Validator(setup, world.part).check(
                        ContainerSpec.tray(), state.ids[inside], state.poses[inside])
                valid.append(report.counts['valid'])
                stops.update(STAGES[r.stage] for r in report.results)
                z = kicad_z(state.poses[inside], turn)
                upside += int((z < -0.5).sum())
                total += len(z)
            mean, (low, high) = float(np.mean(valid)), interval(valid, counts=True)
            print(f'  {args.parts} on the tray, {args.seeds} seeds: valid per check {mean:.1f} '
                  f'[{low:.1f}, {high:.1f}] ({", ".join(str(v) for v in valid)}); upside down '
                  f'{share(upside, total)}; stopped at '
                  + ', '.join(f'{s} {k}' for s, k in stops.most_common())
                  + f'; {time.perf_counter() - start:.0f} s')


if __name__ == '__main__':
    main()
