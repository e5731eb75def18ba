"""The part section of an experiment file: a built-in model or the user's CAD file, its
material, its grasps and how it is placed, in SI units; and its geometry, with the check that
each grasp's jaws close on it, every error named by the file's keys."""

import os
from typing import Any

from pick_common.errors import InvalidArgument
from pick_common.parts.geometry import build_part, PartGeometry
from pick_common.parts.materials import body_values, Contact, DEFAULT_BASIS, SOURCE
from pick_common.parts.spec import PartSpec, states_units, UNITS
from pick_validity.check_geometry import build_geometry
from pick_validity.config import (
    CAPACITOR_GRASPS,
    check_grasps,
    GraspPose,
    Gripper,
    is_suction,
    PlaceSpec,
    Setup,
    SuctionCup,
    SuctionGrasp,
)
from pick_validity.grasp_fit import check_grasps_fit
from pick_validity.grasp_proposals import propose, propose_suction
from pick_validity.suction import OFF_SURFACE, seal

from . import schema
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


def read_part(p: schema.Part, m: schema.MaterialsSection, base_dir: str, suction: bool = False
              ) -> tuple[PartSpec, tuple[GraspPose, ...] | tuple[SuctionGrasp, ...] | str,
                         PlaceSpec]:
    """The part's spec (its contact materials from `m`), its grasps (AUTO when the file
    leaves them to `proposed`; a suction cup's when `suction`) and its placing, in SI
    units."""
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
    if p.grasps is None:
        if suction:
            raise InvalidArgument('part.grasps', None, 'is required with a suction cup (the '
                                  "default grasps are jaws' for a capacitor): give each "
                                  "grasp's up_axis and grasp_point_mm, or auto")
        return spec, CAPACITOR_GRASPS, place
    if p.grasps == AUTO:
        return spec, AUTO, place
    grasps = tuple(grasp_entry(g, i, suction) for i, g in enumerate(p.grasps))
    names = [g.name for g in grasps]
    if len(set(names)) != len(names):
        raise InvalidArgument('part.grasps', names, 'has a grasp name twice')
    return spec, grasps, place


def grasp_entry(g: schema.GraspEntry, i: int, suction: bool) -> GraspPose | SuctionGrasp:
    """One entry of part.grasps as the gripper's type reads it: a suction grasp gives no
    closing_axis and no jaw_opening_mm, a jaws' grasp both."""
    name = g.name if g.name is not None else f'grasp_{i}'
    point = tuple(MM * v for v in g.grasp_point_mm)
    jaws_keys = [k for k in ('closing_axis', 'jaw_opening_mm') if getattr(g, k) is not None]
    if suction:
        if jaws_keys:
            raise InvalidArgument(f'part.grasps[{i}].{jaws_keys[0]} (grasp {name!r})',
                                  getattr(g, jaws_keys[0]), "is a jaws' key, and the "
                                  'gripper is type: suction (a suction grasp is up_axis and '
                                  "grasp_point_mm: where the cup's centre touches)")
        return SuctionGrasp(name=name, up_axis=g.up_axis, grasp_point=point)
    missing = [k for k in ('closing_axis', 'jaw_opening_mm') if getattr(g, k) is None]
    if missing:
        raise InvalidArgument(f'part.grasps[{i}].{missing[0]} (grasp {name!r})', None,
                              'is required with parallel jaws (gripper.type: jaws); a grasp '
                              "without it is a suction cup's: set gripper.type: suction")
    return GraspPose(name=name, up_axis=g.up_axis, closing_axis=g.closing_axis,
                     jaw_opening=MM * g.jaw_opening_mm, grasp_point=point)


def check_cup(geometry: PartGeometry, setup: Setup) -> None:
    """A suction cup's grasps: each one's point lies on the part's surface, named by its
    place in the file; at least one seals and holds (build_geometry names each one's
    reason). The seals are the check geometry's, computed once; only when it refuses the
    setup are they computed here, so that a point off the surface is the error said."""
    cup, grasps = setup.gripper, setup.grasps
    try:
        seals = build_geometry(setup, geometry).seals
        refused = None
    except InvalidArgument as exc:
        seals = tuple(seal(geometry, cup, c) for c in check_grasps(grasps, cup))
        refused = InvalidArgument(f'part.{exc.field}', exc.value, exc.rule)
    for i, (g, found) in enumerate(zip(grasps, seals, strict=True)):
        if found.reason.startswith(OFF_SURFACE):
            raise InvalidArgument(f'part.grasps[{i}].grasp_point_mm (grasp {g.name!r})',
                                  [round(v / MM, 3) for v in g.grasp_point], found.reason)
    if refused is not None:
        raise refused


def proposed(geometry: PartGeometry, gripper: Gripper | SuctionCup | None = None
             ) -> tuple[GraspPose, ...] | tuple[SuctionGrasp, ...]:
    """`part.grasps: auto`: the grasps proposed from the part's geometry for the gripper's
    type (a suction cup's: grasp_proposals.propose_suction)."""
    if gripper is not None and is_suction(gripper):
        try:
            return tuple(p.grasp for p in propose_suction(geometry, gripper))
        except InvalidArgument as exc:      # the core's field, in the file's mm
            raise InvalidArgument(f'{exc.field}_mm', exc.value,
                                  exc.rule.removeprefix('(mm) ')) from None
    grasps = tuple(p.grasp for p in propose(geometry))
    if not grasps:
        raise InvalidArgument('part.grasps', AUTO, 'found no grasp: the part has no opposed '
                              'faces and no round body across its mass centre; write its '
                              'grasps')
    return grasps


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


def check_fits(geometry: PartGeometry, grasps: tuple[GraspPose, ...]) -> None:
    """Every grasp closes on the part (grasp_fit), named by its place in the file."""
    try:
        check_grasps_fit(geometry, grasps)
    except InvalidArgument as exc:
        name = exc.field.split('.')[1]
        index = next(i for i, g in enumerate(grasps) if g.name == name)
        raise InvalidArgument(f'part.grasps[{index}].grasp_point_mm (grasp {name!r})',
                              exc.value, exc.rule.removeprefix('(mm) ')) from None
