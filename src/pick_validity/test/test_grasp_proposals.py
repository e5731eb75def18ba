"""Grasps proposed from a part's geometry: they close on the part where the user would, and
what `run --check` prints of them reads back as the same grasps."""

import os

import numpy as np
from pick_common.errors import InvalidArgument
from pick_common.parts.geometry import build_part
from pick_common.parts.spec import PartSpec
from pick_validity.grasp_fit import check_grasps_fit
from pick_validity.grasp_proposals import as_yaml, JAW_MARGIN, propose
from pick_validity.grasps import GraspPose
from pick_validity.grippers import SuctionCup
from pick_validity.suction import lift
import pytest
import trimesh
import yaml

STEP = os.path.join(os.path.dirname(__file__), '..', '..', 'experiment_manager', 'config',
                    'parts', 'TO-220-3_Vertical.step')


def test_kicads_to220_gets_grasps_across_its_width_and_thickness_at_its_mass_centre():
    part = build_part(PartSpec(model='mesh', mesh_path=STEP, mass=0.002))
    proposals = propose(part)
    check_grasps_fit(part, [p.grasp for p in proposals])        # every one closes on it
    by_name = {p.grasp.name: p for p in proposals}
    # lying on its tab side or its back, jaws across the 10.25 mm width; on its edges,
    # across the 4.46 mm thickness
    for name in ('up+y_close+x', 'up-y_close+x'):
        assert by_name[name].width == pytest.approx(0.01025, abs=1e-5)
        assert by_name[name].grasp.jaw_opening == pytest.approx(0.01025 + 2 * JAW_MARGIN,
                                                                abs=1e-5)
    for name in ('up+x_close+y', 'up-x_close+y'):
        assert by_name[name].width == pytest.approx(0.00446, abs=1e-5)
    for p in proposals:      # at the mass centre, to the 0.01 mm a person reads
        assert np.allclose(p.grasp.grasp_point, part.mass_frame[0], atol=5e-6)
        assert p.grasp.jaw_opening * 1e5 == pytest.approx(round(p.grasp.jaw_opening * 1e5))


def test_a_round_body_is_closed_across_its_axis(tmp_path):
    # a 5 x 11 mm cylinder, its axis along x, its origin 20 mm away: no flat faces to close
    # across but its ends; the jaws close across the round body too, lying on its side (any
    # roll: one up axis) and standing on its ends
    body = trimesh.creation.cylinder(radius=0.0025, height=0.011, sections=32)
    body.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, [0, 1, 0]))
    body.apply_translation([0.02, 0.0, 0.0])
    body.export(tmp_path / 'cylinder.stl')
    part = build_part(PartSpec(model='mesh', mesh_path=str(tmp_path / 'cylinder.stl'),
                               mass=0.0004))
    across = [p for p in propose(part) if abs(p.grasp.closing_axis[0]) < 1e-6]
    assert across and all(p.width == pytest.approx(0.005, rel=0.01) for p in across)
    ups = sorted(tuple(np.round(p.grasp.up_axis, 6)) for p in across)
    lying = [u for u in ups if abs(u[0]) < 1e-6]
    assert lying and sorted({u for u in ups if abs(u[0]) > 0.999}) == [(-1, 0, 0), (1, 0, 0)]


def _led(path) -> PartSpec:
    """A 5 mm LED as KiCad draws it, roughly: a round body along z on a flange with a flat on
    one side, two leads below; the flat and the leads tilt its principal axes off the frame's
    by a degree or two."""
    body = trimesh.creation.cylinder(radius=0.0025, height=0.0086, sections=48)
    body.apply_translation([0, 0, 0.0053])
    ring = [(0.0029 * np.cos(a), 0.0029 * np.sin(a)) for a in np.linspace(0, 2 * np.pi, 48,
                                                                            endpoint=False)]
    ring = [(min(x, 0.0025), y) for x, y in ring]            # the flat
    flange = trimesh.convex.convex_hull([(x, y, z) for x, y in ring for z in (0.0, 0.001)])
    leads = [trimesh.creation.box(extents=[0.0005, 0.0005, 0.02],
                                  transform=trimesh.transformations.translation_matrix(
                                      [x, 0.0, -0.01])) for x in (-0.00127, 0.00127)]
    trimesh.util.concatenate([body, flange, *leads]).export(path)
    return PartSpec(model='mesh', mesh_path=str(path), mass=0.0003)


def test_a_round_body_gets_one_grasp_that_turns_with_its_roll_named_as_a_person_reads(tmp_path):
    from pick_validity.config import Setup
    from pick_validity.validity import Validator
    part = build_part(_led(tmp_path / 'led.stl'))
    proposals = propose(part)
    lying = [p for p in proposals if abs(p.grasp.up_axis[2]) < 1e-9]
    across = [p for p in lying if abs(p.grasp.closing_axis[2]) < 1e-9]
    assert len(across) == 1         # not four rolls 1.6 deg off the axes
    (one,) = across
    assert 'deg' not in one.grasp.name
    assert sorted(map(abs, one.grasp.up_axis)) == [0, 0, 1]
    assert sorted(map(abs, one.grasp.closing_axis)) == [0, 0, 1]
    assert one.width == pytest.approx(0.005, rel=0.01)
    assert one.grasp.jaw_opening * 1e5 == pytest.approx(round(one.grasp.jaw_opening * 1e5))
    v = Validator(Setup(part.spec, grasps=tuple(p.grasp for p in proposals)), part)
    for p in lying:         # across the body, and on its two ends: each turns about its axis
        assert np.allclose(np.abs(v.geometry.free_axes[proposals.index(p)]), [0, 0, 1])


def test_the_printed_yaml_reads_back_as_the_same_grasps():
    part = build_part(PartSpec(model='mesh', mesh_path=STEP, mass=0.002))
    proposals = propose(part)
    read = yaml.safe_load('\n'.join(as_yaml(proposals)))['grasps']
    assert [g['name'] for g in read] == [p.grasp.name for p in proposals]
    for g, p in zip(read, proposals, strict=True):
        back = GraspPose(g['name'], tuple(g['up_axis']), tuple(g['closing_axis']),
                         g['jaw_opening_mm'] / 1000, tuple(v / 1000 for v in g['grasp_point_mm']))
        assert np.allclose(back.up_axis, p.grasp.up_axis, atol=1e-4)
        assert np.allclose(back.closing_axis, p.grasp.closing_axis, atol=1e-4)
        assert back.jaw_opening == pytest.approx(p.grasp.jaw_opening, abs=1e-5)
        assert np.allclose(back.grasp_point, p.grasp.grasp_point, atol=1e-5)


def test_a_cup_whose_vacuum_cannot_lift_the_part_is_refused_without_a_search():
    """KiCad's TO-220 at 2 g gets the 4 mm cup's grasps; at 20 g the cup's 0.754 N cannot lift
    it (it needs about 1.19 N) at any grasp: refused at once, saying the forces, where the
    search for a seal ran every offset of every way it lies, then for three smaller cups, and
    said no flat patch took the cup."""
    cup = SuctionCup(cup_diameter=0.004)
    assert cup.propose(build_part(PartSpec(model='mesh', mesh_path=STEP, mass=0.002)))
    heavy = build_part(PartSpec(model='mesh', mesh_path=STEP, mass=0.02))
    force, needed = lift(heavy, cup)
    assert force < needed
    with pytest.raises(InvalidArgument) as err:
        cup.propose(heavy)
    assert err.value.field == 'gripper.cup_diameter'
    assert f'vacuum force of {force:.3g} N where the part (20 g) needs {needed:.3g} N' \
        in str(err.value)
