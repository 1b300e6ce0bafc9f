"""The controller's input conversions from finger readings (plain functions, no ROS)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mindgrasp_common.robot import FINGER_CLOSED, FINGER_OPEN
from mindgrasp_fsm.conversions import gripper_from_fingers


def test_gripper_state_from_fingers_contacts_and_efforts() -> None:
    half = (FINGER_OPEN + FINGER_CLOSED) / 2
    g = gripper_from_fingers(np.full(3, half), 1.5, contacts=np.array([1, 0, 1], np.uint8),
                             efforts=np.array([0.5, -0.25, 0.25]))
    assert g.opening == pytest.approx(0.5)
    assert (g.contact, g.fingers_in_contact) == (True, 2)
    assert g.force == pytest.approx(1.0)
    assert g.efforts == (0.5, -0.25, 0.25)
    assert g.stamp == 1.5


def test_gripper_opening_is_clipped_and_missing_readings_say_unknown() -> None:
    g = gripper_from_fingers([FINGER_CLOSED + 0.3] * 3, 0.0)
    assert g.opening == 0.0
    assert g.contact is None and g.fingers_in_contact is None and g.efforts is None
    assert math.isnan(g.force)
    assert gripper_from_fingers([FINGER_OPEN - 0.3] * 3, 0.0).opening == 1.0
    one = gripper_from_fingers([FINGER_OPEN] * 3, 0.0, contacts=[True, False, False],
                               efforts=[0.1, 0.2])
    assert one.contact is False and one.efforts is None and one.force == pytest.approx(0.3)
    assert math.isnan(gripper_from_fingers([math.nan] * 3, 0.0).opening)


def test_a_synergy_with_a_range_per_joint_opens_by_each_joints_own_closure():
    """The Jaco hand's proximal joints close 0-1.3 rad, its distal ones 0-0.6: half closed is
    0.5 of each joint's range (the first joint's range for all read it as 0.73 open)."""
    opened, closed = (0.0,) * 4, (1.3, 0.6, 1.3, 0.6)
    g = gripper_from_fingers([0.65, 0.3, 0.65, 0.3], 0.0, open_angle=opened,
                             closed_angle=closed)
    assert g.opening == pytest.approx(0.5)
    assert gripper_from_fingers(list(closed), 0.0, open_angle=opened,
                                closed_angle=closed).opening == 0.0
