"""The staged checks on scenes whose answer is known by construction, and against the naive
all-FCL loop on settled scenes from the real world."""

import math

import numpy as np
from pick_common.containers import ContainerSpec
from pick_common.errors import InvalidArgument, UnknownPart
from pick_common.parts import build_part, PartSpec
from pick_common.specs import SceneSpec
from pick_sim_world.world import World
from pick_validity.config import CheckConfig, GraspPose, Gripper, PlaceSpec
from pick_validity.validity import (
    naive_check,
    STAGE_CANDIDACY,
    STAGE_CONTAINER,
    STAGE_NEIGHBOUR,
    STAGE_PLACEABILITY,
    STAGE_VALID,
    Validator,
)
import pytest
from scipy.spatial.transform import Rotation

BIN = ContainerSpec(inner_size=(0.2, 0.2, 0.03))
CAPACITOR = build_part(PartSpec())
# A lying capacitor grasped across its body from above: part +X up, closing along part Y.
SIDE = GraspPose('side', (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), 0.011)
TOP = GraspPose('top', (0.0, 0.0, 1.0), (1.0, 0.0, 0.0), 0.011, (0.0, 0.0, 0.002))
RADIUS = 0.0025   # body radius of the capacitor, m


def _validator(grasps=(SIDE,), **config) -> Validator:
    return Validator(CAPACITOR, Gripper(), grasps, PlaceSpec(), CheckConfig(**config))


def _lying(x: float, y: float, roll_deg: float = 0.0) -> np.ndarray:
    """A capacitor lying on the floor, its axis along world -X and part +X up, rolled about
    its axis by roll_deg: pose (7,)."""
    base = Rotation.from_matrix(np.column_stack([[0, 0, 1.0], [0, 1.0, 0], [-1.0, 0, 0]]))
    rotation = Rotation.from_euler('x', roll_deg, degrees=True) * base
    return np.concatenate([[x, y, RADIUS], rotation.as_quat()])


def test_lying_pose_puts_the_side_grasp_up_axis_along_z():
    pose = _lying(0, 0)
    up = Rotation.from_quat(pose[3:]).apply([1.0, 0, 0])
    axis = Rotation.from_quat(pose[3:]).apply([0, 0, 1.0])
    assert np.allclose(up, [0, 0, 1]) and np.allclose(axis, [-1, 0, 0])


@pytest.mark.parametrize(('tilt', 'candidate'), [(0.0, True), (44.0, True), (46.0, False),
                                                 (-44.0, True), (-46.0, False)])
def test_candidacy_follows_the_tolerance(tilt, candidate):
    report = _validator().check(BIN, [7], [_lying(0, 0, tilt)], neighbour_check=False)
    result = report.results[0]
    assert math.isclose(result.candidacy_angle, math.radians(abs(tilt)), abs_tol=1e-9)
    assert (result.stage != STAGE_CANDIDACY) == candidate, result.reason
    if not candidate:
        assert result.grasp_index == -1 and '45.0 deg' in result.reason


def test_the_nearest_grasp_pose_is_chosen():
    v = _validator(grasps=(TOP, SIDE))
    report = v.check(BIN, [1], [_lying(0, 0, 30.0)], neighbour_check=False)
    assert report.results[0].grasp_index == 1
    assert math.isclose(report.results[0].candidacy_angle, math.radians(30))


def test_placement_hits_the_surface_at_some_tilts_and_not_others():
    v = _validator()
    placeable = v.placeable[0]
    # Tilt 0: the 20 mm body reaches 10 mm along the part's -Z, past the seat at 5.5 mm.
    assert not placeable[np.argmin(np.abs(v.tilts))]
    # A tilt a about the closing axis (part Y) turns the gripper axis to cos(a) X - sin(a) Z:
    # negative tilts lean the body away from the seat (part -Z), positive ones into it.
    assert placeable[0] and not placeable[-1]
    assert math.isclose(v.tilts[0], -math.pi / 4) and math.isclose(v.tilts[-1], math.pi / 4)
    # A gripper as thin as the part clears it upright and at more tilts (its 75 mm reach still
    # crosses the seat once tilted 5 deg into it); a huge jaw never clears it.
    thin = Validator(CAPACITOR, Gripper(body_diameter=0.004, jaw_depth=0.004), [SIDE],
                     PlaceSpec())
    assert thin.placeable[0][np.argmin(np.abs(v.tilts))]
    assert thin.placeable[0].sum() > placeable.sum()
    wide = Validator(CAPACITOR, Gripper(jaw_depth=0.05), [SIDE], PlaceSpec())
    assert not wide.placeable[0].any()
    report = wide.check(BIN, [1], [_lying(0, 0)], neighbour_check=False)
    assert report.results[0].stage == STAGE_PLACEABILITY


def test_a_part_in_the_middle_is_valid_and_against_a_wall_is_not():
    v = _validator()
    y_wall = BIN.inner_size[1] / 2 - RADIUS          # touching the +Y wall
    report = v.check(BIN, [1, 2], [_lying(0, 0), _lying(0, y_wall)], neighbour_check=False)
    middle, wall = report.results
    assert middle.stage == STAGE_VALID and middle.valid_tilts
    assert wall.stage == STAGE_CONTAINER and 'container' in wall.reason
    # The gripper pose of a valid part: at its grasp point, z tilted from vertical.
    assert np.allclose(middle.gripper_pose[:3], [0, 0, RADIUS])


def test_touching_neighbours_block_the_grasp_and_distant_ones_do_not():
    v = _validator()
    close = [_lying(0, 0), _lying(0, 2 * RADIUS + 0.0002)]   # side by side along the closing axis
    far = [_lying(0, 0), _lying(0, 0.06)]
    for poses, expected in ((close, STAGE_NEIGHBOUR), (far, STAGE_VALID)):
        report = v.check(BIN, [1, 2], poses, targets=[1])
        assert report.results[0].stage == expected, report.results[0].reason
    blocked = v.check(BIN, [1, 2], close, targets=[1]).results[0]
    assert 'parts [2]' in blocked.reason
    # The static bin analysis skips the neighbour stage.
    assert v.check(BIN, [1, 2], close, targets=[1], neighbour_check=False).results[0].valid


def test_counts_per_stage():
    v = _validator()
    poses = [_lying(0, 0), _lying(0, 0.06, 60.0), _lying(0, BIN.inner_size[1] / 2 - RADIUS)]
    report = v.check(BIN, [1, 2, 3], poses)
    assert report.counts == {'checked': 3, 'candidates': 2, 'placeable': 2,
                             'container_free': 1, 'valid': 1}


@pytest.mark.parametrize(('container', 'model', 'count'), [
    (ContainerSpec.tray(), 'radial_capacitor', 60),
    (ContainerSpec(inner_size=(0.15, 0.15, 0.026)), 'radial_capacitor', 150),
    (ContainerSpec.tray(), 'to220', 40),
    (ContainerSpec.tray(), 'dip', 40),
], ids=['tray-capacitor', 'bin-capacitor', 'tray-to220', 'tray-dip'])
def test_fast_check_equals_the_naive_loop_on_settled_scenes(container, model, count):
    with World(SceneSpec(container, PartSpec(model=model), seed=4)) as world:
        world.drop(count)
        state = world.snapshot()
        part = world.part
    grasps = [GraspPose(f'{s}{a}', u, c, 0.014) for s, a, u, c in (
        ('+', 'x', (1, 0, 0), (0, 1, 0)), ('-', 'x', (-1, 0, 0), (0, 1, 0)),
        ('+', 'y', (0, 1, 0), (1, 0, 0)), ('-', 'y', (0, -1, 0), (1, 0, 0)),
        ('+', 'z', (0, 0, 1), (1, 0, 0)), ('-', 'z', (0, 0, -1), (1, 0, 0)))]
    v = Validator(part, Gripper(), grasps, PlaceSpec(seat_offset=0.003))
    for neighbours in (False, True):
        fast = v.check(container, state.ids, state.poses, neighbour_check=neighbours)
        naive = naive_check(v, container, state.ids, state.poses, neighbour_check=neighbours)
        assert [r.key() for r in fast.results] == [r.key() for r in naive.results]
        assert fast.queries < naive.queries
    stages = {r.stage for r in fast.results}
    assert len(stages) >= 3, f'a scene that exercises several stages, got {stages}'


def test_mesh_parts_are_checked_with_their_hulls(tmp_path):
    import trimesh
    mesh = trimesh.util.concatenate([trimesh.creation.box(extents=[0.006, 0.004, 0.002]),
                                     trimesh.creation.box(extents=[0.001, 0.001, 0.006],
                                                          transform=trimesh.transformations
                                                          .translation_matrix([0, 0, -0.004]))])
    path = tmp_path / 'clip.stl'
    mesh.export(path)
    spec = PartSpec(model='mesh', mesh_path=str(path), mass=0.0002)
    with World(SceneSpec(ContainerSpec.tray(), spec, seed=2)) as world:
        world.drop(40)
        state = world.snapshot()
        part = world.part
    v = Validator(part, Gripper(), [GraspPose('flat', (0, 0, 1), (1, 0, 0), 0.01)],
                  PlaceSpec(seat_offset=0.001))
    fast = v.check(ContainerSpec.tray(), state.ids, state.poses)
    naive = naive_check(v, ContainerSpec.tray(), state.ids, state.poses)
    assert [r.key() for r in fast.results] == [r.key() for r in naive.results]


# ----------------------------------------------------------------------------- bad input
@pytest.mark.parametrize(('poses', 'rule'), [
    ([[0, 0, math.nan, 0, 0, 0, 1]], r'parts\[0\] \(id 5\).pose: .* must be finite'),
    ([[0, 0, 0, 0, 0, math.inf, 1]], r'parts\[0\] \(id 5\).pose: .* must be finite'),
    ([[0, 0, 0, 0, 0, 0, 0.5]], r'parts\[0\] \(id 5\).pose.orientation: .* has norm 0.5'),
    ([[0, 0, 0, 0, 0, 0, 0]], r'has norm 0'),
    ([[1.3e154, 0, 0, 0, 0, 0, 1]], r'parts\[0\] \(id 5\).pose.position: .* must be within '
                                    r'10 m of the instance frame'),     # found by fuzzing
    (np.zeros((1, 5)), r'parts: \(1, 5\) must be \(1, 7\) poses'),
])
def test_bad_poses_are_refused_before_fcl(poses, rule):
    ids = [5] if len(poses) else []
    with pytest.raises(InvalidArgument, match=rule):
        _validator().check(BIN, ids, np.array(poses, dtype=float))


def test_quaternions_off_by_float_noise_are_normalised():
    pose = _lying(0, 0)
    pose[3:] *= 1.0005
    assert _validator().check(BIN, [1], [pose], neighbour_check=False).results[0].valid


def test_empty_duplicate_and_unknown_ids_are_refused():
    v = _validator()
    with pytest.raises(InvalidArgument, match='parts: .* is empty'):
        v.check(BIN, [], np.zeros((0, 7)))
    with pytest.raises(InvalidArgument, match='parts: 3 id appears twice'):
        v.check(BIN, [3, 3], [_lying(0, 0), _lying(0, 0.05)])
    with pytest.raises(UnknownPart, match='target_ids: 9 is not among the parts sent'):
        v.check(BIN, [3], [_lying(0, 0)], targets=[9])


@pytest.mark.parametrize(('grasp', 'rule'), [
    (GraspPose('z', (0, 0, 0), (1, 0, 0), 0.01), r'grasps.z.up_axis: .* is a zero vector'),
    (GraspPose('p', (1, 0, 0), (1, 0.01, 0), 0.01), r'grasps.p.closing_axis: .* is parallel'),
    (GraspPose('n', (1, 0, 0), (0, 1, 0), math.nan), r'grasps.n.jaw_opening: nan'),
    (GraspPose('o', (1, 0, 0), (0, 1, 0), 0.0), r'grasps.o.jaw_opening: 0.0 must be > 0'),
])
def test_bad_grasps_are_refused(grasp, rule):
    with pytest.raises(InvalidArgument, match=rule):
        _validator(grasps=(grasp,))


def test_an_unnamed_bad_grasp_is_named_by_its_index():
    with pytest.raises(InvalidArgument, match=r'grasps\[1\].up_axis'):
        _validator(grasps=(SIDE, GraspPose('', (0, 0, 0), (1, 0, 0), 0.01)))


@pytest.mark.parametrize(('config', 'rule'), [
    (dict(tolerance=0.0), 'check.tolerance: 0.0 must be > 0'),
    (dict(tolerance=2.0), 'check.tolerance: 2.0 must be <= 1.5708'),
    (dict(tolerance=math.nan), 'check.tolerance: nan must be finite'),
    (dict(tilt_min=0.5, tilt_max=0.1), 'check.tilt_max: 0.1 must be >= 0.5'),
    (dict(tilt_step=1e-4), 'check.tilt_step'),
])
def test_bad_check_settings_are_refused(config, rule):
    with pytest.raises(InvalidArgument, match=rule):
        _validator(**config)


def test_bad_gripper_and_placement_are_refused():
    with pytest.raises(InvalidArgument, match='gripper.body_diameter: -0.02 must be > 0'):
        Validator(CAPACITOR, Gripper(body_diameter=-0.02), [SIDE], PlaceSpec())
    with pytest.raises(InvalidArgument, match='place.place_axis: .* is a zero vector'):
        Validator(CAPACITOR, Gripper(), [SIDE], PlaceSpec(place_axis=(0, 0, 0)))
