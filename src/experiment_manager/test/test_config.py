"""The experiment file: the default parses into SI units; every kind of bad file is refused with
a message naming the field, the value and the rule."""

import dataclasses
import math
import os
import re

from ament_index_python.packages import get_package_share_directory
from experiment_manager import experiment_file
from experiment_manager.experiment_file.plan import plan
from pick_common.errors import InvalidArgument
from pick_common.specs import MOVES
import pytest

HERE = os.path.dirname(__file__)
DEFAULT = os.path.join(HERE, '..', 'config', 'default_experiment.yaml')
MINIMAL = """id: t
experiments:
  - {id: b, type: bin_static, iterations: 1, parts: 10, bins_mm: [[100, 100, 20]]}
"""
SWEEP = MINIMAL + '  - {id: g, type: gripper_sweep, iterations: 1, parts: 10, '


def test_the_default_file_parses_into_si_units():
    f = experiment_file.load(DEFAULT)
    assert f.id == 'capacitor_demo'
    assert [e.type for e in f.experiments if e.scenario is None] == list(experiment_file.TYPES)
    assert [e.id for e in f.experiments if e.scenario is not None] == [
        'feeder@materials_part_on_surface_lateral_friction_low',
        'feeder@materials_part_on_surface_lateral_friction_high']
    assert f.gripper.body_diameter == pytest.approx(0.020)
    assert f.check.tolerance == pytest.approx(math.radians(45))
    assert f.tray.inner_size == pytest.approx((0.195, 0.150, 0.027))
    assert f.moves == (MOVES['centre'], MOVES['flip']) and f.requirements.max_spilled == 0
    assert f.requirements.success_rate == 0.9
    assert f.requirements.refill_interval == 4 * 3600 and f.requirements.capacity == 60
    emptying = f.experiment('emptying')
    assert emptying.bin is None and emptying.bin_from == 'bins'
    assert f.experiment('feeder').range_from == 'sweep'
    assert f.experiment('sweep').counts == tuple(range(5, 61, 5))


def test_the_default_file_s_containers_hold_a_refill_interval_s_parts():
    # Otherwise its bin and table could never come out feasible (it once loaded 150
    # parts into a cell that needed 480).
    f = experiment_file.load(DEFAULT)
    loads = {e.id: e.parts for e in f.experiments
             if e.type in ('bin_emptying', 'feeder_emptying') and e.scenario is None}
    assert len(loads) == 2 and min(loads.values()) >= f.requirements.capacity, loads


def test_omitted_keys_take_the_documented_defaults():
    f = experiment_file.parse(MINIMAL)
    assert f.seed == 0 and f.search_order == 'top_first' and len(f.grasps) == 5
    assert f.experiments[0].bins[0].inner_size == pytest.approx((0.1, 0.1, 0.02))
    assert f.experiments[0].bins[0].wall_thickness == pytest.approx(0.003)
    # the hopper drops on a quarter of the tray's length at its -X end, 0.8 of its width
    assert f.tray.feeder_zone_center == pytest.approx((-0.073125, 0.0))
    assert f.tray.feeder_zone_size == pytest.approx((0.04875, 0.12))


def test_a_feeder_run_s_dose_reaches_its_policy():
    f = experiment_file.parse(MINIMAL + '  - {id: f, type: feeder_emptying, iterations: 1, '
                              'parts: 10, optimal_range: [4, 8], max_feed: 3}\n')
    (unit,) = plan(f, f.experiment('f'), {})
    assert unit.feeder.max_feed == 3 and unit.feeder.max_count == 8


def test_the_feeder_zone_is_where_the_file_puts_it():
    f = experiment_file.parse('feeder_zone_mm: {center: [-70, 5], size: [30, 90]}\n' + MINIMAL)
    assert f.tray.feeder_zone_center == pytest.approx((-0.07, 0.005))
    assert f.tray.feeder_zone_size == pytest.approx((0.03, 0.09))


BAD = [
    ('colour: red\n' + MINIMAL, r"colour: 'red' is not a known key here \(known: "),
    ('gripper: {body_diameter: 20}\n' + MINIMAL,
     r'gripper\.body_diameter: 20 is not a known key here \(did you mean body_diameter_mm\?\) '
     r'\(known: acceleration_m_s2, body_diameter_mm'),
    ('seed: abc\n' + MINIMAL, r"seed: 'abc' is not an integer"),
    ('requirements: {success_rate: 0}\n' + MINIMAL,
     r'requirements\.success_rate: 0 must be > 0'),
    ('requirements: {success_rate: 1.5}\n' + MINIMAL,
     r'requirements\.success_rate: 1\.5 must be <= 1'),
    ('seed: -1\n' + MINIMAL, r'seed: -1 must be within \[0, '),
    ('check: {tolerance_deg: .nan}\n' + MINIMAL, r'check\.tolerance_deg: nan must be finite'),
    ('check: {tolerance_deg: 120}\n' + MINIMAL, r'check \(check\.tolerance\): .* must be <='),
    ('check: {search_order: nearest}\n' + MINIMAL, r'search_order: .nearest. must be one of'),
    (MINIMAL.replace('iterations: 1', 'iterations: 0'),
     r'experiments\[0\]\.iterations: 0 must be within \[1, 10000\]'),
    (MINIMAL.replace('[[100, 100, 20]]', '[[400, 100, 20]]'),
     r'experiments\[0\]\.bins_mm\[0\]\[0\]: 400\.0 mm is over the size limit '
     r'requirements\.max_dimension_mm = 300'),
    (MINIMAL.replace('[[100, 100, 20]]', '[[100, 100]]'),
     r'bins_mm\[0\]: \[100, 100\] must be a list of 3 numbers'),
    (MINIMAL.replace('parts: 10', 'parts: 3000'),
     r'experiments\[0\]\.parts \(bins_mm\[0\]\): 3000 parts do not fit a container of '
     r'100 x 100 x 20 mm: .* at most \d+ within the packing limit'),
    (MINIMAL.replace('type: bin_static', 'type: bin_sweep'), r'type: .bin_sweep. must be one of'),
    ('id: t\n', r'experiments: None is required'),
    ('id: t\nexperiments: []\n', r'experiments: \[\] must be a list of 1\.\.50'),
    ('id: "t/../x"\n' + MINIMAL.split('\n', 1)[1], r'id: .t/\.\./x. must be 1\.\.64 letters'),
    (MINIMAL + '  - {id: b, type: bin_emptying, iterations: 1, parts: 10, bin: b}\n',
     r'experiments\[1\]\.id: .b. is the id of an earlier experiment'),
    (MINIMAL + '  - {id: e, type: bin_emptying, iterations: 1, parts: 10, bin: nope}\n',
     r'experiments\[1\]\.bin: .nope. names no earlier bin_static experiment'),
    (MINIMAL + '  - {id: f, type: feeder_emptying, iterations: 1, parts: 10, '
     'optimal_range: [30, 20]}\n', r'optimal_range: \[30, 20\] has min > max'),
    (MINIMAL + '  - {id: f, type: feeder_emptying, iterations: 1, parts: 10, '
     'optimal_range: b}\n', r'optimal_range: .b. names no earlier table_sweep'),
    (MINIMAL + '  - {id: s, type: table_sweep, iterations: 1, counts: {first: 9, last: 3}}\n',
     r'counts\.last: 3 must be within \[9, '),
    (MINIMAL + '  - {id: s, type: table_sweep, iterations: 1, bins_mm: [[1, 1, 1]]}\n',
     r'experiments\[1\]\.bins_mm: .* is not a known key here'),
    ('part: {model: mesh, mass_g: 1, mesh: no_such.stl, units: mm}\n' + MINIMAL,
     r'part\.mesh: .*no_such\.stl. does not exist or is not a file'),
    ('part: {model: mesh, mass_g: 1}\n' + MINIMAL,
     r'part\.mesh: .. is required when model is mesh'),
    ('part: {model: resistor}\n' + MINIMAL,
     r"part\.model: 'resistor' must be one of dip, radial_capacitor, to220, mesh"),
    ('part: {model: mesh, mesh: x.stl}\n' + MINIMAL, r'part\.mass_g: 0 is required'),
    ('part: {dimensions_mm: {body_diameter: -5}}\n' + MINIMAL,
     r'part\.dimensions_mm\.body_diameter: -5 must be > 0'),
    ('part: {dimensions_mm: {pins_per_row: 4}}\n' + MINIMAL, r'pins_per_row.*is a count'),
    ('part:\n  grasps:\n    - {up_axis: [0, 0, 1], closing_axis: [0, 0, 2], jaw_opening_mm: 5}\n'
     + MINIMAL, r'part\.grasps \(grasps\.grasp_0\.closing_axis\): .* is parallel to up_axis'),
    ('part:\n  grasps:\n    - {up_axis: [0, 0, 1], closing_axis: [1, 0, 0]}\n' + MINIMAL,
     r"part\.grasps\[0\]\.jaw_opening_mm \(grasp 'grasp_0'\): None is required with "
     r'parallel jaws \(gripper\.type: jaws\); a grasp without it is a suction cup'),
    ('moves: [{amplitude_mm: [0, 0, 10], frequency_hz: 50}]\n' + MINIMAL,
     r'moves\[0\] \(vibration\.amplitude\): .* gives a peak acceleration of .* \(limit 200\)'),
    ('moves: [{direction: diagonal}]\n' + MINIMAL,
     r"moves\[0\]\.direction: 'diagonal' must be one of fixed, random"),
    ('experiments: [\n', r'line \d+, column \d+: .* is not valid YAML'),
    ('feeder_zone_mm: {center: [-80, 0], size: [50, 100]}\n' + MINIMAL,
     r'feeder_zone_mm: .* reaches from -105 to -55 mm along x and -50 to 50 mm along y: it '
     r"must lie on the tray's plate, within \+-97\.5 and \+-75 mm of its centre \(tray_mm\)"),
    ('feeder_zone_mm: {center: [-80, 0], size: [5, 100]}\n' + MINIMAL,
     r'feeder_zone_mm\.size: \[5\.0, 100\.0\] is smaller than the part \(\d+\.\d mm across '
     r'in some orientation\): parts cannot be dropped into it'),
    ('feeder_zone_mm: {center: [0, 0], size: [0, 10]}\n' + MINIMAL,
     r'feeder_zone_mm\.size\[0\]: 0 must be > 0'),
    (SWEEP + 'grippers: {jaw_depth_mm: []}}\n',
     r'grippers\.jaw_depth_mm: \[\] must be a number or a list of 1 to 64 numbers'),
    (SWEEP + 'grippers: {jaw_depth_mm: [3, x]}}\n',
     r"grippers\.jaw_depth_mm\[1\]: 'x' is not a number"),
    (SWEEP + 'grippers: {jaw_width_mm: 3}}\n',
     r'grippers\.jaw_width_mm: 3 is not a known key here \(did you mean jaw_depth_mm\?\) '
     r'\(known: acceleration_m_s2, body_diameter_mm'),
    (SWEEP + 'grippers: {body_diameter_mm: [0, 8]}}\n',
     r'grippers \(body_diameter_mm 0, body_length_mm 60, .*\) \(gripper\.body_diameter\): 0'),
    (SWEEP + 'grippers: {body_diameter_mm: [5, 6, 7, 8, 9, 10, 11, 12, 13], '
     'jaw_depth_mm: [1, 2, 3, 4, 5, 6, 7, 8]}}\n',
     r'experiments\[1\]\.grippers: 72 grippers x grasp sets is over the limit of 64'),
    (SWEEP + 'grasp_sets: {top: [upright, flat]}}\n',
     r"grasp_sets\.top\[1\]: 'flat' is not the name of a grasp of part\.grasps \(side_px, "),
    (SWEEP + 'grasp_sets: {top: []}}\n',
     r'grasp_sets\.top: \[\] must be a non-empty list of grasp names'),
    (SWEEP + 'bin: nope}\n',
     r'experiments\[1\]\.bin: .nope. names no earlier bin_static experiment'),
    (SWEEP + 'bins_mm: [[1, 1, 1]]}\n',
     r'experiments\[1\]\.bins_mm: .* is not a known key here'),
    ('- just\n- a list\n', r'file: .* must be a mapping of keys'),
]


@pytest.mark.parametrize('text, message', BAD)
def test_a_bad_file_is_refused_with_field_value_and_rule(text, message):
    with pytest.raises(InvalidArgument) as info:
        experiment_file.parse(text)
    assert re.search(message, str(info.value)), str(info.value)


def test_a_gripper_sweep_is_every_combination_of_its_grid_and_grasp_sets():
    f = experiment_file.parse('gripper: {body_diameter_mm: 10, jaw_height_mm: 12}\n' + MINIMAL + (
        '  - {id: g, type: gripper_sweep, iterations: 3, parts: 10, min_valid: 2, '
        'grippers: {body_diameter_mm: [8, 12], jaw_depth_mm: [3, 4, 5]}, '
        'grasp_sets: {sides: [side_py, side_px], up: [upright]}}\n'
        '  - {id: h, type: gripper_sweep, iterations: 1, parts: 10, bin: b}\n'))
    g = f.experiment('g')
    assert g.bin is None and g.bin_from == '' and g.min_valid == 2
    assert len(g.variants) == 2 * 3 * 2
    # body diameter varies slowest, then jaw depth, then the grasp set; grasps keep the
    # part's order; keys not in the grid are the file's gripper's.
    assert [(v.gripper.body_diameter, v.gripper.jaw_depth, v.grasp_set)
            for v in g.variants[:3]] == [(0.008, 0.003, 'sides'), (0.008, 0.003, 'up'),
                                         (0.008, 0.004, 'sides')]
    assert [x.name for x in g.variants[0].grasps] == ['side_px', 'side_py']
    assert {v.gripper.jaw_height for v in g.variants} == {0.012}
    h = f.experiment('h')       # no grid: the file's gripper, every grasp, the best bin of b
    assert h.bin_from == 'b' and h.min_valid == 1.0
    assert [(v.gripper, v.grasp_set, v.grasps) for v in h.variants] == [
        (f.gripper, 'all', f.grasps)]


def test_a_file_that_cannot_be_read_is_named(tmp_path):
    with pytest.raises(InvalidArgument, match=r"experiment_file: '.*missing\.yaml' cannot be "
                       'read: No such file'):
        experiment_file.load(str(tmp_path / 'missing.yaml'))
    (tmp_path / 'binary.yaml').write_bytes(b'\xff\xfe\x00')
    with pytest.raises(InvalidArgument, match='is not UTF-8 text'):
        experiment_file.load(str(tmp_path / 'binary.yaml'))


def test_a_mesh_path_is_relative_to_the_file(tmp_path):
    import trimesh
    trimesh.creation.box((0.004, 0.002, 0.01)).export(tmp_path / 'clip.stl')
    path = tmp_path / 'exp.yaml'
    path.write_text('part:\n  model: mesh\n  mesh: clip.stl\n  units: m\n  mass_g: 0.2\n'
                    '  place: {seat_offset_mm: 5}\n  grasps:\n'
                    '    - {up_axis: [0, 0, 1], closing_axis: [1, 0, 0], jaw_opening_mm: 8}\n'
                    + MINIMAL)
    f = experiment_file.load(str(path))
    assert f.part.mesh_path == str(tmp_path / 'clip.stl')


def test_a_reduced_copy_caps_iterations_and_keeps_the_rest(tmp_path):
    f = experiment_file.load(DEFAULT)
    small = experiment_file.parse(experiment_file.reduced(f, 1))
    # the sensitivity experiment caps its two repeats of `feeder` at 1 too
    assert [e.iterations for e in small.experiments] == [1] * 9
    assert small.experiment('sweep').counts == f.experiment('sweep').counts
    assert (small.part, small.gripper, small.grasps) == (f.part, f.gripper, f.grasps)
    with pytest.raises(InvalidArgument, match=r'max_iterations: 0 must be within \[1, '):
        experiment_file.reduced(f, 0)


def test_feeder_moves_are_named_or_set_field_by_field():
    text = open(DEFAULT).read()
    assert 'moves: [centre, flip]' in text
    f = experiment_file.parse(text.replace('moves: [centre, flip]', 'moves: [spread, {move: '
                                  'backward, duration_s: 0.2}, {amplitude_mm: [0, 1, 2]}]'))
    spread, back, own = f.moves
    assert spread == MOVES['spread'] and spread.direction == 'random' and back.duration == 0.2
    assert back.amplitude == MOVES['backward'].amplitude and back.direction == 'fixed'
    # fields over the default move, the flip: no random direction unless asked for
    assert own.amplitude == pytest.approx((0.0, 0.001, 0.002)) and own.direction == 'fixed'
    for moves, error in (('[shake]', r"moves\[0\].move: 'shake' must be one of flip, centre"),
                         ('[]', r'moves: \[\] must be a list of 1 to 16 moves'),
                         ('[{amplitude_mm: [0, 0, -1]}]',
                          r'moves\[0\] \(vibration.amplitude\[2\]\): -0.001 must be >= 0')):
        with pytest.raises(InvalidArgument, match=error):
            experiment_file.parse(text.replace('moves: [centre, flip]', f'moves: {moves}'))


def test_the_cell_s_times_default_and_are_checked():
    text = open(DEFAULT).read()
    assert experiment_file.parse(MINIMAL).cell == experiment_file.Cell(pick_time=4.0,
                                                                       image_time=0.0)
    f = experiment_file.parse(text.replace('pick_s: 4', 'pick_s: 2.5').replace('image_s: 0',
                                                                    'image_s: 0.3'))
    assert f.cell == experiment_file.Cell(pick_time=2.5, image_time=0.3)
    for old, new, error in (('pick_s: 4', 'pick_s: 0', r'cell.pick_s: 0 must be > 0'),
                            ('image_s: 0', 'image_s: -1', r'cell.image_s: -1 must be >= 0'),
                            ('pick_s: 4', 'pick_time: 4',
                             r'cell.pick_time: 4 is not a known key here \(did you mean '
                             r'pick_s\?\)')):
        with pytest.raises(InvalidArgument, match=error):
            experiment_file.parse(text.replace(old, new))


def test_the_installed_share_holds_the_paper_test_case():
    # A user of an installed workspace runs the test case by its share path.
    share = os.path.join(get_package_share_directory('experiment_manager'), 'config')
    for name in ('pth0.yaml', 'pth1.yaml', 'pth2.yaml', 'grippers_pth0.yaml',
                 'pth0_robustness.yaml', 'pth1_robustness.yaml', 'pth2_robustness.yaml',
                 'pth0_gripper_map.yaml', 'pth0_options.yaml', 'pth1_options.yaml',
                 'pth2_options.yaml', 'pth0_spills.yaml', 'pth2_spills.yaml',
                 'pth1_feed.yaml'):
        assert experiment_file.load(os.path.join(share, 'test_case', name)).experiments


@pytest.mark.parametrize('name', ['pth0_robustness.yaml', 'pth1_robustness.yaml',
                                  'pth2_robustness.yaml', 'pth0_gripper_map.yaml'])
def test_the_robustness_files_are_their_part_with_a_sensitivity_experiment(name):
    # a copy that drifted from its pthN.yaml would answer for another part or cell
    case = os.path.join(HERE, '..', 'config', 'test_case')
    part = experiment_file.load(os.path.join(case, name.split('_')[0] + '.yaml'))
    robust = experiment_file.load(os.path.join(case, name))
    own = [e for e in robust.experiments if e.scenario is None and e.type != 'sensitivity']
    assert own == list(part.experiments)
    assert (robust.id, robust.seed, robust.part, robust.gripper, robust.setup, robust.moves,
            robust.requirements, robust.cell, robust.tray) == (
        part.id, part.seed, part.part, part.gripper, part.setup, part.moves,
        part.requirements, part.cell, part.tray)
    sensitivity = robust.experiments[-1]
    assert sensitivity.type == 'sensitivity' and all(x.source for x in sensitivity.inputs)


SPILLS = ['materials.part_on_surface.restitution', 'moves.amplitude_scale']
FEED = ['tray.hopper_lip_mm', 'tray.hopper_rate', 'tray.hopper_speed_mm_s', 'tray.wall_mm']


@pytest.mark.parametrize('name, sensitivity, inputs', [
    ('pth0_spills.yaml', 'spills', SPILLS), ('pth2_spills.yaml', 'spills', SPILLS),
    ('pth1_feed.yaml', 'feed', FEED)])
def test_the_feeder_files_are_their_part_and_its_feeder_runs_on_the_same_seeds(
        name, sensitivity, inputs):
    # the first runs must be the sensitivity's own (the same part, cell, seeds and range)
    case = os.path.join(HERE, '..', 'config', 'test_case')
    part = experiment_file.load(os.path.join(case, name.split('_')[0] + '.yaml'))
    spills = experiment_file.load(os.path.join(case, name))
    assert (spills.id, spills.seed, spills.part, spills.gripper, spills.setup, spills.moves,
            spills.requirements, spills.cell, spills.tray) == (
        part.id, part.seed, part.part, part.gripper, part.setup, part.moves,
        part.requirements, part.cell, part.tray)
    feeder, theirs = spills.experiment('feeder'), part.experiment('feeder')
    assert (feeder.type, feeder.parts, feeder.max_vibrations) == (
        theirs.type, theirs.parts, theirs.max_vibrations)
    assert [x.name for x in spills.experiment(sensitivity).inputs] == inputs


@pytest.mark.parametrize('name', ['pth0_options.yaml', 'pth1_options.yaml',
                                  'pth2_options.yaml'])
def test_the_options_files_are_their_part_and_the_same_experiments_with_a_cup(name):
    case = os.path.join(HERE, '..', 'config', 'test_case')
    part = experiment_file.load(os.path.join(case, name.split('_')[0] + '.yaml'))
    options = experiment_file.load(os.path.join(case, name))
    assert [e for e in options.experiments if not e.gripper and not e.station] == list(
        part.experiments)
    assert (options.id, options.seed, options.setup, options.moves, options.requirements,
            options.cell, options.tray) == (part.id, part.seed, part.setup, part.moves,
                                             part.requirements, part.cell, part.tray)
    cup = [e for e in options.experiments if e.gripper]
    assert [e.id for e in cup] == [f'{e.id}_cup' for e in part.experiments]
    for mine, theirs in zip(cup, part.experiments, strict=True):     # on the same scenes
        own = [f.name for f in dataclasses.fields(theirs)
               if f.name not in ('id', 'gripper', 'setup', 'seeded_by', 'bin_from', 'range_from')]
        assert type(mine) is type(theirs) and 'iterations' in own and 'parts' in own
        assert [getattr(mine, k) for k in own] == [getattr(theirs, k) for k in own]
        assert mine.gripper == 'cup' and type(mine.setup.gripper).__name__ == 'SuctionCup'
        assert mine.seeded_by == theirs.id
    station = options.experiment('emptying_station')
    assert station.station and station.setup.config.regrasp_station
    assert (station.bin_from, station.parts, station.seeded_by) == ('bins', part.experiment(
        'emptying').parts, 'emptying')


def test_every_error_of_a_file_comes_at_once():
    # One per section or experiment: the user fixes a file in one pass, not one run per typo.
    text = """id: t
seed: -1
gripper: {body_diameter_mm: 20, jaw_depht_mm: 3}
experiments:
  - {id: b, type: bin_static, iterations: 0, parts: 10, bins_mm: [[100, 100, 20]]}
  - {id: s, type: table_sweep, iterations: 1, margn: 5}
"""
    with pytest.raises(experiment_file.InvalidFile) as info:
        experiment_file.parse(text)
    assert [e.field for e in info.value.errors] == [
        'seed', 'gripper.jaw_depht_mm', 'experiments[0].iterations', 'experiments[1].margn']
    message = str(info.value)
    assert message.startswith('4 errors:\n')
    assert 'gripper.jaw_depht_mm: 3 is not a known key here (did you mean jaw_depth_mm?)' in message
    assert 'experiments[1].margn: 5 is not a known key here (did you mean margin?)' in message


def test_an_empty_experiment_list_is_refused():
    for text in ('id: t\nexperiments:\n', 'id: t\nexperiments: []\n'):
        with pytest.raises(InvalidArgument, match=r'^experiments: .* must be a list of 1\.\.'):
            experiment_file.parse(text)


def test_a_misspelt_required_key_is_named_as_the_typo_it_is():
    text = MINIMAL.replace('iterations: 1', 'iteration: 1')
    with pytest.raises(InvalidArgument) as info:
        experiment_file.parse(text)
    assert str(info.value) == ('experiments[0].iteration: 1 is not a known key here '
                               '(did you mean iterations? it is required)')
    assert not isinstance(info.value, experiment_file.InvalidFile)     # one error, told once


STEP = os.path.join(HERE, '..', 'config', 'parts', 'TO-220-3_Vertical.step')
# KiCad's TO-220: origin at pin 1 on the board plane; the body is 10.25 mm across x at
# (2.54, 0, 9) mm, 4.46 mm across y there (-1.29 to 3.16 mm about it).
TO220 = """id: t
part:
  model: mesh
  mesh: {mesh}
  mass_g: 2
  place: {{axis: [0, 0, -1], seat_offset_mm: 0}}
  grasps:
    - {{name: across, up_axis: [0, 1, 0], closing_axis: [1, 0, 0], jaw_opening_mm: {opening},
       grasp_point_mm: {point}}}
experiments:
  - {{id: s, type: table_sweep, iterations: 1, counts: {{first: 5, last: 10, step: 5}}}}
"""


def _to220(mesh=STEP, opening=16, point='[2.54, 0, 9]', extra=''):
    return TO220.format(mesh=mesh, opening=opening, point=point).replace(
        '  mass_g: 2\n', '  mass_g: 2\n' + extra)


def test_a_step_file_is_read_in_its_own_units():
    f = experiment_file.parse(_to220(), STEP)
    assert f.part.scale == 1.0 and f.part.mesh_path == os.path.normpath(STEP)
    from pick_common.parts.geometry import build_part
    assert build_part(f.part).visual.extents == pytest.approx((0.01025, 0.004455, 0.028525),
                                                              abs=1e-6)


@pytest.mark.parametrize('text, message', [
    (_to220(point='[0, -1, 18]'), r"part\.grasps\[0\]\.grasp_point_mm \(grasp 'across'\): "
     r'\[0\.0, -1\.0, 18\.0\] closes on nothing'),
    (_to220(opening=9), r"grasp 'across'\): .* cannot close on the part: it is 10\.25 mm across "
     r'the closing axis .* the jaws open 9\.00 mm'),
    (_to220(point='[9, 0, 9]'), r'grasp point off the part: the material on its closing line '
     r'begins 1\.34 mm from it'),
    (_to220(extra='  mesh_scale: 0.001\n'), r'part\.mesh_scale: 0\.001 is not read for '
     r'TO-220-3_Vertical\.step: the file states its own units'),
    (_to220(extra='  units: mm\n'), r'part\.units: .mm. is not read for'),
    (_to220().split('  grasps:')[0] + 'experiments:' + _to220().split('experiments:')[1],
     r'part\.grasps: None are required for a mesh part'),
    (_to220().replace('seat_offset_mm: 0', 'axis: [0, 0, -1]').replace(
        '{axis: [0, 0, -1], axis', '{axis'), r'part\.place\.seat_offset_mm: None is required '
     'for a mesh part'),
])
def test_a_wrong_mesh_part_is_refused_with_what_was_measured(text, message):
    with pytest.raises(InvalidArgument) as info:
        experiment_file.parse(text, STEP)
    assert re.search(message, str(info.value)), str(info.value)


def test_a_file_without_units_needs_them_and_a_wrong_unit_is_named(tmp_path):
    import trimesh
    trimesh.creation.box((6.0, 4.0, 2.0)).export(tmp_path / 'clip.stl')     # in mm
    text = _to220(mesh='clip.stl', point='[0, 0, 0]')
    with pytest.raises(InvalidArgument, match=r'part\.units: None is required for clip\.stl, '
                       r'which states no units: one of mm, cm, m, in'):
        experiment_file.parse(text, str(tmp_path / 'exp.yaml'))
    with pytest.raises(InvalidArgument, match=r'part\.mesh: .* is 6000 mm across at scale 1; '
                       r'a part must be 0\.5 to 300 mm across: in mm \(scale 0\.001\) it is 6 '
                       r'mm, in cm \(scale 0\.01\) it is 60 mm, in in \(scale 0\.0254\) it is '
                       r'152\.4 mm'):
        experiment_file.parse(_to220(mesh='clip.stl', point='[0, 0, 0]', extra='  units: m\n'),
                              str(tmp_path / 'exp.yaml'))
    f = experiment_file.parse(_to220(mesh='clip.stl', point='[0, 0, 0]', extra='  units: mm\n'),
                              str(tmp_path / 'exp.yaml'))
    assert f.part.scale == 0.001
