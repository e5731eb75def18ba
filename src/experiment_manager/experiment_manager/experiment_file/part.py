"""The part section of an experiment file: a built-in model or the user's CAD file, its
material, its grasps and how it is placed, in SI units; and its geometry, with the check that
each grasp's jaws close on it, every error named by the file's keys."""

from dataclasses import fields, MISSING, replace
import os
from typing import Any

from pick_common.errors import InvalidArgument
from pick_common.parts.geometry import build_part, PartGeometry
from pick_common.parts.materials import body_values, Contact, DEFAULT_BASIS, SOURCE
from pick_common.parts.spec import PartSpec, states_units, UNITS
from pick_validity.check_geometry import build_geometry
from pick_validity.config import PlaceSpec, Setup
from pick_validity.grippers import check_grasps, GripperKind, KINDS

from . import schema
from .errors import checked as checked_as
from .model import G, MM

AUTO = 'auto'       # part.grasps: proposed from the geometry


def mesh_file(p: schema.Part, base_dir: str) -> tuple[str, float]:
    """A mesh part's file (absolute) and its scale to metres: 1 for a file that states its
    units (STEP, glTF), else from `units` or `mesh_scale`, one of which is required."""
    if not p.mesh:
        raise InvalidArgument('part.mesh', p.mesh, 'is required when model is mesh')
    mesh = os.path.normpath(os.path.join(base_dir, os.path.expanduser(p.mesh)))
    if not os.path.isfile(mesh):
        raise InvalidArgument('part.mesh', mesh, 'does not exist or is not a file')
    if p.units is not None and p.mesh_scale is not None:
        raise InvalidArgument('part.mesh_scale', p.mesh_scale,
                              f'and part.units ({p.units}) say the same: give one of them')
    if states_units(mesh):
        given = 'units' if p.units is not None else 'mesh_scale' if p.mesh_scale else ''
        if given:
            raise InvalidArgument(f'part.{given}', getattr(p, given),
                                  f'is not read for {os.path.basename(mesh)}: the file states '
                                  'its own units')
        return mesh, 1.0
    if p.units is None and p.mesh_scale is None:
        raise InvalidArgument('part.units', None, f'is required for {os.path.basename(mesh)}, '
                              f'which states no units: one of {", ".join(UNITS)} (or '
                              'part.mesh_scale, the factor to metres)')
    return mesh, UNITS[p.units] if p.units is not None else p.mesh_scale


def contact(pair: Any) -> Contact:
    """A pair of the materials section in SI units."""
    return Contact(lateral_friction=pair.lateral_friction,
                   rolling_friction=MM * pair.rolling_friction_mm,
                   spinning_friction=MM * pair.spinning_friction_mm,
                   restitution=pair.restitution)


def material_account(m: schema.MaterialsSection
                     ) -> tuple[tuple[str, tuple[tuple[str, str], ...], str], ...]:
    """Per pair, how each value was got (materials.BASES, by Contact field) and where the
    values come from, as the report says them. A value the file leaves to its default has
    the default's basis (materials.DEFAULT_BASIS); one the file gives, the pair's `basis` for
    it, else 'not said'. The source: the pair's `source`; the defaults' (materials.SOURCE)
    when the file gives none of the pair's values; else that they were given without one."""
    out = []
    for pair in ('part_on_surface', 'part_on_part'):
        section = getattr(m, pair)
        given = section.model_fields_set - {'source', 'basis'}
        bases = tuple(
            (field, (section.basis.get(key, section.basis.get('*', 'not said'))
                     if key in given else DEFAULT_BASIS[field]))
            for key, field in schema.FIELD_OF.items())
        if section.source:
            said = section.source
        elif not given:
            said = f'the defaults: {SOURCE}'
        else:
            said = 'given in the file, its source not said (materials.<pair>.source)'
        out.append((pair, bases, said))
    return tuple(out)


def read_part(p: schema.Part, m: schema.MaterialsSection, base_dir: str
              ) -> tuple[PartSpec, PlaceSpec]:
    """The part's spec (its contact materials from `m`) and its placing, in SI units (its
    grasps: `grasps_for`, once the gripper is known)."""
    mesh, scale, mass = '', 1.0, G * p.mass_g
    if p.model == 'mesh':
        if mass == 0.0:
            raise InvalidArgument('part.mass_g', 0, 'is required (> 0) for a mesh part')
        mesh, scale = mesh_file(p, base_dir)
        # no defaults taken from the built-in capacitor for a part of the user's own
        if p.grasps is None:
            raise InvalidArgument('part.grasps', None, 'are required for a mesh part: the '
                                  "grasp poses, each with its grasp_point_mm in the file's "
                                  "frame, or 'auto' for those proposed from its geometry "
                                  '(run --check prints them, to paste and edit)')
        if 'seat_offset_mm' not in p.place.model_fields_set:
            raise InvalidArgument('part.place.seat_offset_mm', None, 'is required for a mesh '
                                  "part: how far its seating plane lies from the file's "
                                  'origin along place.axis')
    else:
        for key in ('mesh', 'units', 'mesh_scale'):
            if getattr(p, key) not in (None, ''):
                raise InvalidArgument(f'part.{key}', getattr(p, key), f'is only read when '
                                      f'model is mesh (model is {p.model})')
    if 'pins_per_row' in p.dimensions_mm:
        raise InvalidArgument('part.dimensions_mm.pins_per_row',
                              p.dimensions_mm['pins_per_row'],
                              'is a count, not a length: give it as part.pins_per_row')
    dimensions: dict[str, float] = {k: MM * v for k, v in p.dimensions_mm.items()}
    if p.pins_per_row is not None:
        dimensions['pins_per_row'] = p.pins_per_row
    spec = PartSpec(
        model=p.model, dimensions=dimensions, mass=mass or None,
        part_on_surface=contact(m.part_on_surface), part_on_part=contact(m.part_on_part),
        mesh_path=mesh, scale=scale)
    body_values(spec.part_on_surface, spec.part_on_part)     # a pair Bullet cannot apply
    place = PlaceSpec(place_axis=p.place.axis, seat_offset=MM * p.place.seat_offset_mm)
    return spec, place


# A grasp's keys in the file: per field of a written grasp (pick_validity.grasps), its key and
# the factor from the file's unit to SI.
GRASP_KEYS = {'up_axis': ('up_axis', 1.0), 'closing_axis': ('closing_axis', 1.0),
              'jaw_opening': ('jaw_opening_mm', MM), 'grasp_point': ('grasp_point_mm', MM)}


def grasps_for(value, gripper: GripperKind, geometry: PartGeometry, setup: Setup,
               where: str = 'part.grasps') -> tuple:
    """The grasps a gripper picks the part with, as the file gives them at `where` (`value`:
    a list of schema.GraspEntry, AUTO, or None for the kind's defaults), each read as the
    gripper's kind reads a grasp, checked, and holding the part as the kind requires
    (`check_held`). `setup`: the rest of the setup they are checked in. The one resolution of
    the file's own grasps and of each named gripper's."""
    if value == AUTO:
        grasps = proposed(geometry, gripper, where)
    elif value is None:
        grasps = gripper.default_grasps
        if not grasps:
            raise InvalidArgument(where, None, f'is required with {gripper.description} (the '
                                  "default grasps are the jaws' for a capacitor): give each "
                                  f"grasp's {_keys(gripper)}, or auto")
    else:
        grasps = tuple(grasp_entry(g, i, gripper, where) for i, g in enumerate(value))
        names = [g.name for g in grasps]
        if len(set(names)) != len(names):
            raise InvalidArgument(where, names, 'has a grasp name twice')
    checked_as(lambda g: check_grasps(g, gripper), list(grasps), where)
    check_held(geometry, replace(setup, gripper=gripper, grasps=grasps), where)
    return grasps


def _keys(gripper: GripperKind) -> str:
    return ' and '.join(GRASP_KEYS[f.name][0] for f in fields(gripper.written)
                        if f.name in GRASP_KEYS)


def grasp_entry(g: schema.GraspEntry, i: int, gripper: GripperKind,
                where: str = 'part.grasps'):
    """One entry of part.grasps as the gripper's kind reads it (its written grasp's fields:
    a suction grasp gives no closing_axis and no jaw_opening_mm, a jaws' grasp both)."""
    name = g.name if g.name is not None else f'grasp_{i}'
    wanted = {f.name: f.default is MISSING for f in fields(gripper.written) if f.name != 'name'}
    values = {}
    for field, (key, factor) in GRASP_KEYS.items():
        given = getattr(g, key)
        if field not in wanted:
            if given is not None:
                raise InvalidArgument(
                    f'{where}[{i}].{key} (grasp {name!r})', given,
                    f'is not a key of a grasp of {gripper.description} (gripper.type: '
                    f'{gripper.kind}; its grasps give {_keys(gripper)})')
            continue
        if given is None:
            if wanted[field]:
                others = [k for k in KINDS.values()
                          if field not in {f.name for f in fields(k.written)}]
                raise InvalidArgument(f'{where}[{i}].{key} (grasp {name!r})', None,
                                      f'is required with {gripper.description} (gripper.type: '
                                      f'{gripper.kind})' + ''.join(
                                          f"; a grasp without it is {k.description}'s: set "
                                          f'gripper.type: {k.kind}' for k in others))
            continue
        values[field] = tuple(factor * v for v in given) if field == 'grasp_point' else \
            given if factor == 1.0 else factor * given
    return gripper.written(name=name, **values)


def check_held(geometry: PartGeometry, setup: Setup, where: str = 'part.grasps') -> None:
    """The setup's grasps hold the part as its gripper's kind requires (check_geometry.
    build_geometry: a jaws' grasp closes on the part, a cup's grasp point lies on its surface,
    some cup's grasp seals and holds), a grasp named by its place in the file at `where`."""
    try:
        build_geometry(setup, geometry)
    except InvalidArgument as exc:
        parts = exc.field.split('.')
        if len(parts) == 3 and parts[0] == 'grasps':        # grasps.<name>.grasp_point
            index = next(i for i, g in enumerate(setup.grasps) if g.name == parts[1])
            raise InvalidArgument(f'{where}[{index}].grasp_point_mm (grasp {parts[1]!r})',
                                  exc.value, exc.rule.removeprefix('(mm) ')) from None
        raise InvalidArgument(exc.field.replace('grasps', where, 1), exc.value,
                              exc.rule) from None


class NoGrasp(InvalidArgument):
    """`grasps: auto` found no grasp on a part that reads: the part's geometry comes with
    the error, for `run --check` to print its account and draw its sheet all the same."""

    def __init__(self, field: str, value: object, rule: str, geometry: PartGeometry) -> None:
        super().__init__(field, value, rule)
        self.geometry = geometry


def proposed(geometry: PartGeometry, gripper: GripperKind, where: str = 'part.grasps'
             ) -> tuple:
    """`part.grasps: auto`: the grasps the gripper's kind proposes from the part's geometry;
    a core field is named with the file's key (gripper.cup_diameter_mm)."""
    try:
        return tuple(p.grasp for p in gripper.propose(geometry))
    except InvalidArgument as exc:
        field = exc.field
        if field == 'grasps':
            raise NoGrasp(where, exc.value, exc.rule.removeprefix('(mm) '), geometry) from None
        if field.startswith('gripper.'):
            key = next(k for k in gripper.KEYS if f'gripper.{k.field}' == field)
            field = f'gripper.{key.file_key}'
        raise InvalidArgument(field, exc.value, exc.rule.removeprefix('(mm) ')) from None


# The core's names of a mesh part's fields, and the file's keys for them; the core's other
# fields are named as `part (core field)`, their values in SI units.
FILE_KEYS = {'part.mesh_path': 'part.mesh', 'part.scale': 'part.mesh_scale'}


def _file_key(field: str) -> str:
    return FILE_KEYS.get(field, f'part ({field})')


def geometry(part: PartSpec) -> PartGeometry:
    """The part's geometry; a core error names the file's key."""
    try:
        return build_part(part)
    except InvalidArgument as exc:
        raise InvalidArgument(_file_key(exc.field), exc.value, exc.rule) from None
