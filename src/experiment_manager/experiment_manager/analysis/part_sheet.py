"""The part of an experiment file as the run will see it, before any run: its size, mass, mass
centre and collision pieces, and each grasp with what its jaws close on, in words (`describe`)
and as a picture sheet (`write`): the part as drawn in its file beside its collision pieces,
and per grasp the gripper at the pick (the part lying with the grasp's up axis up, the jaws
across its closing axis, the fingertips where the checks put them) and at the place (the part
turned so that place.axis points down, the gripper held as it picked, at the extreme wrist
tilts and at 0, the placing surface drawn, and each tilt said clear or hitting it).

matplotlib only (no simulator, no ROS); lengths drawn in mm, in the file's frame.
"""

import json
import os

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt
from mpl_toolkits.mplot3d.art3d import Poly3DCollection
import numpy as np
from pick_common.parts.aspects import part_aspects
from pick_common.parts.geometry import build_part
from pick_common.parts.insets import HULL_MARGIN, hull_swelling
from pick_common.parts.pieces import why_larger
from pick_common.parts.primitives import Hull
from pick_common.parts.spec import states_units
from pick_validity.geometry import (
    BoxShape,
    CylinderShape,
    part_shapes,
    place,
    Shape,
    support,
    turn_onto,
)
from pick_validity.grasp_proposals import as_yaml, Proposal
from pick_validity.grippers import KINDS
from pick_validity.validity import Validator
import trimesh

from ..experiment_file import ExperimentFile
from ..experiment_file.kinds import kind_of

MM = 1000.0
PIECE_COLOURS = ('#4c72b0', '#dd8452', '#55a868', '#c44e52', '#8172b3', '#937860')


def validator(file: ExperimentFile) -> Validator:
    """The file's checks as a run builds them: its part's geometry, grasps and gripper."""
    return Validator(file.setup, build_part(file.part))


def describe(file: ExperimentFile, checks: Validator) -> list[str]:
    """What the run will use of the file's part and grasps (as `checks`, the file's
    `validator`, holds them), one fact a line."""
    part = checks.geometry.part
    lines = part_lines(part)
    spec = file.part
    account = {pair: (dict(bases), said) for pair, bases, said in file.material_account}
    for pair, where in (('part_on_surface', "on the container's floor and walls"),
                        ('part_on_part', 'against another part')):
        c = getattr(spec, pair)
        bases, said = account.get(pair, ({}, 'the file'))
        figures = ', '.join(
            f'{label} {getattr(c, field) * scale:g}{unit} ({bases.get(field, "not said")})'
            for label, field, scale, unit in (
                ('friction', 'lateral_friction', 1, ''),
                ('rolling arm', 'rolling_friction', MM, ' mm'),
                ('spinning arm', 'spinning_friction', MM, ' mm'),
                ('restitution', 'restitution', 1, '')))
        lines.append(f'  contact {where} (materials.{pair}, as the physics applies it): '
                     f'{figures}; from {said}')
    lines += aspect_lines(part)
    lines += grasp_lines(file, checks)
    if file.auto_grasps:
        gripper = checks.geometry.gripper
        lines.append('  the grasps are part.grasps: auto, proposed from the geometry '
                     f'({gripper.proposal_rule}); to edit them, paste these under part: in '
                     'place of grasps: auto')
        used = tuple(Proposal(g, width) for g, width in zip(
            file.grasps, gripper.proposed_widths(checks.geometry), strict=True))
        lines += ['  ' + line for line in as_yaml(used)]
    return lines


def aspect_lines(part) -> list[str]:
    """The aspects a part (PartGeometry) can rest on, a line each."""
    return ["  aspects it can rest on (a drop test's `measured` names them), each with the "
            "outward normal of its face in the file's frame and its quasi-static share:"] + [
        f'    {a.name}: ({", ".join(f"{v:.2f}" for v in a.normal)}), '
        f'{100 * a.quasi_static:.1f} %' for a in part_aspects(part)]


def part_lines(part) -> list[str]:
    """The part (a PartGeometry) as the run reads it: its file, size, mass, mass centre
    and collision pieces, one fact a line."""
    spec = part.spec
    lo, hi = part.visual.bounds * MM
    lines = []
    if spec.model == 'mesh':
        units = 'stated by the file, read in m' if states_units(spec.mesh_path) else \
            f'scale {spec.scale:g} to m'
        lines.append(f'part: {spec.mesh_path} ({units}; {len(part.visual.faces)} triangles, '
                     f'{"closed" if part.visual.is_watertight else "not closed"})')
    else:
        lines.append(f'part: built-in {spec.model}')
    lines.append(f'  size {" x ".join(f"{v:.2f}" for v in hi - lo)} mm; in its frame x '
                 f'{lo[0]:.2f} to {hi[0]:.2f}, y {lo[1]:.2f} to {hi[1]:.2f}, z {lo[2]:.2f} to '
                 f'{hi[2]:.2f} mm')
    centre = part.mass_centre
    lines.append(f'  mass {part.mass * 1000:g} g, volume {part.volume * 1e9:.1f} mm^3; mass '
                 f'centre at ({", ".join(f"{v:.2f}" for v in centre * MM)}) mm in its frame'
                 + ('' if part.mass_frame is not None else ' (the frame origin: a built-in)'))
    hulls = [p for p in part.primitives if isinstance(p, Hull)]
    if hulls:
        together = sum(_hull_volume(h) for h in hulls)
        over = 100 * (together / part.volume - 1)
        lines.append(f'  collision: {len(hulls)} convex piece(s) of '
                     f'{", ".join(str(len(h.vertices)) for h in hulls)} vertices, '
                     f'{together * 1e9:.1f} mm^3 together, {over:+.1f} '
                     f"% on the part's volume (pieces that overlap count twice)")
        lines.append(f'    made as: {part.collision_note}')
        if why := why_larger(together, part.volume):
            lines.append(f'    {why}')
        swollen = hull_swelling(part)
        lines.append("    in the physics: each piece inset by pybullet's "
                     f'{HULL_MARGIN * MM:g} mm margin, so that it collides this surface'
                     + (f'; pieces thinner than {2 * HULL_MARGIN * MM:g} mm stay swollen by up '
                        f'to {swollen * MM:.2f} mm (docs/physics.md)' if swollen > 1e-6 else
                        ' (its edges rounded by the margin)'))
    else:
        lines.append(f'  collision: {len(part.primitives)} piece(s) (boxes and cylinders)')
    return lines


def grasp_lines(file: ExperimentFile, checks: Validator) -> list[str]:
    """The gripper's own lines (its kind's account: a suction cup's sizes; the jaws are said
    in the file's keys), then a line per grasp (grasp_figures)."""
    return checks.geometry.gripper.account() + [_grasp_line(figures) for figures in
                                                grasp_figures(file, checks)]


def named_grippers(file: ExperimentFile, checks: Validator
                   ) -> list[tuple[str, ExperimentFile, Validator]]:
    """The file's `grippers` its experiments name, in the order they first do: (name, the
    file as such an experiment runs it, its checks on the same part)."""
    out, seen = [], set()
    for exp in file.experiments:
        if exp.gripper and exp.gripper not in seen:
            seen.add(exp.gripper)
            mine = file.for_experiment(exp)
            out.append((exp.gripper, mine, Validator(mine.setup, checks.geometry.part)))
    return out


def grasp_figures(file: ExperimentFile, checks: Validator) -> list[dict]:
    """Per grasp, what the check computed of it before any scene, mm: where it is, and what
    its gripper's kind computed of it (`figures`: for jaws what they close on and whether
    they turn on a round body; for a suction cup its seal and holding)."""
    geometry = checks.geometry
    part = geometry.part
    centre = part.mass_centre
    out = []
    for k, (g, grasp) in enumerate(zip(file.grasps, geometry.grasps, strict=True)):
        item = {'name': g.name, 'up_axis': [float(v) for v in g.up_axis],
                'grasp_point_mm': [round(float(v) * MM, 3) for v in g.grasp_point],
                'from_mass_centre_mm': round(float(np.linalg.norm(grasp.point - centre)) * MM,
                                             3)}
        item.update(geometry.gripper.figures(geometry, k, g))
        out.append(item)
    return out


def _grasp_line(f: dict) -> str:
    at = (f'at ({", ".join(f"{v:.2f}" for v in f["grasp_point_mm"])}) mm, '
          f'{f["from_mass_centre_mm"]:.2f} mm from the mass centre, up {f["up_axis"]}')
    return KINDS[f['gripper']].figures_line(f, at)


def write_check(file: ExperimentFile, checks: Validator, path: str) -> str:
    """`run --check --output DIR`'s DIR/check.json: the part's account (describe's lines)
    and, per grasp, its figures and verdicts (grasp_figures)."""
    with open(path, 'w', encoding='utf-8') as f:
        json.dump({'file': file.path, 'part': describe(file, checks),
                   'grasps': grasp_figures(file, checks),
                   'grippers': {name: grasp_figures(mine, theirs)
                                for name, mine, theirs in named_grippers(file, checks)}},
                  f, indent=1)
    return path


def _hull_volume(primitive) -> float:
    return float(trimesh.Trimesh(primitive.vertices, primitive.faces, process=False).volume)


def _shape_mesh(shape: Shape, rotation: np.ndarray, centre: np.ndarray) -> trimesh.Trimesh:
    """A validity shape as a mesh, placed with `rotation` (3, 3) and `centre` (3,)."""
    if isinstance(shape, BoxShape):
        mesh = trimesh.creation.box(extents=2.0 * shape.half)
    elif isinstance(shape, CylinderShape):
        mesh = trimesh.creation.cylinder(radius=shape.radius, height=2.0 * shape.half_length,
                                         sections=24)
    else:
        mesh = trimesh.convex.convex_hull(shape.vertices)
    transform = np.eye(4)
    transform[:3, :3], transform[:3, 3] = rotation, centre
    return mesh.copy().apply_transform(transform)


def _draw(ax, mesh: trimesh.Trimesh, view: np.ndarray, colour: str, alpha: float) -> None:
    triangles = np.einsum('ij,ntj->nti', view, mesh.triangles) * MM
    ax.add_collection3d(Poly3DCollection(triangles, facecolor=colour, edgecolor='none',
                                         alpha=alpha))


def _frame(ax, points: np.ndarray, title: str) -> None:
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre, half = (lo + hi) / 2, max((hi - lo).max() / 2, 1.0)
    for axis, c in zip('xyz', centre, strict=True):
        getattr(ax, f'set_{axis}lim')(c - half, c + half)
        getattr(ax, f'set_{axis}label')(f'{axis} mm', fontsize=7)
    ax.set_box_aspect((1, 1, 1))
    ax.tick_params(labelsize=6)
    ax.set_title(title, fontsize=8)


def clearance(validator: Validator, g: int, relative: np.ndarray) -> float:
    """How far (m) the gripper of grasp `g`, holding the part at `relative` (its rotation in
    the part frame), stays on its side of the seating plane once the part is placed: negative
    where it reaches past it, as the placeability check decides (clear when positive)."""
    geo = validator.geometry
    point = geo.grasps[g].point[None]
    return min(float(geo.seat_offset - support(shape, *place(shape, relative[None], point),
                                               geo.place_axis)[0])
               for shape in geo.gripper_shapes[g])


def draw_place(ax, validator: Validator, g: int, relatives: list[np.ndarray],
               tilts: list[float], title: str) -> list[str]:
    """The part turned to its place orientation (place.axis down) on the placing surface
    (yellow), with the gripper of grasp `g` holding it at each of `relatives` (its rotations
    in the part frame, at wrist `tilts`, rad): green where it clears the surface, red where
    it reaches past it. Returns the words per tilt ('+0 deg hits')."""
    part = validator.geometry.part
    visual, grasp = part.visual, validator.geometry.grasps[g]
    view = turn_onto(validator.geometry.place_axis, np.array([0.0, 0.0, -1.0]))
    _draw(ax, visual, view, '#999999', 0.7)
    points = [view @ visual.vertices.T]
    words = []
    for relative, tilt in zip(relatives, tilts, strict=True):
        clear = clearance(validator, g, relative) > 0
        for shape in validator.geometry.gripper_shapes[g]:
            rot, centre = place(shape, relative[None], grasp.point[None])
            mesh = _shape_mesh(shape, rot[0], centre[0])
            _draw(ax, mesh, view, '#55a868' if clear else '#c44e52', 0.15)
            points.append(view @ mesh.vertices.T)
        words.append(f'{np.degrees(tilt):+.0f} deg {"clear" if clear else "hits"}')
    pts = np.hstack(points).T
    seat = (view @ (validator.geometry.place_axis * validator.geometry.seat_offset))[2]
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    plane = np.array([[lo[0], lo[1], seat], [hi[0], lo[1], seat], [hi[0], hi[1], seat],
                      [lo[0], hi[1], seat]]) * MM
    ax.add_collection3d(Poly3DCollection([plane], facecolor='#e8c547', alpha=0.35))
    _frame(ax, np.vstack([pts * MM, plane]), title + 'tilt ' + ', '.join(words))
    return words


def write(checks: Validator, path: str) -> str:
    """Draw the sheet of the file's `validator` into `path` (PNG); returns `path`."""
    geometry = checks.geometry
    part, grasps = geometry.part, geometry.grasps
    rows = 1 + len(grasps)
    fig = plt.figure(figsize=(8.0, 3.4 * rows))
    visual = part.visual
    _part_row(fig, rows, part)
    tilts = geometry.tilts
    shown = sorted({0, len(tilts) - 1, int(np.abs(tilts).argmin())})
    for g, grasp in enumerate(grasps):
        # pick: the part with the grasp's up axis up and its closing axis along x
        pick = np.stack([grasp.closing, np.cross(grasp.up, grasp.closing), grasp.up])
        ax = fig.add_subplot(rows, 2, 3 + 2 * g, projection='3d')
        _draw(ax, visual.copy().apply_translation(-grasp.point), pick, '#999999', 0.7)
        points = [pick @ (visual.vertices - grasp.point).T]
        for shape in geometry.gripper_shapes[g]:
            mesh = _shape_mesh(shape, shape.rotation, shape.center)
            _draw(ax, mesh, np.eye(3), '#4c72b0', 0.25)
            points.append(mesh.vertices.T)
        # what the gripper's kind marks at a pick (a cup's rim: green where it seals)
        for marks, ok in geometry.gripper.pick_marks(geometry, g):
            line = (pick @ (marks - grasp.point).T).T * MM
            ax.plot(*np.vstack([line, line[:1]]).T, color='#55a868' if ok else '#c44e52',
                    linewidth=1.5)
        _frame(ax, np.hstack(points).T * MM,
               f'{grasp.name}: pick\n{geometry.gripper.pick_caption(geometry, g)}')
        # place: the part turned so that place.axis points down; gripper as it picked
        ax = fig.add_subplot(rows, 2, 4 + 2 * g, projection='3d')
        relatives = [pick.T @ trimesh.transformations.rotation_matrix(tilts[k], [1, 0, 0])[:3, :3]
                     for k in shown]
        draw_place(ax, checks, g, relatives, [tilts[k] for k in shown],
                   f'{grasp.name}: place (yellow: the surface)\n')
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def _part_row(fig, rows: int, part) -> None:
    """The sheet's first row: the part as drawn in its file, and its collision pieces."""
    visual = part.visual
    ax = fig.add_subplot(rows, 2, 1, projection='3d')
    _draw(ax, visual, np.eye(3), '#999999', 0.6)
    ax.scatter(*np.zeros(3), color='k', s=12)
    if part.mass_frame is not None:
        ax.scatter(*(part.mass_frame[0] * MM), color='r', s=18)
    _frame(ax, visual.vertices * MM, 'as drawn in its file\n(black: origin, red: mass centre)')
    ax = fig.add_subplot(rows, 2, 2, projection='3d')
    for i, shape in enumerate(part_shapes(part)):
        _draw(ax, _shape_mesh(shape, shape.rotation, shape.center), np.eye(3),
              PIECE_COLOURS[i % len(PIECE_COLOURS)], 0.55)
    _frame(ax, visual.vertices * MM, f'what the physics and the checks collide:\n'
           f'{len(part.primitives)} convex piece(s)')


def write_part(part, path: str) -> str:
    """The sheet's first row alone, for a part with no grasp yet: `path` (PNG)."""
    fig = plt.figure(figsize=(8.0, 3.4))
    _part_row(fig, 1, part)
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def write_aspects(part, path: str) -> str:
    """Draw each aspect of `part` (a PartGeometry): the part resting on it on a plate, named
    as a drop test names it, with its quasi-static share, in the drop chart's order."""
    aspects = part_aspects(part)
    cols = min(len(aspects), 4)
    rows = -(-len(aspects) // cols)
    fig = plt.figure(figsize=(2.4 * cols, 2.5 * rows))
    for k, a in enumerate(aspects):
        ax = fig.add_subplot(rows, cols, k + 1, projection='3d')
        mesh = part.visual.copy()
        mesh.apply_transform(trimesh.geometry.align_vectors(a.normal, (0.0, 0.0, -1.0)))
        mesh.apply_translation(-mesh.bounds[0] * (0.0, 0.0, 1.0))
        lo, hi = mesh.bounds * MM
        edge = 0.15 * (hi - lo).max()
        plate = np.array([[lo[0] - edge, lo[1] - edge, 0], [hi[0] + edge, lo[1] - edge, 0],
                          [hi[0] + edge, hi[1] + edge, 0], [lo[0] - edge, hi[1] + edge, 0]])
        ax.add_collection3d(Poly3DCollection([plate], facecolor='#e8d88a', alpha=0.3))
        light = np.clip(mesh.face_normals @ (0.3, -0.5, 0.8), 0.0, 1.0)[:, None]
        ax.add_collection3d(Poly3DCollection(
            mesh.triangles * MM, edgecolor='none',
            facecolor=(0.35 + 0.65 * light) * matplotlib.colors.to_rgb(PIECE_COLOURS[0])))
        ax.view_init(elev=25, azim=-60)
        _frame(ax, np.vstack([plate, mesh.vertices * MM]),
               f'{a.name}: quasi-static {100 * a.quasi_static:.1f} %')
        ax.set_axis_off()
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def write_account(file: ExperimentFile, run_dir: str) -> None:
    """The part's account for a run's report: `part.json` (describe's lines) and `part.png`
    (the sheet), in the run directory; with a drop test, `aspects.png` (write_aspects)."""
    checks = validator(file)
    with open(os.path.join(run_dir, 'part.json'), 'w', encoding='utf-8') as f:
        json.dump(describe(file, checks), f, indent=1)
    write(checks, os.path.join(run_dir, 'part.png'))
    if any(kind_of(e).names_aspects for e in file.experiments):
        write_aspects(checks.geometry.part, os.path.join(run_dir, 'aspects.png'))
