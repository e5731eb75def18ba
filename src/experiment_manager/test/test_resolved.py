"""What a run ran with (experiment_file.resolved): every default applied, in the file's units,
written once and read back as written; a run directory without one is resolved from its
experiment.yaml."""

import json
import os
import shutil

from experiment_manager.experiment_file import load, resolved

CONFIG = os.path.join(os.path.dirname(__file__), '..', 'config')
OPTIONS = os.path.join(CONFIG, 'test_case', 'pth0_options.yaml')


def test_the_record_holds_every_default_and_each_named_gripper(tmp_path):
    file = load(OPTIONS)
    ran = resolved.resolved(file)
    # the file's jaws with the keys it left out, and its cup, each in the file's units
    assert ran['gripper'] == {'type': 'jaws', 'body_diameter_mm': 20.0, 'body_length_mm': 60.0,
                              'jaw_height_mm': 15.0, 'jaw_depth_mm': 3.0,
                              'finger_clearance_mm': 1.0}
    cup = ran['grippers']['cup']
    assert cup['type'] == 'suction' and cup['vacuum_kpa'] == 60.0 and cup['grasps']
    assert [g['name'] for g in ran['grasps']] == [g.name for g in file.grasps]
    assert ran['grasps'][0]['jaw_opening_mm'] == 11.0
    assert ran['tray']['hopper_lip_mm'] == 30.0 and ran['tray']['tray_mm'] == [195.0, 150.0, 27.0]
    assert (ran['tray']['hopper_rate'], ran['tray']['hopper_speed_mm_s']) == (10.0, 100.0)
    assert {'hopper_lip_mm', 'hopper_rate', 'hopper_speed_mm_s', 'feeder_zone_mm'} <= set(
        ran['defaulted'])
    assert ran['doses'] == {'feeder': 0, 'feeder_cup': 0}
    assert [a['name'] for a in ran['part']['aspects']] == [a.name for a in file.aspects]
    assert ran['requirements']['refill_interval_h'] == 4.0
    # written once, read back as written; a directory without it resolved from its file
    path = resolved.write(file, str(tmp_path))
    with open(path, encoding='utf-8') as f:
        assert json.load(f) == resolved.read(str(tmp_path))
    old = tmp_path / 'old'
    old.mkdir()
    shutil.copy(OPTIONS, old / 'experiment.yaml')
    assert resolved.read(str(old))['gripper'] == ran['gripper']
