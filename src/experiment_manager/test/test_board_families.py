"""`grasps: auto` on KiCad's own 3D models of the common through-hole families
(config/boards/3dmodels and config/parts, kicad-packages3d 6.0.10): the jaws close across each
part's body at the size its package drawing gives, and the cup seals where the part has a flat
top as wide as the cup, or is refused naming its diameter where it has none. Each part is built
from its STEP file as a board's part is (mass from its solids)."""

import os

import numpy as np
from pick_common.errors import InvalidArgument
from pick_common.parts.geometry import build_part
from pick_common.parts.solids import solid_mass
from pick_common.parts.spec import PartSpec
from pick_validity.grasp_proposals import propose, propose_suction
from pick_validity.grippers.suction_cup import SuctionCup
import pytest
from trimesh.triangles import closest_point

CONFIG = os.path.join(os.path.dirname(__file__), '..', 'config')
MODELS = os.path.join(CONFIG, 'boards', '3dmodels')
CUP = SuctionCup(cup_diameter=0.004)            # the built-in cell's cup (config/board_cell.yaml)


def _part(model: str):
    step = os.path.join(MODELS, model)
    if not os.path.exists(step):        # the TO-220 and the DIP-8 are the part files' own
        step = os.path.join(CONFIG, 'parts', os.path.basename(model))
    return build_part(PartSpec(model='mesh', mesh_path=step, mass=solid_mass(step).mass))


def _across(proposals) -> dict[tuple, list[float]]:
    """The jaws' widths (mm) by closing axis (rounded)."""
    widths: dict[tuple, list[float]] = {}
    for p in proposals:
        axis = tuple(np.round(np.abs(p.grasp.closing_axis), 2))
        widths.setdefault(axis, []).append(p.width * 1000)
    return widths


# model, {closing axis: (low, high) mm the jaws must close across}, the cup seals (True) or not,
# and where the sizes come from
FAMILIES = [
    ('LED_THT.3dshapes/LED_D5.0mm.step', {(1, 0, 0): (4.5, 5.1)}, False,
     "a 5 mm LED's round body (the model's name); its top is a dome, no flat for a 4 mm cup"),
    ('Package_TO_SOT_THT.3dshapes/TO-220-3_Vertical.step',
     {(1, 0, 0): (10.1, 10.6), (0, 1, 0): (4.2, 4.7)}, True,
     'standing TO-220: JEDEC TO-220AB body E 10.11-10.51 mm, A 4.25-4.65 mm (Vishay outline '
     'document 95222)'),
    ('Package_TO_SOT_THT.3dshapes/TO-220-3_Horizontal_TabDown.step',
     {(1, 0, 0): (10.1, 10.6), (0, 0, 1): (4.2, 4.7)}, True, 'the TO-220 lying on its tab'),
    ('Package_DIP.3dshapes/DIP-8_W7.62mm.step', {(1, 0, 0): (6.0, 7.2), (0, 0, 1): (2.9, 5.0)},
     True, 'PDIP-8: moulded width E1 0.240-0.280 in, thickness A2 0.115-0.195 in (Microchip '
     'drawing C04-018-P)'),
    ('Crystal.3dshapes/Crystal_HC49-4H_Vertical.step', {(0, 1, 0): (3.5, 4.7)}, True,
     "an HC-49/4H crystal's 4.65 mm can (the model's extent), its flat top"),
    ('Connector_PinHeader_2.54mm.3dshapes/PinHeader_1x04_P2.54mm_Vertical.step',
     {(1, 0, 0): (1.5, 2.6), (0, 1, 0): (10.0, 10.3)}, False,
     "a 1x4 header's 2.54 mm housing, 10.16 mm long; 2.54 mm leaves no flat for a 4 mm cup"),
    ('Capacitor_THT.3dshapes/CP_Axial_L10.0mm_D6.0mm_P15.00mm_Horizontal.step',
     {'round about x': (5.5, 6.1)}, False,
     "an axial electrolytic's 6 mm can (the model's name), jaws across it at any roll"),
    # the larger models take minutes each to cut and to search (-m slow)
    pytest.param('Package_DIP.3dshapes/DIP-8_W7.62mm_Socket.step', {(1, 0, 0): (10.0, 10.3)},
                 False, "a DIP-8 socket's 10.16 mm frame; no flat as wide as the cup on its top",
                 marks=pytest.mark.slow),
    pytest.param('Connector_Dsub.3dshapes/DSUB-9_Male_Vertical_P2.77x2.84mm.step',
                 {(1, 0, 0): (15.0, 30.0), (0, 1, 0): (8.0, 12.0)}, True,
                 "a D-sub 9's body under its 30.8 x 12.5 mm flange (the model's extent): "
                 'the jaws close across the body, inside the flange',
                 marks=pytest.mark.slow),
    pytest.param('TerminalBlock_Altech.3dshapes/Altech_AK300_1x02_P5.00mm_45-Degree.step',
                 {(1, 0, 0): (9.8, 10.2)}, True, 'a two-pole terminal block, 5 mm a pole',
                 marks=pytest.mark.slow),
]


@pytest.mark.parametrize('model, across, seals, source', FAMILIES,
                         ids=[os.path.basename(getattr(f, 'values', f)[0])[:-5]
                              for f in FAMILIES])
def test_the_jaws_close_across_each_familys_body_and_the_cup_seals_where_it_is_flat(
        model, across, seals, source):
    part = _part(model)
    proposals = propose(part)
    widths = _across(proposals)
    for axis, (low, high) in across.items():
        if axis == 'round about x':      # a round body: any closing axis square to its axis
            found = [p.width * 1000 for p in proposals
                     if abs(p.grasp.closing_axis[0]) < 0.05]
        else:
            found = widths.get(tuple(float(a) for a in axis), [])
        assert found, f'{model}: no grasp closing along {axis} ({source}); got {widths}'
        assert all(low <= w <= high for w in found), (model, axis, found, source)
    if seals:
        cups = propose_suction(part, CUP)
        assert cups
        # every cup grasp's point is on the part's surface
        triangles = part.visual.triangles
        for p in cups:
            point = np.tile(p.grasp.grasp_point, (len(triangles), 1))
            nearest = closest_point(triangles, point)
            assert np.linalg.norm(nearest - point, axis=1).min() < 2e-4, (model, p.grasp)
    else:
        with pytest.raises(InvalidArgument) as err:
            propose_suction(part, CUP)
        assert err.value.field == 'gripper.cup_diameter' and err.value.value == 4.0
