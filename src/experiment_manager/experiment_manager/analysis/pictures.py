"""Pictures for the report, rendered with PyBullet's CPU renderer (no GPU needed).

An iteration is re-simulated from its seed on the cores (the same physics as the nodes: the
settled poses are identical to the recorded ones, which is checked and said in the caption):
- `bin.png`: the first bin_emptying iteration's settled bin, with the gripper of its first pick
  (green, a valid grasp) and the gripper of a rejected part at the tilt nearest 0, the most
  vertical approach (red: it hits the bin or a neighbour);
- `tray.png`: the first table_sweep iteration at the count nearest the optimum n*;
- `feed.png`: the first feeder_emptying iteration's tray after its first feed (the pile by the
  hopper's outlet) and after the moves that follow it;
- `spill.png` (drawn by running/resimulate.py, passed in): the first feeder run that spilled,
  re-simulated to the move that spilled, the tray before and after it;
- `stopped_container.png`, `stopped_neighbour.png`: in the bin (else the tray) above, the first
  part the stage stopped, its gripper in red at the most vertical approach;
- `stopped_placeability.png`: the first part placeability stopped, in its place orientation on
  the placing surface with the gripper at its best tilt (drawn as the part sheet draws it).
"""

from collections.abc import Callable, Mapping
import csv
import json
import os
from types import MappingProxyType

from feeder_controller.policy import FeederPolicy
import matplotlib.image
import matplotlib.pyplot as plt
import numpy as np
from pick_common.specs import SceneSpec
from pick_sim_world import hopper
from pick_sim_world.world import Overlay, World
from pick_validity.geometry import BoxShape, Shape
from pick_validity.results import STAGE_CONTAINER, STAGE_NEIGHBOUR, STAGE_PLACEABILITY
from pick_validity.validity import Validator
from scipy.spatial.transform import Rotation

from ..experiment_file import BIN_EMPTYING, ExperimentFile, FEEDER_EMPTYING, TABLE_SWEEP
from ..experiment_file.plan import plan, Unit
from . import part_sheet
from . import summary as summary_model

SIZE = (800, 600)
# stage: (its name in the pictures' files, what a part stopped there hits)
STOPPED = {STAGE_PLACEABILITY: ('placeability', 'the placing surface'),
           STAGE_CONTAINER: ('container', 'the bin'), STAGE_NEIGHBOUR: ('neighbour', 'a neighbour')}
GREEN, RED = (0.1, 0.8, 0.1, 0.55), (0.9, 0.1, 0.1, 0.55)
# a picture's drawer: (file, the run's summary, run directory, the captions so far) -> its
# caption, None when it has nothing to draw
Drawer = Callable[['ExperimentFile', summary_model.Summary, str, dict[str, str]], str | None]


def gripper_overlays(shapes: tuple[Shape, ...], pose, rgba) -> list[Overlay]:
    """The validity check's simplified gripper (its shapes, in the gripper frame: the jaws'
    cuboid around the grasp point and the body cylinder above it) at a pose (7,) of its
    frame."""
    pose = np.asarray(pose, dtype=float)
    rotation = Rotation.from_quat(pose[3:])
    overlays = []
    for shape in shapes:
        at = (*(pose[:3] + rotation.apply(shape.center)),
              *(rotation * Rotation.from_matrix(shape.rotation)).as_quat())
        if isinstance(shape, BoxShape):     # the gripper is a box (the jaws) and a cylinder
            overlays.append(Overlay('box', tuple(shape.half), at, rgba))
        else:
            overlays.append(Overlay('cylinder', (shape.radius, 2 * shape.half_length), at, rgba))
    return overlays


def _rows(run_dir: str, name: str, experiment: str, iteration: int = 0) -> list[dict]:
    with open(os.path.join(run_dir, f'{name}.csv'), newline='') as f:
        return [r for r in csv.DictReader(f) if r['experiment'] == experiment
                and int(r['iteration']) == iteration]


def _settle(file: ExperimentFile, unit: Unit) -> World:
    world = World(SceneSpec(unit.container, file.part, 1, unit.seed))
    world.drop(unit.parts)
    return world


def _same_as_recorded(world: World, rows: list[dict], group: int) -> bool:
    recorded = {int(r['part_id']): [float(r[k]) for k in ('x', 'y', 'z', 'qx', 'qy', 'qz', 'qw')]
                for r in rows if r['check'] == '0' and int(r['group']) == group}
    states = world.snapshot()
    return recorded == {i: p for i, p in zip(states.ids.tolist(), states.poses.tolist(),
                                             strict=True)}


def camera(unit: Unit) -> dict:
    """The camera that shows a unit's whole container (World.render's keywords)."""
    x, y, z = unit.container.inner_size
    return {'distance': 1.7 * max(x, y), 'target': (0.0, 0.0, z / 2)}


def save(path: str, image: np.ndarray) -> None:
    """A picture (H, W, 3) as a PNG file."""
    matplotlib.image.imsave(path, image)


def _stopped_gripper(validator: Validator, row: dict) -> list[Overlay]:
    """The gripper (red) of a part's row of parts.csv at the tilt nearest 0, the most vertical
    approach, with the grasp the check chose."""
    index = int(row['grasp'])
    position = np.array([float(row[k]) for k in ('x', 'y', 'z')])
    part_rotation = _rotation(row)
    geo = validator.geometry
    frames = validator.approach_frames(part_rotation.as_matrix()[None], np.array([index]))
    tilt = int(np.abs(geo.tilts).argmin())
    rotation = Rotation.from_matrix(frames[0, tilt])
    origin = position + part_rotation.apply(geo.grasps[index].point)
    return gripper_overlays(geo.gripper_shapes[index], (*origin, *rotation.as_quat()), RED)


def _rotation(row: dict) -> Rotation:
    return Rotation.from_quat([float(row[k]) for k in ('qx', 'qy', 'qz', 'qw')])


def _first_stopped(rows: list[dict], stage: int) -> dict | None:
    return next((r for r in rows if r['check'] == '0' and int(r['grasp']) >= 0
                 and int(r['stage']) == stage), None)


def stopped_in_world(world: World, validator: Validator, unit: Unit, rows: list[dict],
                     exp_id: str, run_dir: str, captions: dict[str, str]) -> None:
    """stopped_container.png and stopped_neighbour.png, each not yet in `captions`: the first
    part of the settled `world` (its first check, `rows` of parts.csv) that the stage stopped,
    with its gripper in red at the most vertical approach."""
    for stage in (STAGE_CONTAINER, STAGE_NEIGHBOUR):
        name, what = STOPPED[stage]
        row = _first_stopped(rows, stage)
        if f'stopped_{name}.png' in captions or row is None:
            continue
        image = world.render(*SIZE, overlays=_stopped_gripper(validator, row), **camera(unit))
        save(os.path.join(run_dir, f'stopped_{name}.png'), image)
        captions[f'stopped_{name}.png'] = (
            f'Stopped at {name} collision: part {row["part_id"]} of `{exp_id}` iteration 1 '
            f'(grasp {validator.geometry.grasps[int(row["grasp"])].name}), its gripper in red at '
            f'the most vertical approach: it hits {what}.')


def placeability_picture(validator: Validator, rows: list[dict], exp_id: str,
                         run_dir: str) -> str | None:
    """stopped_placeability.png: the first part of `rows` (parts.csv, an experiment's first
    iteration) that placeability stopped, turned to its place orientation on the placing
    surface, with the gripper as it picked it at its best tilt (the one that reaches least
    past the surface, among those within the approach cone); returns its caption."""
    row = _first_stopped(rows, STAGE_PLACEABILITY)
    if row is None:
        return None
    g, geo = int(row['grasp']), validator.geometry
    rotation = _rotation(row).as_matrix()
    frames = validator.approach_frames(rotation[None], np.array([g]))[0]
    within = np.flatnonzero(frames[:, 2, 2] >= np.cos(geo.config.approach_cone) - 1e-12)
    relatives = {k: rotation.T @ frames[k] for k in within}
    reach = {k: part_sheet.clearance(validator, g, r) for k, r in relatives.items()}
    if not reach:
        return None
    best = max(reach, key=reach.get)
    fig = plt.figure(figsize=(5.0, 4.2))
    ax = fig.add_subplot(1, 1, 1, projection='3d')
    part_sheet.draw_place(ax, validator, g, [relatives[best]], [geo.tilts[best]],
                          f'part {row["part_id"]}, grasp {geo.grasps[g].name}\n')
    fig.tight_layout()
    fig.savefig(os.path.join(run_dir, 'stopped_placeability.png'), dpi=90)
    plt.close(fig)
    return (f'Stopped at placeability: part {row["part_id"]} of `{exp_id}` iteration 1 (grasp '
            f'{geo.grasps[g].name}), turned to its place orientation, the gripper holding '
            f'it as it would pick it as it lies, at its best tilt '
            f'({np.degrees(geo.tilts[best]):+.0f} deg of {len(within)} within the '
            f'approach cone): it reaches {-reach[best] * 1000:.1f} mm past the placing surface '
            '(yellow).')


def bin_picture(file: ExperimentFile, summary: summary_model.Summary, run_dir: str,
                captions: dict[str, str]) -> str | None:
    """bin.png with a valid and a rejected grasp, and the parts its bin's stages stopped
    (`stopped_in_world`, into `captions`); returns its caption (None: nothing to draw)."""
    exp = file.first_of(BIN_EMPTYING)
    if exp is None or exp.id not in summary.experiments or (
            exp.bin_from and exp.bin_from not in summary.experiments):
        return None
    unit = plan(file, exp, summary.experiments)[0]
    parts, picks = _rows(run_dir, 'parts', exp.id), _rows(run_dir, 'picks', exp.id)
    if not parts:
        return None
    with _settle(file, unit) as world:
        validator = Validator(file.for_experiment(exp).setup, world.part)
        grasps = validator.geometry.grasps
        same = _same_as_recorded(world, parts, 0)
        overlays, notes = [], []
        if picks:
            p = picks[0]
            pose = [float(p[k]) for k in ('gripper_x', 'gripper_y', 'gripper_z', 'gripper_qx',
                                          'gripper_qy', 'gripper_qz', 'gripper_qw')]
            overlays += gripper_overlays(validator.geometry.gripper_shapes[int(p['grasp'])], pose,
                                         GREEN)
            notes.append(f'green: the first pick, part {p["part_id"]} (grasp '
                         f'{grasps[int(p["grasp"])].name}), found after {p["searches"]} '
                         'parts in search order')
        rejected = next((r for r in parts if r['check'] == '0' and int(r['grasp']) >= 0
                         and int(r['stage']) in (STAGE_CONTAINER, STAGE_NEIGHBOUR)), None)
        if rejected is not None:
            overlays += _stopped_gripper(validator, rejected)
            notes.append(f'red: part {rejected["part_id"]} (grasp '
                         f'{grasps[int(rejected["grasp"])].name}) at the most vertical '
                         f'approach, rejected: it hits {STOPPED[int(rejected["stage"])][1]}')
        stopped_in_world(world, validator, unit, parts, exp.id, run_dir, captions)
        image = world.render(*SIZE, overlays=overlays, **camera(unit))
    save(os.path.join(run_dir, 'bin.png'), image)
    size = ' x '.join(f'{s * 1000:g}' for s in unit.container.inner_size)
    return (f'The settled {size} mm bin of `{exp.id}` iteration 1 ({unit.parts} parts, seed '
            f'{unit.seed}; re-simulated: poses '
            f'{"identical to" if same else "DIFFERENT from"} the recorded ones). '
            + '; '.join(notes) + '.')


def tray_picture(file: ExperimentFile, summary: summary_model.Summary, run_dir: str,
                 captions: dict[str, str]) -> str | None:
    """tray.png at the count nearest n*, and the parts its stages stopped that the bin did not
    show (`stopped_in_world`); returns its caption (None: nothing to draw)."""
    exp = file.first_of(TABLE_SWEEP)
    sweep = summary.experiments.get(exp.id) if exp is not None else None
    if sweep is None or sweep.n_star is None:
        return None
    n_star = sweep.n_star
    n = min(exp.counts, key=lambda c: (abs(c - n_star), c))
    unit = next(u for u in plan(file, exp, summary.experiments)
                if u.group == n and u.iteration == 0)
    rows = [r for r in _rows(run_dir, 'parts', exp.id) if int(r['group']) == n]
    with _settle(file, unit) as world:
        same = _same_as_recorded(world, rows, n)
        image = world.render(*SIZE, **camera(unit))
        stopped_in_world(world, Validator(file.for_experiment(exp).setup, world.part), unit,
                         rows, exp.id, run_dir, captions)
    save(os.path.join(run_dir, 'tray.png'), image)
    return (f'{n} parts settled on the tray (`{exp.id}`, the tested count nearest n* = '
            f'{n_star}, iteration 1, seed {unit.seed}; re-simulated: poses '
            f'{"identical to" if same else "DIFFERENT from"} the recorded ones).')


def feed_picture(file: ExperimentFile, summary: summary_model.Summary, run_dir: str,
                 captions: dict[str, str]) -> str | None:
    """feed.png: the tray of the first feeder_emptying iteration as its first feed left it,
    the pile by the hopper's outlet, before the vibrations that centre it, beside the tray
    after them; the latter checked against the recorded poses of its first check. Returns
    its caption (None: nothing to draw)."""
    exp = file.first_of(FEEDER_EMPTYING)
    if exp is None or exp.id not in summary.experiments:
        return None
    unit = plan(file, exp, summary.experiments)[0]
    rows = _rows(run_dir, 'parts', exp.id)
    dose = FeederPolicy(unit.feeder).decide(0, 0).feed
    with World(SceneSpec(unit.container, file.part, 1, unit.seed)) as world:
        ids, report = world.drop(dose, zone='feeder')
        fed = world.render(*SIZE, **camera(unit))
        for move in file.moves:
            world.vibrate(move)
        after = world.render(*SIZE, **camera(unit))
        recorded = {int(r['part_id']) for r in rows if r['check'] == '0'}
        same = bool(rows) and _same_as_recorded(
            world, [r for r in rows if int(r['part_id']) in recorded], 0)
    save(os.path.join(run_dir, 'feed.png'), np.hstack([fed, after]))
    out = hopper.outlet(unit.container)
    came = ('all came out' if len(ids) == dose else
            f'{len(ids)} came out (the rest waited where the pile stood at the outlet)')
    end = '-x' if out.inward > 0 else '+x'
    return (f'Left: the tray after the first feed of `{exp.id}` iteration 1 (seed {unit.seed}): '
            f'a dose of {dose} let out of the hopper over {dose / out.rate:g} s, {came}, '
            f"{len(report.landed_ids)} spilled; the outlet is the {end} end's edge, "
            f'{out.height * 1000:g} mm up. Right: after the {len(file.moves)} moves of the '
            f'cycle (`moves`); re-simulated: poses '
            f'{"identical to" if same else "DIFFERENT from"} the recorded first check.')


def write(file: ExperimentFile, run_dir: str, more: Mapping[str, Drawer] = MappingProxyType({})
          ) -> dict[str, str]:
    """Render the pictures of a finished run, and `more` ({file name: its drawer}, drawn by a
    later room: running.resimulate's run again to the move that spilled); returns {file name:
    caption}, also written to pictures.json for the report."""
    summary = summary_model.read(os.path.join(run_dir, 'summary.json'))
    captions: dict[str, str] = {}
    for name, draw in (('bin.png', bin_picture), ('tray.png', tray_picture),
                       ('feed.png', feed_picture), *more.items()):
        caption = draw(file, summary, run_dir, captions)
        if caption:
            captions[name] = caption
    validators: dict[tuple, Validator] = {}     # per setup: the file's and its grippers'
    for exp in file.experiments:
        if exp.id in summary.experiments:
            setup = file.for_experiment(exp).setup
            if setup.key() not in validators:
                validators[setup.key()] = Validator(setup)
            validator = validators[setup.key()]
            caption = placeability_picture(validator, _rows(run_dir, 'parts', exp.id), exp.id,
                                           run_dir)
            if caption:
                captions['stopped_placeability.png'] = caption
                break
    with open(os.path.join(run_dir, 'pictures.json'), 'w', encoding='utf-8') as f:
        json.dump(captions, f, indent=2)
    return captions
