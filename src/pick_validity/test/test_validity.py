"""The staged checks on scenes whose answer is known by construction, and against the naive
all-FCL loop on settled scenes from the real world."""

import math

import numpy as np
from pick_common.containers import ContainerSpec
from pick_common.errors import InvalidArgument, UnknownPart
from pick_common.parts.geometry import build_part
from pick_common.parts.spec import PartSpec
from pick_common.specs import SceneSpec
from pick_sim_world.world import World
from pick_validity.config import CheckConfig, PlaceSpec, Setup
from pick_validity.grasps import GraspPose
from pick_validity.grippers import Jaws
from pick_validity.naive import naive_check
from pick_validity.results import (
    STAGE_CANDIDACY,
    STAGE_CONTAINER,
    STAGE_NEIGHBOUR,
    STAGE_OUTSIDE,
    STAGE_PLACEABILITY,
    STAGE_VALID,
)
from pick_validity.validity import Validator
import pytest
from scipy.spatial.transform import Rotation
import trimesh

BIN = ContainerSpec(inner_size=(0.2, 0.2, 0.03))
CAPACITOR = build_part(PartSpec())
# A lying capacitor grasped across its body from above: part +X up, closing along part Y.
SIDE = GraspPose('side', (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), 0.011)
TOP = GraspPose('top', (0.0, 0.0, 1.0), (1.0, 0.0, 0.0), 0.011, (0.0, 0.0, 0.002))
# The side grasp 1 mm off the body's axis: fixed to the part, so a roll tilts it.
OFF_AXIS = GraspPose('off_axis', (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), 0.011, (0.001, 0.0, 0.0))
RADIUS = 0.0025   # body radius of the capacitor, m


def _validator(grasps=(SIDE,), **config) -> Validator:
    return Validator(Setup(grasps=tuple(grasps), config=CheckConfig(**config)))


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
    # pitched about the closing axis: a tilt no turn about the round body undoes
    report = _validator().check(BIN, [7], [_tilted(tilt)], neighbour_check=False)
    result = report.results[0]
    assert math.isclose(result.candidacy_angle, math.radians(abs(tilt)), abs_tol=1e-9)
    assert (result.stage != STAGE_CANDIDACY) == candidate, result.reason
    if not candidate:
        assert result.grasp_index == -1 and '45.0 deg' in result.reason


def test_the_nearest_grasp_pose_is_chosen():
    v = _validator(grasps=(TOP, SIDE))
    report = v.check(BIN, [1], [_tilted(30.0)], neighbour_check=False)
    assert report.results[0].grasp_index == 1
    assert math.isclose(report.results[0].candidacy_angle, math.radians(30))


DEEP = ContainerSpec(inner_size=(0.2, 0.2, 0.1))
THIN = Jaws(body_diameter=0.004, jaw_depth=0.004)
FAR = PlaceSpec(seat_offset=0.5)      # a seat no gripper reaches: placeability never decides


def _tilted(pitch_deg: float, roll_deg: float = 0.0, z: float = 0.03) -> np.ndarray:
    """A lying capacitor held in the air (nothing near it), pitched by pitch_deg about its
    closing axis (world Y) after a roll of roll_deg about its body axis: pose (7,)."""
    pose = _lying(0, 0, roll_deg)
    rotation = Rotation.from_euler('y', pitch_deg, degrees=True) * Rotation.from_quat(pose[3:])
    return np.concatenate([[0, 0, z], rotation.as_quat()])


def _tilts(validator: Validator, pose: np.ndarray) -> tuple[int, tuple[int, ...]]:
    result = validator.check(DEEP, [1], [pose], neighbour_check=False).results[0]
    return result.stage, tuple(round(math.degrees(t)) for t in result.valid_tilts)


def test_placeability_depends_on_how_the_part_lies():
    # The gripper comes from above and holds the part as it lies; placing turns the pair so
    # that the part's -Z (the seat at 5.5 mm) points down. Lying flat, a tilt a leans the
    # gripper's axis by a from the part's +X towards -Z or +Z: the 20 mm body clears the seat
    # only leaning away from it (a <= -20 deg).
    v = _validator()
    stage, flat = _tilts(v, _tilted(0))
    assert stage == STAGE_VALID and flat == tuple(range(-45, -15, 5)), flat
    # Pitch the part 20 deg about the closing axis: wrist tilt a is now a - 20 or a + 20
    # relative to the part, so the placeable wrist tilts are those with a -+ 20 <= -20.
    assert _tilts(v, _tilted(20)) == (STAGE_VALID, tuple(range(-45, 5, 5)))
    assert _tilts(v, _tilted(-20)) == (STAGE_VALID, (-45, -40))
    # Pitched 30 deg the wrong way, no wrist tilt can place it: the same grasp, another answer.
    result = v.check(DEEP, [1], [_tilted(-30)], neighbour_check=False).results[0]
    assert result.stage == STAGE_PLACEABILITY and result.grasp_index == 0
    assert 'cannot be placed' in result.reason
    assert _tilts(v, _tilted(30)) == (STAGE_VALID, tuple(range(-45, 15, 5)))
    # A huge jaw never clears the seat, however the part lies.
    wide = Validator(Setup(gripper=Jaws(jaw_depth=0.05), grasps=(SIDE,)))
    assert _tilts(wide, _tilted(20))[0] == STAGE_PLACEABILITY


def test_a_regrasp_station_places_what_the_pitch_kept_from_placing(tmp_path):
    # Pitched 30 deg the wrong way the part cannot be placed as picked; put down on the
    # station (lying on its side, flat) it is picked again and placed: valid after a regrasp.
    from pick_validity.regrasp import placements
    station = Validator(Setup(grasps=(SIDE,), config=CheckConfig(regrasp_station=True)))
    assert station.geometry.placements and station.geometry.station_ok.any()
    result = station.check(DEEP, [1], [_tilted(-30)], neighbour_check=False).results[0]
    assert result.stage == STAGE_VALID and result.regrasp, result.reason
    assert result.reason.endswith('placed after a regrasp on the station')
    naive = naive_check(station.geometry, DEEP, [1], [_tilted(-30)], neighbour_check=False)
    assert naive.results[0].key() == result.key()
    # what places without it keeps its answer, and no regrasp
    flat = station.check(DEEP, [1], [_tilted(0)], neighbour_check=False).results[0]
    assert flat.stage == STAGE_VALID and not flat.regrasp
    # the station's placements keep the margin: a cube rests on each face with d / h = 1;
    # a margin over it leaves none
    trimesh.creation.box(extents=(0.01, 0.01, 0.01)).export(tmp_path / 'cube.stl')
    cube = build_part(PartSpec(model='mesh', mesh_path=str(tmp_path / 'cube.stl'), mass=0.001))
    assert [round(p.ratio, 6) for p in placements(cube, 0.1)] == [1.0] * 6
    assert placements(cube, 1.5) == ()


def test_the_gripper_stays_within_the_approach_cone():
    # A grasp off the body's axis is fixed to the part. Rolled 40 deg about its body axis,
    # the lying part's closing axis rises 40 deg: the gripper's axis leans at least 40 deg
    # from the vertical, and tilt a makes it acos(cos 40 cos a): within the 45 deg cone for
    # |a| <= 22.6 deg.
    v = Validator(Setup(gripper=THIN, grasps=(OFF_AXIS,), place=FAR))
    assert not v.geometry.free_axes.any()
    assert _tilts(v, _tilted(0))[1] == tuple(range(-45, 50, 5))
    assert _tilts(v, _tilted(0, roll_deg=40))[1] == tuple(range(-20, 25, 5))
    narrow = Validator(Setup(gripper=THIN, grasps=(OFF_AXIS,), place=FAR,
                             config=CheckConfig(approach_cone=math.radians(30))))
    result = narrow.check(DEEP, [1], [_tilted(0, roll_deg=40)], neighbour_check=False)
    assert result.results[0].stage == STAGE_CANDIDACY
    assert 'no wrist tilt approaches within 30.0 deg' in result.results[0].reason
    # The reported gripper pose is the most vertical valid one: its axis straight up.
    pose = v.check(DEEP, [1], [_tilted(30)], neighbour_check=False).results[0].gripper_pose
    assert np.allclose(Rotation.from_quat(pose[3:]).apply([0, 0, 1.0]), [0, 0, 1])


@pytest.mark.parametrize('roll', [0.0, 7.0, 20.0, 30.0, 44.0, -44.0, 130.0])
def test_jaws_across_a_round_body_grip_it_at_any_roll(roll):
    # A capacitor lying alone on the floor: a cell's camera cannot see its roll, and its jaws
    # close across the round body whatever it is. With the grasp fixed to the part, rolls
    # beyond 6 deg of a side grasp tilted the jaws into the floor
    # (studies/roll.py). The turned grasp is the side grasp nearest in roll.
    sides = [GraspPose(f'side{k}', (math.cos(k * math.pi / 2), math.sin(k * math.pi / 2), 0.0),
                       (-math.sin(k * math.pi / 2), math.cos(k * math.pi / 2), 0.0), 0.011)
             for k in range(4)]
    v = _validator(grasps=sides)
    assert np.allclose(v.geometry.free_axes, [[0, 0, 1.0]] * 4)
    result = v.check(BIN, [1], [_lying(0, 0, roll)]).results[0]
    assert result.stage == STAGE_VALID and result.candidacy_angle < 1e-6, result.reason
    assert result.grasp_index == round(roll / 90) % 4, result.grasp_index
    gripper = Rotation.from_quat(result.gripper_pose[3:])
    closing, axis = gripper.apply([1.0, 0, 0]), gripper.apply([0, 0, 1.0])
    assert abs(closing[2]) < 1e-9 and axis[2] > math.cos(math.radians(45))
    # the body stays where it lies: the jaws close on its axis, 2.5 mm above the floor
    assert np.allclose(result.gripper_pose[:3], [0, 0, RADIUS])


@pytest.mark.parametrize('roll', [0.0, 30.0, -44.0, 130.0])
def test_a_round_body_is_found_in_a_mesh(tmp_path, roll):
    # The built-in capacitor written out as an STL in mm, as a CAD tool would: its body is
    # found round from the surface, and its side grasps turn with its roll as the built-in's.
    mesh = CAPACITOR.visual.copy()
    mesh.apply_scale(1000.0)
    mesh.export(tmp_path / 'capacitor.stl')
    part = PartSpec(model='mesh', mesh_path=str(tmp_path / 'capacitor.stl'), scale=0.001,
                    mass=0.0004)
    sides = [GraspPose(f'side{k}', (math.cos(k * math.pi / 2), math.sin(k * math.pi / 2), 0.0),
                       (-math.sin(k * math.pi / 2), math.cos(k * math.pi / 2), 0.0), 0.011)
             for k in range(4)]
    v = Validator(Setup(part=part, grasps=tuple(sides)))
    assert np.allclose(np.abs(v.geometry.free_axes), [[0, 0, 1.0]] * 4)
    result = v.check(BIN, [1], [_lying(0, 0, roll)]).results[0]
    assert result.stage == STAGE_VALID and result.candidacy_angle < 1e-6, result.reason
    # off the axis, or across a square section: fixed to the part
    assert not Validator(Setup(part=part, grasps=(OFF_AXIS,))).geometry.free_axes.any()
    trimesh.creation.box((5.0, 5.0, 11.0)).export(tmp_path / 'square.stl')
    square = PartSpec(model='mesh', mesh_path=str(tmp_path / 'square.stl'), scale=0.001,
                      mass=0.0004)
    assert not Validator(Setup(part=square, grasps=(SIDE,))).geometry.free_axes.any()


def test_the_fingertips_reach_down_the_grasped_part():
    # Side grasp of a lying capacitor: the body the jaws close on (radius 2.5 mm) ends 2.5 mm
    # below its axis, so the fingertips go 2.5 mm - clearance below it; from the top, the
    # body ends 5.5 mm below its centre, where only its two leads go on (a fifth of it).
    v = _validator()
    assert v.geometry.finger_depths[0] == pytest.approx(RADIUS - 0.001, abs=1e-7)
    top = _validator(grasps=(TOP,)).geometry
    assert top.finger_depths[0] == pytest.approx(0.0055 + 0.002 - 0.001, abs=1e-7)
    # Lying 0.5 mm into the floor (as resting parts do in the physics): with no clearance the
    # fingertips, and nothing else, go through the floor at every tilt.
    sunk = _lying(0, 0)
    sunk[2] -= 0.0005
    touching = Validator(Setup(gripper=Jaws(finger_clearance=0.0), grasps=(SIDE,)))
    result = touching.check(BIN, [1], [sunk], neighbour_check=False).results[0]
    assert result.stage == STAGE_CONTAINER, result.reason
    # With the default 1 mm they stop 1.5 mm below the axis, which lies 2.0 mm above the
    # floor: they clear it straight down. Tilted by a, the 4 mm deep jaws' lower edge swings
    # to 1.5 cos a + 2 sin |a| mm below the axis: above the floor up to 10 deg, into it from
    # 15 deg. (The default 20 mm body hits the seat below 20 deg: a far seat keeps
    # placeability out of this.)
    sunk[2] -= 0.0001
    clear = Validator(Setup(gripper=THIN, grasps=(SIDE,), place=FAR))
    assert _tilts(clear, sunk) == (STAGE_VALID, (-10, -5, 0, 5, 10))


@pytest.mark.parametrize(('where', 'position', 'words'), [
    ('beside', (0.13, 0.0, RADIUS), 'beside the container'),
    ('below', (0.0, 0.0, -0.006), 'below the floor'),
    ('above', (0.0, 0.0, 0.03 + 0.025), 'more than 20 mm (check.rim_tolerance) above'),
])
def test_a_part_not_in_the_container_is_answered_outside(where, position, words):
    pose = _lying(0, 0)
    pose[:3] = position
    # The other part lies off to the side: the part outside is still an obstacle.
    report = _validator().check(BIN, [1, 2], [pose, _lying(0, 0.06)])
    outside, inside = report.results
    assert outside.stage == STAGE_OUTSIDE and not outside.valid, outside.reason
    assert words in outside.reason and 'not checked' in outside.reason
    assert inside.valid
    assert report.counts['outside'] == 1 and report.counts['checked'] == 2
    assert report.counts['candidates'] == 1
    naive = naive_check(_validator().geometry, BIN, [1, 2], [pose, _lying(0, 0.06)])
    assert [r.stage for r in naive.results] == [STAGE_OUTSIDE, STAGE_VALID]


def test_a_part_just_above_the_rim_is_still_in_the_container():
    pose = _lying(0, 0)
    pose[2] = 0.03 + 0.015        # on a heap 15 mm above the 30 mm rim
    assert _validator().check(BIN, [1], [pose], neighbour_check=False).results[0].valid


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
    pitched = _tilted(60.0)               # no grasp within 45 deg of +Z
    pitched[:3] = [0.0, 0.06, 0.02]
    poses = [_lying(0, 0), pitched, _lying(0, BIN.inner_size[1] / 2 - RADIUS)]
    report = v.check(BIN, [1, 2, 3], poses)
    assert report.counts == {'checked': 3, 'outside': 0, 'candidates': 2, 'placeable': 2,
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
    # The default gripper stops most parts at placeability or the container; a thin one
    # lets more through to the later stages.
    for gripper in (Jaws(), THIN):
        v = Validator(Setup(PartSpec(model=model), gripper=gripper, grasps=tuple(grasps),
                            place=PlaceSpec(seat_offset=0.003)), part)
        for neighbours in (False, True):
            fast = v.check(container, state.ids, state.poses, neighbour_check=neighbours)
            naive = naive_check(v.geometry, container, state.ids, state.poses,
                                neighbour_check=neighbours)
            assert [r.key() for r in fast.results] == [r.key() for r in naive.results]
            assert fast.queries < naive.queries
    stages = {r.stage for r in fast.results}
    assert len(stages) >= 3, f'a scene that exercises several stages, got {stages}'
    # with a regrasp station: its put-downs and picks again, part for part
    v = Validator(Setup(PartSpec(model=model), grasps=tuple(grasps),
                        place=PlaceSpec(seat_offset=0.003),
                        config=CheckConfig(regrasp_station=True)), part)
    fast = v.check(container, state.ids, state.poses)
    naive = naive_check(v.geometry, container, state.ids, state.poses)
    assert [r.key() for r in fast.results] == [r.key() for r in naive.results]


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
    v = Validator(Setup(spec, grasps=(GraspPose('flat', (0, 0, 1), (1, 0, 0), 0.01),),
                        place=PlaceSpec(seat_offset=0.001)), part)
    fast = v.check(ContainerSpec.tray(), state.ids, state.poses)
    naive = naive_check(v.geometry, ContainerSpec.tray(), state.ids, state.poses)
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
    (dict(approach_cone=0.0), 'check.approach_cone: 0.0 must be > 0'),
    (dict(rim_tolerance=-0.01), 'check.rim_tolerance: -0.01 must be >= 0'),
])
def test_bad_check_settings_are_refused(config, rule):
    with pytest.raises(InvalidArgument, match=rule):
        _validator(**config)


def test_bad_gripper_and_placement_are_refused():
    with pytest.raises(InvalidArgument, match='gripper.body_diameter: -0.02 must be > 0'):
        Validator(Setup(gripper=Jaws(body_diameter=-0.02), grasps=(SIDE,)))
    with pytest.raises(InvalidArgument, match='gripper.finger_clearance: nan must be finite'):
        Validator(Setup(gripper=Jaws(finger_clearance=math.nan), grasps=(SIDE,)))
    with pytest.raises(InvalidArgument, match='place.place_axis: .* is a zero vector'):
        Validator(Setup(gripper=Jaws(), grasps=(SIDE,), place=PlaceSpec(place_axis=(0, 0, 0))))
