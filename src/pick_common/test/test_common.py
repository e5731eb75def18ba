"""The shared checks and conversions: a limit is enforced as stated, the packing rule names the
most that fit, a vibration round-trips through its message and its defaults, tunnelled points
are told from spilled ones."""

import numpy as np
from pick_common import containers, conversions
from pick_common.containers import check_fits, ContainerSpec
from pick_common.errors import InvalidArgument, Limit
from pick_common.specs import CENTRE, FIXED, RANDOM, Vibration
from pick_common.states import SettleReport, TrayMotion
from pick_msgs.msg import Vibration as VibrationMsg
import pytest


def test_a_limit_checks_what_it_states():
    limit = Limit(0.0, 1.0, low_open=True)
    assert limit.check('x', 0.5) == 0.5
    with pytest.raises(InvalidArgument, match=r'x: 0.0 must be > 0'):
        limit.check('x', 0.0)
    with pytest.raises(InvalidArgument, match=r'x: 0.1 must be >= 0.2'):
        limit.check('x', 0.1, low=0.2)
    with pytest.raises(InvalidArgument, match=r'n: 7 must be within \[1, 5\]'):
        Limit(1, 5, integer=True).check('n', 7)


def test_the_packing_rule_names_the_most_that_fit():
    bin_ = ContainerSpec(inner_size=(0.1, 0.1, 0.02))       # 200 cm^3; 40 % is 80 cm^3
    check_fits('parts', 80, 1e-6, bin_)
    with pytest.raises(InvalidArgument, match=r'parts: 81 parts do not fit a container of '
                                              r'100 x 100 x 20 mm: .* at most 80 within'):
        check_fits('parts', 81, 1e-6, bin_)


def test_a_vibration_round_trips_and_zeros_take_the_defaults():
    v = Vibration(amplitude=(0.001, 0.0, 0.002), frequency=50.0, duration=0.25,
                  direction=FIXED)
    assert conversions.vibration_from_msg(conversions.vibration_to_msg(v), Vibration()) == v
    assert conversions.vibration_from_msg(VibrationMsg(), v) == v
    with pytest.raises(InvalidArgument, match='vibration.direction: 7 must be'):
        conversions.vibration_from_msg(VibrationMsg(direction=7), Vibration())
    assert conversions.vibration_from_msg(
        VibrationMsg(direction=VibrationMsg.DIRECTION_RANDOM), v).direction == RANDOM
    centre = Vibration(direction=CENTRE)
    assert conversions.vibration_from_msg(conversions.vibration_to_msg(centre), v) == centre


def test_tunnelled_points_are_in_or_under_the_floor_or_in_a_wall():
    spec = ContainerSpec(inner_size=(0.1, 0.08, 0.02), wall_thickness=0.003)
    points = [(0.0, 0.0, 0.005),      # on the floor: inside
              (0.0, 0.0, -0.001),     # under the floor's top face
              (0.03, 0.02, -0.5),     # fallen through, within the footprint
              (0.0515, 0.0, 0.01),    # in the +x wall
              (0.0, -0.0415, 0.019),  # in the -y wall, below its top
              (0.0515, 0.0, 0.03),    # above the +x wall: spilling over it, not in it
              (0.2, 0.0, -0.5)]       # beside the container, fallen: spilled
    assert containers.tunnelled(spec, np.array(points)).tolist() == [
        False, True, True, True, True, False, False]


def test_a_settle_report_tells_spilled_from_tunnelled_and_thrown_and_round_trips():
    report = SettleReport(True, 1.0, 0.5, 240, escaped_ids=[3, 5, 8, 9], tunnelled_ids=[5],
                          max_penetration=2e-4, tray=TrayMotion(0.003, 0.00297, 0.5, 0.49),
                          thrown_ids=[9], max_speed=3.6)
    assert report.spilled_ids == [3, 8]
    assert report.tray.error == pytest.approx(0.02)
    again = conversions.settle_from_msg(conversions.settle_to_msg(report))
    assert again == report
    assert conversions.settle_from_msg(conversions.settle_to_msg(
        SettleReport(True, 0.0, 0.0, 0))).tray is None


def test_a_trays_hopper_round_trips_and_zero_takes_its_default():
    from dataclasses import replace
    tray = replace(ContainerSpec.tray(), drop_height=0.05, hopper_rate=4.0, hopper_speed=0.3)
    back = conversions.container_from_msg(conversions.container_to_msg(tray))
    assert back == tray
    msg = conversions.container_to_msg(ContainerSpec.tray())
    assert (msg.hopper_rate, msg.hopper_speed) == (containers.HOPPER_RATE,
                                                   containers.HOPPER_SPEED)
    msg.hopper_rate = msg.hopper_speed = 0.0      # ROS cannot leave a field unset
    assert containers.hopper(conversions.container_from_msg(msg)) == (
        containers.HOPPER_RATE, containers.HOPPER_SPEED)
    msg.hopper_speed = float('nan')
    with pytest.raises(InvalidArgument, match='container.hopper_speed'):
        conversions.container_from_msg(msg)
    with pytest.raises(InvalidArgument, match=r'container.hopper_rate: 2000.0 must be <= 1000'):
        containers.check_container(replace(tray, hopper_rate=2000.0))
