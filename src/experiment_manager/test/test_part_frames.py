"""The same part written with its origin anywhere and its axes turned gives the same answers:
a mesh's physics comes from its geometry (pick_sim_world's test_mesh_frames.py), and its
grasps and placing, written in the file's frame, follow it."""

import os

import numpy as np
from pick_common.containers import ContainerSpec
from pick_common.parts.spec import PartSpec
from pick_common.specs import SceneSpec
from pick_sim_world.config import PhysicsConfig
from pick_sim_world.world import World
from pick_validity.config import GraspPose, PlaceSpec, Setup
from pick_validity.validity import Validator
import trimesh

BOX = (0.012, 0.004, 0.002)          # m
MASS = 0.001                          # kg
IDENTITY = np.eye(3)


def _mesh(tmp_path, name: str, offset, turn=IDENTITY) -> PartSpec:
    """The box, its centre at `offset` and its axes turned by `turn` in the file's frame."""
    mesh = trimesh.creation.box(BOX)
    mesh.apply_transform(np.vstack([np.column_stack([turn, offset]), [0, 0, 0, 1]]))
    path = os.path.join(tmp_path, f'{name}.stl')
    mesh.export(path)
    return PartSpec(model='mesh', mesh_path=path, mass=MASS)


def _valid_per_check(spec: PartSpec, offset, seeds, turn=IDENTITY) -> np.ndarray:
    """Valid parts per check of 25 boxes on the tray, per seed, gripped flat across their
    4 mm width at their centre and placed on their bottom face, all written in the file's
    frame (the box's centre at `offset`, its axes turned by `turn`)."""
    up, closing, down = turn @ [0.0, 0.0, 1.0], turn @ [0.0, 1.0, 0.0], turn @ [0.0, 0.0, -1.0]
    grasp = GraspPose('flat', tuple(up), tuple(closing), 0.008, tuple(offset))
    # the seating plane: the box's bottom face, 1 mm from its centre along the place axis
    setup = Setup(spec, grasps=(grasp,), place=PlaceSpec(tuple(down), 0.001 + down @ offset))
    return _valid_on_tray(setup, 25, seeds)


def _valid_on_tray(setup: Setup, parts: int, seeds) -> np.ndarray:
    """Valid parts per check of `parts` of setup.part dropped on the tray, per seed."""
    valid = []
    for seed in seeds:
        with World(SceneSpec(ContainerSpec.tray(), setup.part, 1, seed),
                   PhysicsConfig()) as world:
            world.drop(parts)
            state = world.snapshot()
            # the parts still in the tray, as a run checks them (the broken physics of the
            # last case throws them out)
            inside = state.inside
            if not inside.any():
                valid.append(0)
                continue
            report = Validator(setup, world.part).check(ContainerSpec.tray(), state.ids[inside],
                                                        state.poses[inside])
        valid.append(report.counts['valid'])
    return np.array(valid, dtype=float)


def test_moving_the_file_s_origin_and_turning_its_axes_change_no_answer(tmp_path,
                                                                       monkeypatch):
    """The same box with its origin at its centre, 36 mm beside it, and beside it with its
    axes turned, grasps and placing written for each: the valid parts per check agree within
    their noise (8 seeds; the floating point of each frame makes the scenes differ, not their
    statistics). Measured: 8.0 +- 1.1 centred, 8.2 +- 1.0 moved, 7.5 +- 0.7 moved
    and turned; with the mass centre at the file's origin, as the world had it before, the
    moved box gave 0.0 (its parts stood on end, pivoting about a point beside them)."""
    seeds = range(8)
    moved = np.array([0.03, -0.02, 0.01])
    turn = trimesh.transformations.euler_matrix(0.4, -1.1, 2.0)[:3, :3]
    centred = _valid_per_check(_mesh(tmp_path, 'centred', (0, 0, 0)), (0.0, 0.0, 0.0), seeds)
    for name, t in (('moved', np.eye(3)), ('turned', turn)):
        other = _valid_per_check(_mesh(tmp_path, name, moved, t), moved, seeds, t)
        noise = 3.0 * np.hypot(centred.std(ddof=1), other.std(ddof=1)) / np.sqrt(len(seeds))
        assert centred.mean() > 3 and abs(centred.mean() - other.mean()) <= noise, (
            name, centred, other)
    # the check can fail: the mass centre put at the file's origin moves the answer far more
    import pick_common.parts.geometry as geometry
    finish = geometry._finish
    monkeypatch.setattr(geometry, '_finish', lambda *args, **kwargs: finish(*args[:6]))
    old = _valid_per_check(_mesh(tmp_path, 'old', moved), moved, seeds)
    assert abs(centred.mean() - old.mean()) > noise, (centred, old)


def test_kicads_to220_as_step_stl_and_obj_anywhere_gives_the_same_answer(tmp_path):
    """KiCad's TO-220 as its STEP file (metres, KiCad's frame), as an STL in mm with its
    origin 40 mm away, and as an OBJ in mm turned about all three axes: the example's grasps
    and placing written for each frame give the same valid parts per check on the tray
    within their noise (CoACD cuts each file's mesh anew, in the part's own principal frame).
    Measured, 30 parts, 6 seeds: 24.0 +- 3.2, 24.0 +- 3.3, 25.0 +- 3.5; before the
    spawn sphere and the cut were taken about the mass centre and principal axes, the turned
    OBJ gave 20.0 and 19.2 against 23.0 and 24.7."""
    step = os.path.join(os.path.dirname(__file__), '..', 'config', 'parts',
                        'TO-220-3_Vertical.step')
    mesh = trimesh.load(step, force='mesh')
    point = np.array([0.00254, 0.00094, 0.0085])
    grasps = [((0, -1, 0), (1, 0, 0), 0.016), ((0, 1, 0), (1, 0, 0), 0.016),
              ((1, 0, 0), (0, 1, 0), 0.0105), ((-1, 0, 0), (0, 1, 0), 0.0105)]
    seeds = range(6)

    def valid(spec: PartSpec, turn: np.ndarray, shift: np.ndarray) -> np.ndarray:
        poses = tuple(GraspPose(f'g{i}', tuple(turn @ up), tuple(turn @ closing), opening,
                                tuple(turn @ point + shift))
                      for i, (up, closing, opening) in enumerate(grasps))
        down = turn @ np.array([0.0, 0.0, -1.0])
        setup = Setup(spec, grasps=poses, place=PlaceSpec(tuple(down), float(down @ shift)))
        return _valid_on_tray(setup, 30, seeds)

    answers = {'step': valid(PartSpec(model='mesh', mesh_path=step, mass=0.002), IDENTITY,
                             np.zeros(3))}
    turn = trimesh.transformations.euler_matrix(0.7, 0.3, -1.2)[:3, :3]
    for name, t, shift in (('stl', IDENTITY, np.array([0.04, 0.0, -0.01])),
                           ('obj', turn, np.array([0.0, 0.02, 0.0]))):
        moved = mesh.copy()
        moved.apply_transform(np.vstack([np.column_stack([t, shift]), [0, 0, 0, 1]]))
        moved.apply_scale(1000.0)                 # written in mm, as CAD tools export
        path = os.path.join(tmp_path, f'to220.{name}')
        moved.export(path)
        answers[name] = valid(PartSpec(model='mesh', mesh_path=path, scale=0.001, mass=0.002),
                              t, shift)
    base = answers['step']
    assert base.mean() > 2, answers
    for name in ('stl', 'obj'):
        noise = 3.0 * np.hypot(base.std(ddof=1), answers[name].std(ddof=1)) / np.sqrt(len(seeds))
        assert abs(base.mean() - answers[name].mean()) <= noise, (name, answers)
