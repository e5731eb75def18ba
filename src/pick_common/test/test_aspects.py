"""A part's aspects: named from its hull's stable faces, merged by normal, the quasi-static
shares trimesh predicts, a resting pose classified, and counts against a measurement."""

import math

import numpy as np
from pick_common.parts.aspects import (
    agreement,
    classify,
    OTHER,
    stable_aspects,
)
from pick_common.stats import wilson_interval
import pytest
import trimesh


def _turn(axis, angle) -> np.ndarray:
    """The xyzw quaternion of a turn by `angle` about `axis`."""
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    return np.array([*(axis * math.sin(angle / 2)), math.cos(angle / 2)])


def test_a_box_has_six_aspects_named_by_axis_its_long_sides_likelier():
    box = trimesh.creation.box((0.01, 0.01, 0.0144))
    found = {a.name: a for a in stable_aspects(box, box.center_mass)}
    assert set(found) == {'+x', '-x', '+y', '-y', '+z', '-z'}
    assert sum(a.quasi_static for a in found.values()) == pytest.approx(1.0)
    # the small square ends are harder to stand on than the long sides
    assert found['+z'].quasi_static < found['+x'].quasi_static
    assert found['-z'].normal == pytest.approx((0.0, 0.0, -1.0))


def test_a_cylinder_s_many_side_faces_are_one_aspect():
    cylinder = trimesh.creation.cylinder(radius=0.005, height=0.01, sections=48)
    found = {a.name: a for a in stable_aspects(cylinder, cylinder.center_mass)}
    assert set(found) == {'side_z', '+z', '-z'}
    assert len(found['side_z'].normals) > 8
    assert found['+z'].quasi_static == pytest.approx(found['-z'].quasi_static, rel=1e-6)


def test_a_resting_pose_shows_the_aspect_gravity_points_through():
    box = trimesh.creation.box((0.01, 0.01, 0.0144))
    found = stable_aspects(box, box.center_mass)
    poses = np.array([[0.0, 0.0, 0.0, 1.0],                      # as built: on -z
                      _turn((1, 0, 0), math.pi / 2),             # +z turned to -y: on -y
                      _turn((0, 1, 0), math.pi),                 # upside down: on +z
                      _turn((1, 1, 0), 0.6)])                    # tipped: on no face
    assert classify(found, poses) == ['-z', '-y', '+z', OTHER]


def test_the_share_interval_holds_the_share_and_narrows_with_counts():
    low, high = wilson_interval(38, 100)
    assert low < 0.38 < high and high - low == pytest.approx(0.187, abs=0.002)
    assert wilson_interval(380, 1000)[1] - wilson_interval(380, 1000)[0] < high - low
    assert wilson_interval(0, 50)[0] == pytest.approx(0.0, abs=1e-12)


def test_agreement_tells_alike_counts_from_different_ones():
    assert agreement({'a': 60, 'b': 40}, {'a': 58, 'b': 42}) > 0.5
    assert agreement({'a': 60, 'b': 40}, {'a': 38, 'b': 62}) < 0.01
    # an aspect only one side saw still counts; none seen by either is left out
    assert agreement({'a': 50, 'b': 50, 'c': 0}, {'a': 50, 'b': 40, 'c': 10}) < 0.01
