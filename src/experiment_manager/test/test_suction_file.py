"""A suction cup in the experiment file: its keys, its grasps, what `run --check` says and
writes of each grasp, its proposals under `grasps: auto`, and bad input named by key, value
and what was measured."""

import json
import os

from experiment_manager import experiment_file
from experiment_manager.commands.check import check
from pick_common.errors import InvalidArgument
import pytest

PARTS = os.path.join(os.path.dirname(__file__), '..', 'config', 'parts')
SUCTION = os.path.join(PARTS, 'to220_suction.yaml')
DIP = """id: dip_cup
part:
  model: dip
  place: {axis: [0, 0, -1], seat_offset_mm: 1.65}
  grasps:
    - {name: top, up_axis: [0, 0, 1], grasp_point_mm: [0, 0, 1.65]}
    - {name: end, up_axis: [1, 0, 0], grasp_point_mm: [4.7, 0, 0]}
gripper: {type: suction, cup_diameter_mm: 4}
experiments:
  - {id: sweep, type: table_sweep, iterations: 1, counts: {first: 10, last: 20, step: 10}}
"""


def test_the_example_reads_with_its_cup_and_grasps():
    f = experiment_file.load(SUCTION)
    assert type(f.setup.gripper).__name__ == 'SuctionCup'
    assert f.setup.gripper.vacuum == 60_000.0 and f.setup.gripper.cup_diameter == 0.004
    assert [g.name for g in f.setup.grasps] == ['front_up', 'back_up', 'edge_px', 'edge_nx']


def test_check_prints_and_writes_each_grasp_s_seal_and_margin(tmp_path, capsys):
    path = tmp_path / 'dip.yaml'
    path.write_text(DIP)
    assert check([str(path)], str(tmp_path / 'out')) == 0
    printed = capsys.readouterr().out
    assert "grasp 'top': cup at (0.00, 0.00, 1.65) mm" in printed
    assert 'seals: its rim and the surface inside lie within 0.00 mm of a plane' in printed
    assert "grasp 'end'" in printed and 'does not seal: the rim leaves the part' in printed
    assert 'never used by the check' in printed
    written = json.loads((tmp_path / 'out' / 'check.json').read_text())
    top, end = written['grasps']
    assert top['seal'] is True and top['holds'] is True and top['force_margin'] > 1
    assert top['from_mass_centre_mm'] == pytest.approx(1.65)
    assert end['seal'] is False and end['reason'].startswith('the rim leaves the part')
    assert end['used'] is False
    assert any('suction cup 4 mm across' in line for line in written['part'])


@pytest.mark.parametrize('change, field, words', [
    # a grasp point off the surface: how far, along which axis
    (('[0, 0, 1.65]', '[0, 0, 2.5]'), "part.grasps[0].grasp_point_mm (grasp 'top')",
     "the grasp point is not on the part's surface: the first surface along the approach "
     'lies -0.85 mm'),
    # a jaws' key on a suction grasp, and the reverse
    ('{name: top, up_axis: [0, 0, 1],', "part.grasps[0].jaw_opening_mm (grasp 'top')",
     'is not a key of a grasp of a suction cup (gripper.type: suction'),
    (('type: suction, cup_diameter_mm: 4', 'type: jaws'),
     "part.grasps[0].closing_axis (grasp 'top')", 'is required with parallel jaws'),
    (('cup_diameter_mm: 4', 'cup_diameter_mm: 4, jaw_depth_mm: 3'), 'gripper.jaw_depth_mm',
     'is a key of parallel jaws, and the gripper is a suction cup (gripper.type: suction)'),
    # no grasp the cup can use
    (('- {name: top, up_axis: [0, 0, 1], grasp_point_mm: [0, 0, 1.65]}\n', ''), 'part.grasps',
     "hold no grasp the cup can use: 'end': the rim leaves the part"),
])
def test_bad_suction_input_is_named(change, field, words):
    if isinstance(change, str):
        text = DIP.replace(change, change + ' jaw_opening_mm: 10,', 1)
    else:
        assert change[0] in DIP
        text = DIP.replace(*change, 1)
    with pytest.raises(InvalidArgument) as err:
        experiment_file.parse(text)
    assert err.value.field == field, str(err.value)
    assert words in str(err.value)


def test_auto_proposes_a_cup_grasp_per_way_the_part_lies_or_names_a_cup_too_large():
    text = (DIP.split('  grasps:')[0] + '  grasps: auto\n'
            + DIP.split('grasp_point_mm: [4.7, 0, 0]}\n')[1])
    f = experiment_file.parse(text)
    assert sorted(g.name for g in f.setup.grasps) == ['cup_up+z', 'cup_up-z']
    top = next(g for g in f.setup.grasps if g.name == 'cup_up+z')
    assert top.grasp_point == pytest.approx((0.0, 0.0, 0.00165))
    with pytest.raises(InvalidArgument) as err:
        experiment_file.parse(text.replace('cup_diameter_mm: 4', 'cup_diameter_mm: 12'))
    assert err.value.field == 'gripper.cup_diameter_mm' and err.value.value == 12
    assert 'is larger than every flat patch' in str(err.value)
    assert 'a 6 mm cup would seal on it' in str(err.value)


OPTIONS = """id: dip_options
seed: 4
part:
  model: dip
  place: {axis: [0, 0, -1], seat_offset_mm: 1.65}
  grasps:
    - {name: top, up_axis: [0, 0, 1], closing_axis: [0, 1, 0], jaw_opening_mm: 13.5}
    - {name: bottom, up_axis: [0, 0, -1], closing_axis: [0, 1, 0], jaw_opening_mm: 13.5}
gripper: {body_diameter_mm: 20, jaw_depth_mm: 3}
grippers:
  cup: {type: suction, cup_diameter_mm: 4, grasps: auto}
requirements: {parts_per_hour: 60, refill_interval_h: 0.25}
experiments:
  - {id: emptying, type: bin_emptying, iterations: 1, parts: 15, bin: [60, 60, 20]}
  - {id: emptying_cup, type: bin_emptying, iterations: 1, parts: 15, bin: [60, 60, 20],
     gripper: cup}
  - {id: emptying_station, type: bin_emptying, iterations: 1, parts: 15, bin: [60, 60, 20],
     regrasp_station: true, scenes_of: emptying}
"""


def test_one_file_compares_options_per_gripper_with_the_stage_that_stops_most(tmp_path):
    from experiment_manager.analysis.results import ResultsWriter
    from experiment_manager.analysis.verdicts import verdicts
    from experiment_manager.running.local_backend import LocalBackend
    from experiment_manager.running.scheduler import Runner
    file = experiment_file.parse(OPTIONS)
    cup = file.experiment('emptying_cup')
    assert cup.gripper == 'cup' and type(cup.setup.gripper).__name__ == 'SuctionCup'
    assert type(file.for_experiment(cup).setup.gripper).__name__ == 'SuctionCup'
    assert file.for_experiment(file.experiment('emptying')).setup == file.setup
    with LocalBackend() as backend, ResultsWriter(str(tmp_path), file.text) as writer:
        summary = Runner(file, [backend], writer).run()
    assert summary.experiments['emptying_cup'].gripper == 'cup'
    assert summary.experiments['emptying'].gripper is None
    found = verdicts(summary)
    bins = [v for v in found if v.kind.startswith('static bin')]
    assert [v.kind for v in bins] == ['static bin', 'static bin with a regrasp station',
                                      'static bin, gripper cup']
    assert bins[2].option == 'static bin 60 x 60 x 20 mm, gripper cup'
    assert summary.experiments['emptying_station'].station is True
    assert any('after a regrasp on the station' in r for r in bins[1].reasons)
    for v in bins:       # the stage that stops most parts, with its share
        assert v.stops.split(' (')[0] in ('candidacy', 'placeability', 'container',
                                          'neighbours')
        assert '% of the parts checked)' in v.stops
    # the cup's checks are the cup's: its emptying removed parts on its own grasps
    assert summary.experiments['emptying_cup'].removed.mean is not None


STATION = """id: station
seed: 5
experiments:
  - {id: emptying, type: bin_emptying, iterations: 1, parts: 20, bin: [150, 150, 20]}
  - {id: station, type: bin_emptying, iterations: 1, parts: 20, bin: [150, 150, 20],
     regrasp_station: true, scenes_of: emptying}
"""


def test_a_regrasp_station_picks_what_could_not_be_placed_on_the_same_scenes(tmp_path):
    from experiment_manager.analysis.results import read_csv, ResultsWriter
    from experiment_manager.running.local_backend import LocalBackend
    from experiment_manager.running.scheduler import Runner
    file = experiment_file.parse(STATION)
    assert file.experiment('station').seeded_by == 'emptying'
    with LocalBackend() as backend, ResultsWriter(str(tmp_path), file.text) as writer:
        summary = Runner(file, [backend], writer).run()
    rows = {r['experiment']: r for r in read_csv(str(tmp_path / 'iterations.csv'))}
    assert rows['station']['seed'] == rows['emptying']['seed']         # the same scene
    picks = [p for p in read_csv(str(tmp_path / 'picks.csv')) if p['experiment'] == 'station']
    station = summary.experiments['station']
    # the regrasps counted are the picks placed only after one: here the station placed two
    # parts held as they lay could not be, and the bin gave 14 parts against the plain 11
    assert station.regrasps.mean == sum(p['regrasp'] for p in picks) >= 1
    plain = summary.experiments['emptying'].removed.mean
    assert station.removed.mean > plain


@pytest.mark.parametrize('change, field, words', [
    (('gripper: cup}', 'gripper: pump}'), 'experiments[1].gripper',
     "names no gripper of the file's grippers (cup)"),
    (('grasps: auto}', 'grasps: auto, jaw_depth_mm: 3}'), 'grippers.cup.jaw_depth_mm',
     'is a key of parallel jaws'),
    (('cup_diameter_mm: 4', 'cup_diameter_mm: 12'), 'grippers.cup.gripper.cup_diameter_mm',
     'larger than every flat patch'),
])
def test_a_bad_named_gripper_is_named(change, field, words):
    with pytest.raises(InvalidArgument) as err:
        experiment_file.parse(OPTIONS.replace(*change))
    assert err.value.field == field, str(err.value)
    assert words in str(err.value)


def test_the_station_s_margin_is_the_file_s_and_checked():
    text = STATION.replace('experiments:', 'check: {station_margin: 0.3}\nexperiments:')
    file = experiment_file.parse(text)
    assert file.experiment('station').setup.config.station_margin == 0.3
    assert not file.for_experiment(file.experiment('emptying')).setup.config.regrasp_station
    with pytest.raises(InvalidArgument) as err:
        experiment_file.parse(text.replace('0.3}', '-1}'))
    assert 'check.station_margin' in str(err.value) and '-1' in str(err.value)
