"""The MIndGrasp arm: joint names, limits and poses shared by the simulator (which writes the URDF
from them, :mod:`mindgrasp_sim.robot_model`) and the controller (which defaults its parameters to
them, :mod:`mindgrasp_fsm.params`). Angles in rad, velocities in rad/s, efforts in N m.
"""

from __future__ import annotations

import math

__all__ = [
    'ARM_EFFORT', 'ARM_JOINTS', 'ARM_LOWER_LIMITS', 'ARM_MAX_VELOCITY', 'ARM_UPPER_LIMITS',
    'FINGER_CLOSED', 'FINGER_JOINTS', 'FINGER_LOWER_LIMIT', 'FINGER_OPEN', 'FINGER_UPPER_LIMIT',
    'HOME_POSE', 'URDF_URI',
]

#: names of the six arm joints, base to wrist
ARM_JOINTS: tuple[str, ...] = ('joint_1', 'joint_2', 'joint_3', 'joint_4', 'joint_5', 'joint_6')
#: names of the three finger joints (thumb first)
FINGER_JOINTS: tuple[str, ...] = ('finger_thumb_joint', 'finger_left_joint', 'finger_right_joint')

#: position limits of the arm joints (rad), in the order of :data:`ARM_JOINTS`
ARM_LOWER_LIMITS: tuple[float, ...] = (-3.05, -1.75, -2.6, -2.6, -2.4, -3.05)
ARM_UPPER_LIMITS: tuple[float, ...] = (3.05, 1.75, 2.6, 2.6, 2.4, 3.05)
#: velocity limits of the arm joints (rad/s)
ARM_MAX_VELOCITY: tuple[float, ...] = (1.0, 1.0, 1.3, 1.3, 1.6, 1.6)
#: effort limits of the arm joints (N m)
ARM_EFFORT: tuple[float, ...] = (60.0, 80.0, 40.0, 30.0, 12.0, 6.0)

#: position limits of each finger joint (rad)
FINGER_LOWER_LIMIT, FINGER_UPPER_LIMIT = -0.6, 1.3
#: finger joint angles (rad) of the open (closure 0) and closed (closure 1) hand, inside the limits
FINGER_OPEN, FINGER_CLOSED = -0.55, 1.25

#: home pose (rad): long arm up, short arm forward, wrist pitched so the camera looks down at the
#: objects 0.5 m in front of the base (the paper: "all joints straight except joint 5")
HOME_POSE: tuple[float, ...] = (0.0, 0.0, 0.0, math.pi / 2, 1.2, 0.0)

#: the robot description (written by ``python -m mindgrasp_sim.robot_model``)
URDF_URI = 'package://mindgrasp_sim/urdf/mindgrasp_arm.urdf'
