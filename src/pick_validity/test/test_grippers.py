"""The gripper kinds: each one's table of keys agrees with its fields, the limits a field two
kinds share are one, the message carries every key, and a kind made in a test and used by no
other module than its own runs through the check (what adding a kind asks: its class)."""

from dataclasses import dataclass, fields
from typing import ClassVar

import fcl
import numpy as np
from pick_common.containers import ContainerSpec
from pick_common.errors import InvalidArgument, Limit
from pick_msgs.msg import Gripper as GripperMsg
from pick_validity import conversions
from pick_validity.config import Setup
from pick_validity.geometry import BoxShape, CylinderShape
from pick_validity.grippers import check_grasps, Jaws, Key, KINDS, SuctionCup
from pick_validity.results import STAGE_VALID
from pick_validity.validity import Validator
import pytest


@pytest.mark.parametrize('kind', KINDS.values(), ids=KINDS)
def test_a_kind_s_keys_are_its_fields_each_with_a_limit_its_default_keeps(kind):
    assert [k.field for k in kind.KEYS] == [f.name for f in fields(kind)]
    assert len({k.file_key for k in kind.KEYS}) == len(kind.KEYS)
    assert kind().check() == kind()
    assert all(k.source for k in kind.KEYS)
    for key in kind.KEYS:      # a value past its limit is refused, named by the node's name
        with pytest.raises(InvalidArgument, match=f'gripper.{key.field}'):
            kind(**{key.field: key.limit.high * 2 + 1}).check()


def test_a_field_two_kinds_share_has_one_limit_and_the_message_carries_every_key():
    limits: dict[str, Limit] = {}
    for kind in KINDS.values():
        for key in kind.KEYS:
            assert limits.setdefault(key.field, key.limit) == key.limit, key.field
            assert hasattr(GripperMsg(), key.field), key.field
    assert set(conversions.MSG_TYPES) == set(KINDS)


@pytest.mark.parametrize('gripper', [Jaws(jaw_depth=0.004), SuctionCup(vacuum=50e3)],
                         ids=['jaws', 'suction'])
def test_a_gripper_goes_through_the_message_and_back_as_it_was(gripper):
    msg = conversions.gripper_to_msg(gripper)
    assert conversions.gripper_from_msg(msg, Jaws()) == gripper
    empty = GripperMsg(type=msg.type)
    assert conversions.gripper_from_msg(empty, gripper) == gripper   # left empty: the default
    with pytest.raises(InvalidArgument, match='gripper.type'):
        conversions.gripper_from_msg(GripperMsg(type=7), gripper)


def test_a_grasp_of_another_kind_is_refused_saying_what_the_gripper_wants():
    (cup_grasp,) = (SuctionCup.written('top', (0, 0, 1)),)
    with pytest.raises(InvalidArgument, match='is a suction grasp, and the gripper is parallel '
                                              'jaws: give up_axis and closing_axis and '
                                              'jaw_opening'):
        check_grasps([cup_grasp], Jaws())


@dataclass(frozen=True)
class _Paddle(Jaws):
    """A kind made here, as a user adding one would: jaws whose fingers are thin paddles
    (a box as wide as the opening but only `paddle` deep), on no body."""

    kind: ClassVar[str] = 'paddle'
    description: ClassVar[str] = 'paddle fingers'
    KEYS: ClassVar[tuple[Key, ...]] = Jaws.KEYS + (
        Key('paddle', 'mm', Limit(0.0, 0.1, low_open=True), 'paddle depth, m', 'assumed'),)
    paddle: float = 0.001

    def shapes(self, grasp, depth: float) -> tuple[BoxShape, CylinderShape]:
        jaws, body = super().shapes(grasp, depth)
        size = np.array([grasp.jaw_opening, self.paddle, self.jaw_height])
        thin = BoxShape(jaws.rotation, jaws.center, fcl.Box(*size), size / 2)
        return thin, body


def test_a_new_kind_runs_through_the_check_with_nothing_but_its_class():
    setup = Setup(gripper=_Paddle(paddle=0.002, body_diameter=0.004))
    validator = Validator(setup)
    assert validator.geometry.gripper_shapes[0][0].half[1] == pytest.approx(0.001)
    lying = np.array([[0.0, 0.0, 0.0025, *[0.7071067811865476, 0, 0, 0.7071067811865476]]])
    bin_ = ContainerSpec(inner_size=(0.1, 0.1, 0.03))
    report = validator.check(bin_, [1], lying)
    assert report.results[0].stage == STAGE_VALID, report.results[0].reason
    with pytest.raises(InvalidArgument, match='gripper.paddle'):
        Validator(Setup(gripper=_Paddle(paddle=0.5)))
