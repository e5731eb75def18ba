"""A part's mass from its CAD model's solids: each solid's volume (the STEP file read by
OpenCASCADE through cascadio, one mesh per colour) times the density of its material, the
leads told from the body by KiCad's colours for pins.

KiCad's 3D library colours every model from one table of named colours (the
kicad-packages3D-generator's `shaderColors`): its pins are "metal grey pins" (0.824, 0.820,
0.781) or "gold pins" (0.859, 0.738, 0.496), in sRGB; cascadio writes them in linear light,
(165, 163, 146) and (182, 131, 54) of 255 (checked on KiCad's DIP-8 and pin header). A solid
of either colour is a lead; every other solid is the body.

The densities, g/cm^3, each with where it comes from (`assumed` where no document gives it
for the part's material):
- leads: copper, 8.96 (CRC Handbook of Chemistry and Physics, density of the elements);
  through-hole leads are tinned copper or copper alloy, whose densities lie within 3 % of it,
  or copper-clad steel (about 8.2).
- bodies, by the family of the model (its library folder and name): `BODY_DENSITIES`.
"""

from collections.abc import Sequence
from dataclasses import dataclass
import os
import re
import tempfile

import numpy as np
import trimesh

from ..errors import MeshError
from .meshes import quietly

G_CM3 = 1000.0          # kg/m^3 per g/cm^3
LEAD_COLOURS = ((165, 163, 146), (182, 131, 54))
COLOUR_SLACK = 6        # of 255: cascadio's rounding of the linear colour
LEADS = ('copper', 8.96, 'CRC Handbook of Chemistry and Physics, density of the elements')


@dataclass(frozen=True)
class BodyDensity:
    """The body's material for models whose library folder or file name matches `pattern`."""
    pattern: str
    family: str
    material: str
    density: float          # g/cm^3
    source: str             # where the density comes from; 'assumed: ...' with the basis


# First match wins; the last row catches every other model.
BODY_DENSITIES: tuple[BodyDensity, ...] = (
    BodyDensity(r'CP_(Radial|Axial)', 'aluminium electrolytic capacitor',
                'aluminium can, paper and electrolyte', 1.4,
                'assumed: an aluminium can (2.70) about a wound paper and electrolyte roll '
                '(about 1.1), filled about a quarter by the can'),
    BodyDensity(r'C_Disc|C_Rect', 'ceramic disc capacitor', 'barium titanate ceramic in epoxy',
                3.0, 'assumed: a barium titanate disc (about 5.5) in its dipped epoxy coat '
                '(about 1.2), about half of each'),
    BodyDensity(r'Resistor_THT|R_Axial', 'axial resistor', 'alumina core with lacquer', 2.5,
                'assumed: an alumina core (3.95) with end caps, under a lacquer coat (about '
                '1.2), about half of each'),
    BodyDensity(r'Diode_THT.*DO-3[45]|D_DO-3[45]', 'glass diode', 'glass', 2.5,
                'assumed: soda-lime glass, 2.4 to 2.6'),
    BodyDensity(r'Package_DIP|Package_TO_SOT_THT|Diode_THT|LED_THT|Crystal|Oscillator|'
                r'Potentiometer|Inductor', 'moulded package', 'filled epoxy moulding compound',
                1.9, 'assumed: silica-filled epoxy moulding compound, 1.8 to 2.0'),
    BodyDensity(r'TerminalBlock', 'terminal block', 'polyamide 66 with a brass clamp', 1.6,
                'assumed: a polyamide 66 housing (1.14) about a brass clamp and screw (8.5)'),
    BodyDensity(r'Connector_Dsub', 'D-sub connector', 'steel shell on a filled polyester insert',
                2.5, 'assumed: a glass-filled polyester insert (1.5) in a tinned steel shell '
                '(7.85)'),
    BodyDensity(r'Connector|Socket|PinHeader|PinSocket', 'connector or socket',
                'glass-filled polyester', 1.5, 'assumed: glass-filled PBT, 1.4 to 1.6'),
    BodyDensity(r'.', 'other part', 'filled epoxy', 1.9,
                "assumed: the moulded package's, for a model of no known family"),
)


def body_density(model_path: str) -> BodyDensity:
    """The body's row of BODY_DENSITIES for a model file (its folder and name)."""
    where = os.path.join(os.path.basename(os.path.dirname(model_path)),
                         os.path.basename(model_path))
    return next(row for row in BODY_DENSITIES if re.search(row.pattern, where))


@dataclass(frozen=True)
class SolidMass:
    """A model's mass from its solids: kg, and its account (volumes in m^3)."""
    mass: float
    lead_volume: float
    body_volume: float
    body: BodyDensity

    @property
    def lead_mass(self) -> float:
        return self.lead_volume * LEADS[1] * G_CM3

    @property
    def body_mass(self) -> float:
        return self.body_volume * self.body.density * G_CM3

    def account(self) -> str:
        """One line: the mass and how it was got."""
        return (f"{self.mass * 1000:.3g} g from the model's solids: leads "
                f'{self.lead_volume * 1e9:.1f} mm^3 of {LEADS[0]} ({LEADS[1]:g} g/cm^3, '
                f'{LEADS[2]}) {self.lead_mass * 1000:.3g} g, body {self.body_volume * 1e9:.1f} '
                f'mm^3 of {self.body.material} ({self.body.density:g} g/cm^3, '
                f'{self.body.source}) {self.body_mass * 1000:.3g} g')


def _is_lead(colour: Sequence[int]) -> bool:
    return any(max(abs(int(c) - k) for c, k in zip(colour[:3], lead, strict=True)) <= COLOUR_SLACK
               for lead in LEAD_COLOURS)


def solid_mass(path: str) -> SolidMass:
    """The mass of the STEP model at `path` from its solids' volumes and BODY_DENSITIES.
    MeshError when the file cannot be converted or holds no volume."""
    import cascadio  # OpenCASCADE: loaded only where a STEP file is read

    fd, glb = tempfile.mkstemp(suffix='.glb')
    os.close(fd)
    try:    # OpenCASCADE prints its complaints on the process's streams: kept off them
        code, failed, _ = quietly(lambda: cascadio.step_to_glb(
            path, glb, merge_primitives=True, include_materials=True))
        scene = trimesh.load(glb, force='scene') if failed is None and code == 0 else None
    except Exception as exc:    # trimesh's many errors on a bad file
        failed = exc
    finally:
        os.remove(glb)
    if failed is not None:
        raise MeshError('part.mesh_path', path, f'could not be read for its solids: {failed}')
    if scene is None or not scene.geometry:
        raise MeshError('part.mesh_path', path, 'holds no solids to weigh')
    to_metres = {'meters': 1.0, 'm': 1.0, 'millimeters': 1e-3, 'mm': 1e-3}.get(
        scene.units or 'meters', 1.0)
    lead = body = 0.0
    for mesh in scene.dump():           # each geometry placed by the scene's transforms
        with np.errstate(invalid='ignore', divide='ignore'):    # a sliver's centre: 0 / 0
            volume = abs(float(mesh.volume)) * to_metres ** 3
        colour = getattr(getattr(mesh.visual, 'material', None), 'baseColorFactor', None)
        if colour is not None and _is_lead(np.asarray(colour)):
            lead += volume
        else:
            body += volume
    if lead + body <= 0.0:
        raise MeshError('part.mesh_path', path, 'has solids of no volume')
    row = body_density(path)
    mass = (lead * LEADS[1] + body * row.density) * G_CM3
    return SolidMass(mass=mass, lead_volume=lead, body_volume=body, body=row)
