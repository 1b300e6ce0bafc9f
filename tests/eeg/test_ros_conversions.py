"""The virtual subject's arm heading from /joint_states works for any robot's joint names."""

from __future__ import annotations

import pytest

from mindgrasp_common.robot_description import load_robot, robot_names
from mindgrasp_eeg.ros_conversions import base_yaw_from_joint_state


@pytest.mark.parametrize('name', robot_names())
def test_the_base_is_the_first_joint_of_any_robot(name):
    joints = load_robot(name).arm_joints
    positions = [0.3 + i for i in range(len(joints))]
    assert base_yaw_from_joint_state(joints, positions) == pytest.approx(0.3)
    # no robot's joint name is special: the order of /joint_states says which is the base
    assert base_yaw_from_joint_state(['turret', *load_robot('mindgrasp_arm').arm_joints],
                                     [0.7, *positions]) == pytest.approx(0.7)


def test_a_named_base_joint_wins_and_a_missing_one_is_none():
    assert base_yaw_from_joint_state(['a', 'b'], [0.1, 0.2], 'b') == pytest.approx(0.2)
    assert base_yaw_from_joint_state(['a', 'b'], [0.1, 0.2], 'c') is None
    assert base_yaw_from_joint_state([], [], '') is None
