"""The suction cup: where its rim seals on a real part's surface and where not (a hole, an
edge, a curved face, a point off the surface), what it holds, and its staged check on scenes
the real world settled, against the naive all-FCL loop."""

import math

import numpy as np
from pick_common.containers import ContainerSpec
from pick_common.errors import InvalidArgument
from pick_common.parts.geometry import build_part
from pick_common.parts.spec import PartSpec
from pick_common.specs import SceneSpec
from pick_sim_world.world import World
from pick_validity.config import PlaceSpec, Setup
from pick_validity.grasp_fit import Caster, crossings
from pick_validity.grasps import GraspPose, SuctionGrasp
from pick_validity.grippers import check_grasps, Jaws, SuctionCup
from pick_validity.naive import naive_check
from pick_validity.results import STAGE_CANDIDACY, STAGE_VALID
from pick_validity.suction import holding, OFF_SURFACE, seal
from pick_validity.validity import Validator
import pytest
import trimesh

CUP = SuctionCup()                        # 4 mm across, 3 mm high: gives 0.3 mm
MM = 1e-3


def _plate_with_a_hole(path, hole_x=(0.6, 1.4), hole_y=(-0.4, 0.4)) -> PartSpec:
    """A 20 x 20 x 2 mm plate (z from -2 to 0, its top at z = 0) with a rectangular
    through-hole, built face by face (no boolean engine), as an STL in mm."""
    outer = [(-10, -10), (10, -10), (10, 10), (-10, 10)]
    inner = [(hole_x[0], hole_y[0]), (hole_x[1], hole_y[0]), (hole_x[1], hole_y[1]),
             (hole_x[0], hole_y[1])]
    vertices = [(x, y, z) for z in (0.0, -2.0) for x, y in outer + inner]
    faces = []
    for o, i in ((0, 4), (8, 12)):         # the top and bottom annuli
        for k in range(4):
            a, b = o + k, o + (k + 1) % 4
            c, d = i + (k + 1) % 4, i + k
            faces += [(a, b, c), (a, c, d)]
    for ring in (0, 4):                               # outer and inner walls
        for k in range(4):
            a, b = ring + k, ring + (k + 1) % 4
            faces += [(a, b, b + 8), (a, b + 8, a + 8)]
    mesh = trimesh.Trimesh(np.array(vertices, float), np.array(faces), process=True)
    trimesh.repair.fix_normals(mesh)
    assert mesh.is_watertight
    mesh.export(path)
    return PartSpec(model='mesh', mesh_path=str(path), scale=MM, mass=0.0007)


def _seal(part, point_mm, up=(0, 0, 1), cup=CUP):
    (grasp,) = check_grasps([SuctionGrasp('g', up, tuple(MM * v for v in point_mm))], cup)
    return seal(part, cup, grasp)


@pytest.fixture(scope='module')
def plate(tmp_path_factory):
    return build_part(_plate_with_a_hole(tmp_path_factory.mktemp('plate') / 'plate.stl'))


def test_the_cup_seals_on_a_flat_face(plate):
    found = _seal(plate, (-5, -5, 0))
    assert found.ok and found.deviation < 1e-9
    assert np.allclose(found.rim[:, 2], 0.0, atol=1e-9)      # the rim on the plate's top
    assert np.allclose(np.linalg.norm(found.rim[:, :2] - [-0.005, -0.005], axis=1), 0.002)


def test_the_seal_is_refused_over_a_hole_inside_the_ring(plate):
    found = _seal(plate, (0, 0, 0))           # the hole 0.6 to 1.4 mm off the centre
    assert not found.ok and 'a hole or an edge lies inside the cup' in found.reason


def test_the_seal_is_refused_across_an_edge(plate):
    found = _seal(plate, (9, 0, 0))           # 1 mm from the plate's edge, the rim 2 mm out
    assert not found.ok and found.reason.startswith('the rim leaves the part')


def test_the_seal_is_refused_on_a_strongly_curved_face_and_taken_on_a_gentle_one():
    capacitor = build_part(PartSpec())        # a body 5 mm across
    across = _seal(capacitor, (2.5, 0, 0), up=(1, 0, 0))
    assert not across.ok and 'leaves its plane by 0.5' in across.reason
    assert across.deviation > across.give == pytest.approx(0.0003)
    small = _seal(capacitor, (2.5, 0, 0), up=(1, 0, 0), cup=SuctionCup(cup_diameter=0.002))
    assert small.ok and 0 < small.deviation < small.give       # a 2 mm cup on 5 mm is flat enough
    end = _seal(capacitor, (0, 0, 5.5))                           # the body's flat end
    assert end.ok


def test_a_grasp_point_off_the_surface_says_how_far(plate):
    found = _seal(plate, (-5, -5, 0.3))
    assert found.reason.startswith(OFF_SURFACE) and '-0.30 mm' in found.reason
    assert _seal(plate, (0.9, 0, -1)).reason.startswith(OFF_SURFACE)   # inside the hole


def test_the_holding_force_and_its_margin_follow_schmalz_s_load_case():
    dip = build_part(PartSpec(model='dip'))
    (top,) = check_grasps([SuctionGrasp('top', (0, 0, 1), (0, 0, 0.00165))], CUP)
    held = holding(dip, CUP, top)
    assert held.force == pytest.approx(60e3 * math.pi * 0.002 ** 2)         # 0.754 N
    assert held.needed == pytest.approx(dip.mass * (9.81 + 10.0 / 0.5) * 2.0)
    assert held.ok and held.offset == pytest.approx(0.0, abs=1e-9)
    weak = SuctionCup(cup_diameter=0.0006, vacuum=10e3)
    assert not holding(dip, weak, check_grasps([SuctionGrasp('t', (0, 0, 1),
                                                              (0, 0, 0.00165))], weak)[0]).ok
    # off the mass centre (the frame origin of a built-in) the weight's moment about the rim
    # comes in: m (g d + a h) S against the vacuum's force times the cup's radius
    off = check_grasps([SuctionGrasp('off', (0, 0, 1), (0.0045, 0, 0.00165))], CUP)[0]
    moved = holding(dip, CUP, off)
    moment = dip.mass * (9.81 * 0.0045 + 10.0 * 0.00165) * 2.0
    assert moved.offset == pytest.approx(0.0045)
    assert moved.margin == pytest.approx(held.force * 0.002 / moment)
    assert moved.margin < held.margin


def test_a_suction_grasp_with_jaws_and_a_jaws_grasp_with_a_cup_are_refused():
    with pytest.raises(InvalidArgument, match=r"grasps\.top: 'top' is a suction grasp, and "
                       r'the gripper is parallel jaws'):
        check_grasps([SuctionGrasp('top', (0, 0, 1))], Jaws())
    with pytest.raises(InvalidArgument, match=r"grasps\.side: 'side' is a jaws grasp, and the "
                       r'gripper is a suction cup'):
        check_grasps([GraspPose('side', (1, 0, 0), (0, 1, 0), 0.011)], CUP)


def test_no_grasp_that_seals_is_refused_naming_each_reason():
    with pytest.raises(InvalidArgument, match=r"hold no grasp the cup can use: 'side': the rim "
                       'leaves its plane'):
        Validator(Setup(PartSpec(), gripper=CUP,
                        grasps=(SuctionGrasp('side', (1, 0, 0), (0.0025, 0, 0)),)))


DIP_GRASPS = (SuctionGrasp('top', (0, 0, 1), (0, 0, 0.00165)),
              SuctionGrasp('bottom', (0, 0, -1), (0, 0, -0.00165)),
              SuctionGrasp('side', (1, 0, 0), (0.0047, 0, 0)))


@pytest.mark.parametrize('container, count', [(ContainerSpec.tray(), 40),
                                              (ContainerSpec(inner_size=(0.1, 0.1, 0.03)), 80)],
                         ids=['tray', 'bin'])
def test_the_cup_s_check_equals_the_naive_loop_on_settled_scenes(container, count):
    spec = PartSpec(model='dip')
    with World(SceneSpec(container, spec, seed=5)) as world:
        world.drop(count)
        state = world.snapshot()
        part = world.part
    v = Validator(Setup(spec, gripper=CUP, grasps=DIP_GRASPS,
                        place=PlaceSpec(seat_offset=0.0015)), part)
    # the body's end is 3.3 mm high: a 4 mm cup's rim leaves it
    assert [s.ok for s in v.geometry.seals] == [True, True, False]
    for neighbours in (False, True):
        fast = v.check(container, state.ids, state.poses, neighbour_check=neighbours)
        naive = naive_check(v.geometry, container, state.ids, state.poses,
                            neighbour_check=neighbours)
        assert [r.key() for r in fast.results] == [r.key() for r in naive.results]
    assert any(r.stage == STAGE_VALID for r in fast.results)
    # a DIP standing on its end: the side grasp is the nearest, and never taken
    for r in fast.results:
        if r.stage == STAGE_CANDIDACY and 'does not seal' in r.reason:
            assert "'side' at" in r.reason
        if r.grasp_index >= 0:
            assert DIP_GRASPS[r.grasp_index].name != 'side'


def test_a_caster_crosses_what_every_triangle_crosses_to_the_bit():
    """Caster tests a line only against the triangles whose shadow holds it: on a box cut
    into small triangles and a cylinder of 256 facets, lines along the axes through the
    triangles' corners and edges (where a crossing sits on the tolerance), lines whose feet lie
    on the borders of the caster's grid cells, and along a slanted direction find exactly the
    crossings of every triangle, one line at a time or many."""
    box = trimesh.creation.box(extents=(0.02, 0.012, 0.004))
    box = box.subdivide().subdivide()
    cylinder = trimesh.creation.cylinder(radius=0.003, height=0.01, sections=256)
    rng = np.random.default_rng(5)
    for mesh in (box, cylinder):
        triangles = np.asarray(mesh.triangles)
        corners = triangles.reshape(-1, 3)[:200]
        for direction in (np.array([0.0, 0.0, -1.0]), np.array([1.0, 0.0, 0.0]),
                          np.array([0.0, 1.0, 0.0]), rng.normal(size=3)):
            caster = Caster(triangles, direction)
            k = np.arange(caster._side + 1)[:, None]
            borders = (caster._corner + k * caster._cell) @ caster._axes    # feet on borders
            origins = np.concatenate([corners, (corners[:-1] + corners[1:]) / 2,
                                      rng.uniform(-0.012, 0.012, (200, 3)), borders])
            every = [crossings(triangles, origin, direction) for origin in origins]
            assert all(np.array_equal(caster.crossings(o), t)
                       for o, t in zip(origins, every, strict=True))
            batch = caster.crossings_of(origins)
            assert len(batch) == len(every)
            assert all(np.array_equal(b, t) for b, t in zip(batch, every, strict=True))
