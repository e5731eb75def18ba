"""What a user says about a part: a built-in model's name or a CAD file, its size and material,
with the limits each value must keep, and the length units a CAD file may be in. Pure: no mesh
stack."""

from collections.abc import Mapping
from dataclasses import dataclass, field
import os

from ..errors import Limit
from .materials import body_values, Contact, PART_ON_PART, PART_ON_SURFACE

# Largest part accepted: a sanity limit well above small parts, in metres.
MAX_PART_SIZE = 0.5
MIN_PART_SIZE = 1e-4
# Length units a mesh file may be in (the file's key `units`), in metres; and the formats that
# state their own units, which trimesh reads in metres (STEP through cascadio, glTF by its
# specification).
UNITS = {'mm': 1e-3, 'cm': 1e-2, 'm': 1.0, 'in': 0.0254}
STATED_UNITS = ('.step', '.stp', '.glb', '.gltf')
# The range of each material setting and the mesh scale, by field name (the world node's
# parameters of the same names state them).
LIMITS = {
    'part.mass': Limit(0.0, 10.0, low_open=True),                 # kg
    'part.scale': Limit(0.0, 1e3, low_open=True),                 # mesh units to m
}


@dataclass(frozen=True)
class PartSpec:
    """What a user says about a part: a model name or a mesh, its size and material.

    dimensions: overrides of the built-in model's defaults, metres (see
    `models.BUILTIN_MODELS`). mass: kg; None takes the model's default. part_on_surface,
    part_on_part: the contact materials of the part against the container's floor and walls
    and against another part (materials.Contact; the physics applies exactly these pairs).
    """

    model: str = 'radial_capacitor'
    dimensions: Mapping[str, float] = field(default_factory=dict)
    mass: float | None = None
    part_on_surface: Contact = PART_ON_SURFACE
    part_on_part: Contact = PART_ON_PART
    mesh_path: str = ''
    scale: float = 1.0


def geometry_key(spec: PartSpec) -> tuple:
    """What a part's collision geometry depends on (not its mass or friction), hashable."""
    return spec.model, tuple(sorted(spec.dimensions.items())), spec.mesh_path, spec.scale


def check_material(spec: PartSpec, default_mass: float) -> float:
    """Check the spec's contact materials (their limits, and that the physics can apply
    both pairs: materials.body_values); its mass, kg (the model's `default_mass` when it
    gives none). Raises InvalidArgument naming the field."""
    body_values(spec.part_on_surface, spec.part_on_part)
    if spec.mass is None:
        return default_mass
    return LIMITS['part.mass'].check('part.mass', spec.mass)


def states_units(path: str) -> bool:
    """Whether a mesh file states its own length units (STEP, glTF): read in metres, its scale
    is 1."""
    return os.path.splitext(path)[1].lower() in STATED_UNITS
