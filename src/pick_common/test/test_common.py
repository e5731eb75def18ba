"""The shared checks and conversions: a limit is enforced as stated, the packing rule names the
most that fit, a vibration round-trips through its message and its defaults."""

from pick_common import conversions
from pick_common.containers import check_fits, ContainerSpec
from pick_common.errors import InvalidArgument, Limit
from pick_common.specs import FIXED, RANDOM, Vibration
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
