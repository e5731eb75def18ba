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
from pick_common.parts.primitives import Hull
from pick_common.parts.spec import states_units
from pick_validity.config import VACUUM_SOURCE
from pick_validity.geometry import (
    BoxShape,
    CylinderShape,
    part_shapes,
    place,
    Shape,
    support,
    turn_onto,
)
from pick_validity.grasp_proposals import as_yaml, JAW_MARGIN, Proposal
from pick_validity.validity import Validator
import trimesh

from ..experiment_file import ExperimentFile

MM = 1000.0
PIECE_COLOURS = ('#4c72b0', '#dd8452', '#55a868', '#c44e52', '#8172b3', '#937860')


def validator(file: ExperimentFile) -> Validator:
    """The file's checks as a run builds them: its part's geometry, grasps and gripper."""
    return Validator(file.setup, build_part(file.part))


def describe(file: ExperimentFile, checks: Validator) -> list[str]:
    """What the run will use of the file's part and grasps (as `checks`, the file's
    `validator`, holds them), one fact a line."""
    part = checks.part
    spec = file.part
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
    centre = part.mass_frame[0] if part.mass_frame is not None else np.zeros(3)
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
        swollen = hull_swelling(part)
        lines.append("    in the physics: each piece inset by pybullet's "
                     f'{HULL_MARGIN * MM:g} mm margin, so that it collides this surface'
                     + (f'; pieces thinner than {2 * HULL_MARGIN * MM:g} mm stay swollen by up '
                        f'to {swollen * MM:.2f} mm (docs/physics.md)' if swollen > 1e-6 else
                        ' (its edges rounded by the margin)'))
    else:
        lines.append(f'  collision: {len(part.primitives)} piece(s) (boxes and cylinders)')
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
    lines.append("  aspects it can rest on (a drop test's `measured` names them), each with the "
                 "outward normal of its face in the file's frame and its quasi-static share:")
    lines += [f'    {a.name}: ({", ".join(f"{v:.2f}" for v in a.normal)}), '
              f'{100 * a.quasi_static:.1f} %' for a in part_aspects(part)]
    lines += grasp_lines(file, checks)
    if file.auto_grasps and checks.suction:
        lines.append('  the grasps are part.grasps: auto, proposed from the geometry (per way '
                     'the part can lie, the cup on its top where it seals and holds nearest '
                     'the mass centre); to edit them, paste these under part: in place of '
                     'grasps: auto')
        used = tuple(Proposal(g, s.deviation) for g, s in zip(file.grasps, checks.seals,
                                                              strict=True))
        lines += ['  ' + line for line in as_yaml(used)]
    elif file.auto_grasps:
        lines.append('  the grasps are part.grasps: auto, proposed from the geometry (across '
                     'opposed faces and round bodies at the mass centre, jaws '
                     f'{JAW_MARGIN * MM:g} mm wider than the part each side); to edit them, '
                     'paste these under part: in place of grasps: auto')
        used = tuple(Proposal(g, fit.width) for g, fit in zip(file.grasps, checks.grasp_fits,
                                                              strict=True))
        lines += ['  ' + line for line in as_yaml(used)]
    return lines


def grasp_lines(file: ExperimentFile, checks: Validator) -> list[str]:
    """A suction cup's line (the jaws are said in the file's keys), then a line per grasp
    (grasp_figures)."""
    lines = []
    if checks.suction:
        cup = checks.gripper
        lines.append(f'  gripper: a suction cup {cup.cup_diameter * MM:g} mm across and '
                     f'{cup.cup_height * MM:g} mm high on a {cup.body_diameter * MM:g} x '
                     f'{cup.body_length * MM:g} mm body, {cup.vacuum / 1000:g} kPa, safety '
                     f'factor {cup.safety_factor:g}, {cup.acceleration:g} m/s^2, cup friction '
                     f'{cup.cup_friction:g} (defaults: {VACUUM_SOURCE})')
    return lines + [_grasp_line(figures) for figures in grasp_figures(file, checks)]


def named_grippers(file: ExperimentFile, checks: Validator
                   ) -> list[tuple[str, ExperimentFile, Validator]]:
    """The file's `grippers` its experiments name, in the order they first do: (name, the
    file as such an experiment runs it, its checks on the same part)."""
    out, seen = [], set()
    for exp in file.experiments:
        if exp.gripper and exp.gripper not in seen:
            seen.add(exp.gripper)
            mine = file.for_experiment(exp)
            out.append((exp.gripper, mine, Validator(mine.setup, checks.part)))
    return out


def grasp_figures(file: ExperimentFile, checks: Validator) -> list[dict]:
    """Per grasp, what the check computed of it before any scene, mm: for jaws what they
    close on and whether they turn on a round body; for a suction cup its seal (true or
    false, the reason), the rim's deviation from a plane against the cup's give, the force
    margin and the distance of the grasp point from the mass centre's line."""
    part = checks.part
    centre = part.mass_frame[0] if part.mass_frame is not None else np.zeros(3)
    out = []
    for k, (g, grasp) in enumerate(zip(file.grasps, checks.grasps, strict=True)):
        item = {'name': g.name, 'up_axis': [float(v) for v in g.up_axis],
                'grasp_point_mm': [round(float(v) * MM, 3) for v in g.grasp_point],
                'from_mass_centre_mm': round(float(np.linalg.norm(grasp.point - centre)) * MM,
                                             3)}
        if checks.suction:
            found, held = checks.seals[k], checks.holds[k]
            item.update({
                'gripper': 'suction', 'seal': found.ok, 'reason': found.reason,
                'deviation_mm': None if np.isnan(found.deviation) else
                round(found.deviation * MM, 4), 'give_mm': round(found.give * MM, 4),
                'holding_force_n': round(held.force, 4), 'needed_n': round(held.needed, 4),
                'force_margin': round(held.margin, 3), 'holds': held.ok,
                'off_axis_mm': round(held.offset * MM, 3),
                'used': bool(checks.usable[k])})
        else:
            fit, axis = checks.grasp_fits[k], checks.free_axes[k]
            item.update({
                'gripper': 'jaws', 'closing_axis': [float(v) for v in g.closing_axis],
                'jaw_opening_mm': round(g.jaw_opening * MM, 3),
                'problem': fit.problem(), 'closes_on_mm': round(fit.width * MM, 3),
                'span_mm': None if fit.span is None else [round(-fit.span[0] * MM, 3),
                                                          round(fit.span[1] * MM, 3)],
                'round_axis': [round(float(v), 3) for v in axis] if axis.any() else None})
        out.append(item)
    return out


def _grasp_line(f: dict) -> str:
    at = (f'at ({", ".join(f"{v:.2f}" for v in f["grasp_point_mm"])}) mm, '
          f'{f["from_mass_centre_mm"]:.2f} mm from the mass centre, up {f["up_axis"]}')
    if f['gripper'] == 'suction':
        seal = ('seals: its rim and the surface inside lie within '
                f'{f["deviation_mm"]:.2f} mm of a plane (the cup gives {f["give_mm"]:.2f})'
                if f['seal'] else f'does not seal: {f["reason"]}')
        force = (f'holds {f["holding_force_n"]:.3f} N against {f["needed_n"]:.3f} N needed, '
                 f'margin {f["force_margin"]:.2f} with the moment of the mass centre '
                 f'{f["off_axis_mm"]:.2f} mm off the cup\'s axis'
                 + ('' if f['holds'] else ': does not hold'))
        used = '' if f['used'] else '; never used by the check'
        return f'  grasp {f["name"]!r}: cup {at}: {seal}; {force}{used}'
    what = f['problem'] or (f'closes on {f["closes_on_mm"]:.2f} mm of part '
                            f'({f["span_mm"][0]:.2f} and {f["span_mm"][1]:.2f} mm either side '
                            'of the grasp point)')
    roll = (f'; round there, so it grips at any roll about {f["round_axis"]}'
            if f['round_axis'] else '; fixed to the part (not across a round body)')
    return (f'  grasp {f["name"]!r}: jaws open {f["jaw_opening_mm"]:.2f} mm {at}, closing '
            f'{f["closing_axis"]}: {what}{roll}')


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
    point = validator.grasps[g].point[None]
    return min(float(validator.seat_offset - support(shape, *place(shape, relative[None], point),
                                                     validator.place_axis)[0])
               for shape in validator.gripper_shapes[g])


def draw_place(ax, validator: Validator, g: int, relatives: list[np.ndarray],
               tilts: list[float], title: str) -> list[str]:
    """The part turned to its place orientation (place.axis down) on the placing surface
    (yellow), with the gripper of grasp `g` holding it at each of `relatives` (its rotations
    in the part frame, at wrist `tilts`, rad): green where it clears the surface, red where
    it reaches past it. Returns the words per tilt ('+0 deg hits')."""
    part = validator.part
    visual, grasp = part.visual, validator.grasps[g]
    view = turn_onto(validator.place_axis, np.array([0.0, 0.0, -1.0]))
    _draw(ax, visual, view, '#999999', 0.7)
    points = [view @ visual.vertices.T]
    words = []
    for relative, tilt in zip(relatives, tilts, strict=True):
        clear = clearance(validator, g, relative) > 0
        for shape in validator.gripper_shapes[g]:
            rot, centre = place(shape, relative[None], grasp.point[None])
            mesh = _shape_mesh(shape, rot[0], centre[0])
            _draw(ax, mesh, view, '#55a868' if clear else '#c44e52', 0.15)
            points.append(view @ mesh.vertices.T)
        words.append(f'{np.degrees(tilt):+.0f} deg {"clear" if clear else "hits"}')
    pts = np.hstack(points).T
    seat = (view @ (validator.place_axis * validator.seat_offset))[2]
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    plane = np.array([[lo[0], lo[1], seat], [hi[0], lo[1], seat], [hi[0], hi[1], seat],
                      [lo[0], hi[1], seat]]) * MM
    ax.add_collection3d(Poly3DCollection([plane], facecolor='#e8c547', alpha=0.35))
    _frame(ax, np.vstack([pts * MM, plane]), title + 'tilt ' + ', '.join(words))
    return words


def write(checks: Validator, path: str) -> str:
    """Draw the sheet of the file's `validator` into `path` (PNG); returns `path`."""
    validator, part = checks, checks.part
    grasps = validator.grasps
    rows = 1 + len(grasps)
    fig = plt.figure(figsize=(8.0, 3.4 * rows))
    visual = part.visual
    # the part as drawn in its file, and its collision pieces
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
    tilts = validator.tilts
    shown = sorted({0, len(tilts) - 1, int(np.abs(tilts).argmin())})
    for g, grasp in enumerate(grasps):
        # pick: the part with the grasp's up axis up and its closing axis along x
        pick = np.stack([grasp.closing, np.cross(grasp.up, grasp.closing), grasp.up])
        ax = fig.add_subplot(rows, 2, 3 + 2 * g, projection='3d')
        _draw(ax, visual.copy().apply_translation(-grasp.point), pick, '#999999', 0.7)
        points = [pick @ (visual.vertices - grasp.point).T]
        for shape in validator.gripper_shapes[g]:
            mesh = _shape_mesh(shape, shape.rotation, shape.center)
            _draw(ax, mesh, np.eye(3), '#4c72b0', 0.25)
            points.append(mesh.vertices.T)
        if validator.suction:       # the rim where it touches the part: green seals
            found = validator.seals[g]
            rim = (pick @ (found.rim - grasp.point).T).T * MM
            ax.plot(*np.vstack([rim, rim[:1]]).T, color='#55a868' if found.ok else '#c44e52',
                    linewidth=1.5)
            title = (f'{grasp.name}: pick\ncup {grasp.jaw_opening * MM:g} mm, '
                     + ('seals' if found.ok else 'no seal'))
        else:
            title = (f'{grasp.name}: pick\njaws {grasp.jaw_opening * MM:g} mm, fingertips '
                     f'{validator.finger_depths[g] * MM:.1f} mm below the point')
        _frame(ax, np.hstack(points).T * MM, title)
        # place: the part turned so that place.axis points down; gripper as it picked
        ax = fig.add_subplot(rows, 2, 4 + 2 * g, projection='3d')
        relatives = [pick.T @ trimesh.transformations.rotation_matrix(tilts[k], [1, 0, 0])[:3, :3]
                     for k in shown]
        draw_place(ax, validator, g, relatives, [tilts[k] for k in shown],
                   f'{grasp.name}: place (yellow: the surface)\n')
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
    if any(e.type == 'drop_test' for e in file.experiments):
        write_aspects(checks.part, os.path.join(run_dir, 'aspects.png'))
